"""Execution: a checked plan in the world (features, scene), the waypoints that carry it out, the
arm port and its protocol, the executor that streams them, the closed loop that corrects a run,
and the run with its outputs (run.py). Builds on
`stablepush.plan` and `stablepush.task`; knows nothing of any simulator.

The names below are loaded when first used, so that importing one module of the package (the
arm protocol, say) does not load the executor.
"""
from stablepush.lazy import lazy_exports

_EXPORTS = {
    "Arm": "stablepush.execution.arm",
    "ArmError": "stablepush.execution.arm",
    "ArmReady": "stablepush.execution.arm",
    "TcpArm": "stablepush.execution.tcp_arm",
    "ACK_TIMEOUT_RANGE": "stablepush.execution.tcp_arm",
    "DEFAULT_ACK_TIMEOUT": "stablepush.execution.tcp_arm",
    "DEFAULT_PORT": "stablepush.execution.protocol",
    "ClosedLoop": "stablepush.execution.closed_loop",
    "GuardedApproach": "stablepush.execution.guard",
    "ExecutionReport": "stablepush.execution.report",
    "fault_report": "stablepush.execution.report",
    "RunOptions": "stablepush.execution.executor",
    "RunResult": "stablepush.execution.run",
    "run_plan": "stablepush.execution.run",
    "recording_for": "stablepush.execution.run",
    "JsonReport": "stablepush.execution.run",
    "BagRecording": "stablepush.execution.run",
    "execute_plan": "stablepush.execution.executor",
    "execution_warnings": "stablepush.execution.executor",
    "check_resume_from": "stablepush.execution.stream",
    "Verdict": "stablepush.execution.verdict",
    "CAUSES": "stablepush.execution.verdict",
    "Trajectory": "stablepush.execution.trajectory",
    "timed_trajectory": "stablepush.execution.trajectory",
    "parse_stamp": "stablepush.execution.bags",
    "write_bag": "stablepush.execution.bags",
}
__all__ = list(_EXPORTS)
__getattr__ = lazy_exports(__name__, _EXPORTS)
