"""Execution: a checked plan in the world (features, scene), the waypoints that carry it out, the
arm protocol, the executor that streams them, and the closed loop that corrects a run. Builds on
`stablepush.plan` and `stablepush.task`; knows nothing of any simulator."""
from stablepush.execution.closed_loop import ClosedLoop
from stablepush.execution.executor import ExecutionReport, execute_plan, execution_warnings
from stablepush.execution.trajectory import Trajectory, timed_trajectory

__all__ = ["ClosedLoop", "ExecutionReport", "execute_plan", "execution_warnings", "Trajectory", "timed_trajectory"]
