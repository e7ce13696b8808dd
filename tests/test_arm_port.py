"""The arm port (stablepush.execution.arm): a run drives any arm behind it the same way. A simulated
arm in this process and the same arm served over the protocol give the same run; an arm written
here in a few lines (no socket, no simulator) is run, faulted and stopped like any other; run_plan
writes its outputs after a fault too; and the engine-neutral parts of the simulated arm load no
engine."""
import json
import subprocess
import sys

import pytest

from stablepush.errors import ArmFault
from stablepush.execution import Arm, ArmError, ArmReady, RunOptions, TcpArm, execute_plan
from stablepush.execution.run import JsonReport, run_plan
from stablepush.plan import check_plan, plan_task

from conftest import shipped


@pytest.fixture(scope="module")
def low_mu():
    task = shipped("horizontal-offset-low-mu")
    return task, check_plan(task, plan_task(task, seed=1))


class ScriptedArm(Arm):
    """An arm that goes exactly where it is told and reports G there (no tracker, no simulator),
    and fails on waypoint `fail_at` (None: never)."""

    def __init__(self, fail_at=None, bad_state_at=None, paced=False):
        self.fail_at, self.bad_state_at, self.paced = fail_at, bad_state_at, paced
        self.moves = []
        self.stops = 0
        self.closed = False
        self.said_bye = False

    def hello(self, scene, rate_hz, resume):
        self.connected = True
        self.pose = list(scene.gripper_pose)
        return ArmReady(state={"ee_pose": self.pose, "joints": []}, arm="scripted")

    def move(self, waypoint):
        if waypoint.seq == self.fail_at:
            raise ArmError("the scripted arm refuses this waypoint")
        self.moves.append(waypoint)
        self.pose = list(waypoint.pose)
        if waypoint.seq == self.bad_state_at:
            return {"ee_pose": [float("nan")] * 7, "joints": []}
        return {"ee_pose": self.pose, "joints": []}

    def stop(self):
        self.stops += 1
        return True

    def bye(self):
        self.said_bye = True

    def close(self):
        self.closed = True


def test_an_arm_of_a_few_lines_runs_the_plan_to_its_end(low_mu):
    task, plan = low_mu
    arm = ScriptedArm()
    report = execute_plan(task, plan, arm, RunOptions(rate_hz=100.0))
    assert arm.said_bye and arm.stops == 0
    assert report.last_confirmed_step == len(plan.waypoints) - 1 and report.waypoints == len(arm.moves)
    assert [w.seq for w in arm.moves] == list(range(len(arm.moves)))
    # No tracker: the guard approaches as planned, and there is no verdict to give.
    assert report.guard == "no tracker" and report.final_in_grasp is None and report.success is None
    assert report.engine is None


def test_an_arm_error_ends_the_run_in_a_fault_that_stops_the_arm_and_says_where_to_resume(low_mu):
    task, plan = low_mu
    arm = ScriptedArm(fail_at=300)
    with pytest.raises(ArmFault, match="refuses this waypoint") as caught:
        execute_plan(task, plan, arm, RunOptions(rate_hz=100.0))
    fault = caught.value
    assert arm.stops == 1 and fault.arm_stopped is True and fault.connected and not arm.said_bye
    confirmed = [w.step for w in arm.moves if w.completes]
    assert fault.last_confirmed_step == max(confirmed) and 0 < fault.last_confirmed_step < len(plan.waypoints) - 1


def test_a_state_no_arm_could_be_in_is_a_fault_from_any_arm_not_only_over_the_wire(low_mu):
    task, plan = low_mu
    arm = ScriptedArm(bad_state_at=50)
    with pytest.raises(ArmFault, match="state.ee_pose") as caught:
        execute_plan(task, plan, arm, RunOptions(rate_hz=100.0))
    assert caught.value.arm_stopped is True and arm.stops == 1 and arm.closed


def test_anything_else_that_ends_a_run_stops_the_arm_and_lets_it_go(low_mu):
    task, plan = low_mu
    arm = ScriptedArm()

    def progress(waypoint, confirmed, total):
        if waypoint.seq == 40:
            raise ValueError("a bug in the caller's callback")

    with pytest.raises(ValueError, match="a bug"):
        execute_plan(task, plan, arm, RunOptions(rate_hz=100.0), progress=progress)
    assert arm.stops == 1 and arm.closed and not arm.said_bye


def test_a_run_is_paced_as_the_arm_says_unless_told(low_mu, monkeypatch):
    """A real arm's bridge moves in real time (TcpArm.paced), a simulator on its own clock."""
    from stablepush.execution import executor

    task, plan = low_mu
    slept = []
    monkeypatch.setattr(executor.time, "sleep", lambda s: slept.append(s))
    execute_plan(task, plan, ScriptedArm(paced=True), RunOptions(rate_hz=1000.0))
    assert len(slept) > 100
    slept.clear()
    execute_plan(task, plan, ScriptedArm(paced=True), RunOptions(rate_hz=1000.0, pace=False))
    execute_plan(task, plan, ScriptedArm(), RunOptions(rate_hz=1000.0))
    assert slept == [] and TcpArm.paced is True and RunOptions().pace is None


