"""Execution: a checked plan in the world (features, scene), the waypoints that carry it out, the
arm port and its protocol, the executor that streams them, the closed loop that corrects a run,
and the run with its outputs (run.py). Builds on
`stablepush.plan` and `stablepush.task`; knows nothing of any simulator.

The names below are loaded when first used, so that importing one module of the package (the
arm protocol, say) does not load the executor.
"""
import importlib

_EXPORTS = {
    "Arm": "stablepush.execution.arm",
    "ArmError": "stablepush.execution.arm",
    "ArmReady": "stablepush.execution.arm",
    "TcpArm": "stablepush.execution.tcp_arm",
    "ClosedLoop": "stablepush.execution.closed_loop",
    "GuardedApproach": "stablepush.execution.guard",
    "ExecutionReport": "stablepush.execution.report",
    "fault_report": "stablepush.execution.report",
    "RunOptions": "stablepush.execution.executor",
    "RunResult": "stablepush.execution.run",
    "run_plan": "stablepush.execution.run",
    "JsonReport": "stablepush.execution.run",
    "BagRecording": "stablepush.execution.run",
    "execute_plan": "stablepush.execution.executor",
    "execution_warnings": "stablepush.execution.executor",
    "Verdict": "stablepush.execution.verdict",
    "Trajectory": "stablepush.execution.trajectory",
    "timed_trajectory": "stablepush.execution.trajectory",
}
__all__ = list(_EXPORTS)


def __getattr__(name: str):
    if name not in _EXPORTS:
        raise AttributeError(f"module 'stablepush.execution' has no attribute {name!r}")
    return getattr(importlib.import_module(_EXPORTS[name]), name)