def test_run_plan_writes_its_report_after_a_fault_too(low_mu, tmp_path):
    task, plan = low_mu
    path = tmp_path / "run.json"
    run = run_plan(task, plan, ScriptedArm(fail_at=10), RunOptions(rate_hz=100.0), [JsonReport(str(path))])
    assert run.report is None and run.success is False and run.written == [f"report written to {path}"]
    written = json.loads(path.read_text())
    assert written["cause"] == "arm_fault" and written["arm_stopped"] is True
    with pytest.raises(ArmFault):
        run.report_or_fault()


def test_a_bridge_that_is_not_there_is_a_fault_before_anything_was_sent(low_mu):
    task, plan = low_mu
    import socket

    with socket.socket() as free:  # a port nothing listens on
        free.bind(("127.0.0.1", 0))
        port = free.getsockname()[1]
    with pytest.raises(ArmFault, match="cannot reach the arm server") as caught:
        execute_plan(task, plan, TcpArm("127.0.0.1", port, 1.0), RunOptions(rate_hz=100.0, pace=False))
    assert caught.value.connected is False and caught.value.arm_stopped is None


@pytest.mark.slow
def test_the_simulated_arm_in_this_process_and_over_the_protocol_run_the_same(low_mu):
    """The same arm behind the port and behind a socket: the same waypoints, the same states, the
    same report (the wire carries JSON numbers exactly)."""
    from stablepush.sim.deviation import WorldDeviation
    from stablepush.sim.local_arm import SimulatedArm
    from stablepush.sim.server import running_sim_arm

    task, plan = low_mu
    world = WorldDeviation(mu_scale=0.9, tracker_noise_mm=0.02, seed=3)
    local = execute_plan(task, plan, SimulatedArm(deviation=world), RunOptions(rate_hz=100.0))
    with running_sim_arm(log=lambda text: None, deviation=world) as server:
        remote = execute_plan(task, plan, TcpArm(server.host, server.port, 120.0), RunOptions(rate_hz=100.0, pace=False))
    a, b = local.as_dict(), remote.as_dict()
    for d in (a, b):
        d.pop("wall_time_s"), d.pop("sim_steps_per_s")
    assert a == b
    assert local.engine == "mujoco" and local.final_in_grasp is not None and local.replans == []


@pytest.mark.slow
def test_a_resume_on_the_same_simulated_arm_keeps_its_world_and_lands(low_mu):
    """A run that faults part-way and resumes from its last confirmed step on the same in-process
    arm continues in the world it had (the object where the fault left it), and lands."""
    from stablepush.sim.local_arm import SimulatedArm

    task, plan = low_mu
    said = []
    sim = SimulatedArm(log=said.append)

    class Faulting(Arm):
        """The simulated arm, refusing waypoint 400 of the first session."""

        def __init__(self, inner, fail_at=None):
            self.inner, self.fail_at = inner, fail_at

        def hello(self, scene, rate_hz, resume):
            ready = self.inner.hello(scene, rate_hz, resume)
            self.connected = True
            return ready

        def move(self, waypoint):
            if waypoint.seq == self.fail_at:
                raise ArmError("the link dropped")
            return self.inner.move(waypoint)

        def stop(self):
            return self.inner.stop()

    with pytest.raises(ArmFault) as caught:
        execute_plan(task, plan, Faulting(sim, fail_at=400), RunOptions(rate_hz=100.0))
    step = caught.value.last_confirmed_step
    report = execute_plan(task, plan, Faulting(sim), RunOptions(rate_hz=100.0, resume_from=step))
    assert sum("world built" in line for line in said) == 1 and any("world kept" in line for line in said), said
    assert report.resumed_from == step and report.success is True, report.verdict


def test_the_joint_level_bridge_and_the_kinematics_load_no_simulator():
    """A lab's joint-level arm (stablepush.bridge) needs the arm's kinematics and the cell check, not
    a simulator: importing it and the kinematics room loads no module of stablepush.sim and no Drake."""
    code = (
        "import sys\n"
        "import stablepush.bridge, stablepush.kinematics.arm_kinematics, stablepush.kinematics.cell_path\n"
        "print(sorted(m for m in sys.modules if m == 'stablepush.sim' or m.startswith(('stablepush.sim.', 'pydrake'))))\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip().splitlines()[-1] == "[]", out


def test_the_engine_neutral_parts_and_the_drake_arm_load_no_mujoco():
    """Drake reads the arm's MJCF with its own parser: `--engine drake` needs no MuJoCo."""
    code = (
        "import sys\n"
        "class Hide:\n"
        "    def find_spec(self, name, path=None, target=None):\n"
        "        if name.split('.')[0] == 'mujoco':\n"
        "            raise ImportError('hidden')\n"
        "sys.meta_path.insert(0, Hide())\n"
        "import stablepush.sim.tracking, stablepush.sim.deviation, stablepush.sim.local_arm\n"
        "from stablepush.sim.engines import load_engine\n"
        "try:\n"
        "    import pydrake.all\n"
        "except ImportError:\n"
        "    print('no drake')\n"
        "else:\n"
        "    import stablepush.sim.drake.arm\n"
        "    assert load_engine('drake') == 'drake'\n"
        "print('mujoco' in sys.modules)\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip().splitlines()[-1] == "False", out
