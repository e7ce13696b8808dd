"""`stablepush execute` on the simulated arm over the socket, its faults and resume, and the
figures of `stablepush show` / `cone`."""
import dataclasses
import json
import re
import socket
import subprocess
import sys
import threading
import time

import pytest
from click.testing import CliRunner

from stablepush.errors import ArmFault, PlanError
from stablepush.execution import RunOptions, TcpArm, execute_plan
from stablepush.execution.protocol import PROTOCOL, ProtocolError, decode, encode
from stablepush.plan import check_plan, plan_task
from stablepush.plan.files import write_plan
from stablepush.sim.local_arm import SimulatedArm
from stablepush.sim.server import running_sim_arm
from stablepush.task import load_task
from stablepush_cli.main import cli

from conftest import TASKS, shipped

# The bound the end-to-end test holds the simulated run to (the paper's robot: 0.5 mm, 0.5 deg).
# The paper's robot ended within 0.5 mm and 0.5 deg; the simulated arm does better on these plans
# (0.04 mm / 0.05 deg and 0.02 mm / 0.03 deg, docs/results/execute-shipped.md), so the tests hold it to 0.2.
FINAL_BOUND_MM = 0.2
FINAL_BOUND_DEG = 0.2


@pytest.fixture(scope="module")
def high_mu_plan(tmp_path_factory):
    task = shipped("horizontal-offset-high-mu")
    path = tmp_path_factory.mktemp("plans") / "high-mu.plan.json"
    write_plan(plan_task(task, seed=1), path)
    return str(path), str(TASKS / "horizontal-offset-high-mu.yaml")


def test_end_to_end_plan_execute_on_the_sim_arm(high_mu_plan, tmp_path):
    plan, task = high_mu_plan
    report_path = tmp_path / "run.json"
    result = CliRunner().invoke(cli, ["execute", plan, "--task", task, "--sim", "--quiet", "--json", str(report_path)])
    assert result.exit_code == 0, result.output
    report = json.loads(report_path.read_text())
    assert report["last_confirmed_step"] == report["total_steps"] == 20
    err = report["final_error"]
    assert err["distance"] < FINAL_BOUND_MM and abs(err["theta"]) < FINAL_BOUND_DEG, err
    final, goal = report["final_in_grasp"], shipped("horizontal-offset-high-mu").goal
    assert report["goal"] == list(goal)
    assert report["goal_error"]["x"] == pytest.approx(final["x"] - goal[0])
    assert report["goal_error"]["theta"] == pytest.approx(final["theta"] - goal[2])
    (contact,) = report["contacts"]
    assert contact["pusher"] == "left" and contact["slip_mm"] < FINAL_BOUND_MM
    assert "on the last feature, in the grasp" in result.output
    assert report["success"] is True and report["cause"] is None and report["engine"] == "mujoco"
    assert report["tolerance"] == [0.5, 0.5] and "verdict: landed" in result.output


def test_a_completed_run_that_misses_exits_5_and_names_its_cause(high_mu_plan, tmp_path):
    plan, task = high_mu_plan
    report_path = tmp_path / "run.json"
    result = CliRunner().invoke(cli, ["execute", plan, "--task", task, "--sim", "--quiet", "--json", str(report_path),
                                      "--success-tolerance", "0.001", "0.001"])
    assert result.exit_code == 5, result.output
    report = json.loads(report_path.read_text())
    assert report["success"] is False and report["tolerance"] == [0.001, 0.001]
    assert report["cause"] in ("pusher_slipped", "drift") and report["verdict"].startswith("missed: x ")
    assert f"[cause: {report['cause']}]" in result.output


def test_a_part_that_slides_when_released_is_a_miss_that_names_it_and_exits_5(tmp_path):
    """The user study's dropped bar, on a shipped part: the high-mu offset's pads hold 0.91 times
    its weight at the goal. Its task ends the run on the feature (environment.end_on_feature); taken
    out, the run is on target on the feature, the release drops it out of tolerance, and the
    verdict says so (before, it said landed and printed the release beside it)."""
    import yaml

    data = yaml.safe_load((TASKS / "horizontal-offset-high-mu.yaml").read_text())
    del data["environment"]
    task = tmp_path / "released.yaml"
    task.write_text(yaml.safe_dump(data))
    plan, report_path = tmp_path / "p.json", tmp_path / "run.json"
    planned = CliRunner().invoke(cli, ["plan", str(task), "-o", str(plan)])
    assert planned.exit_code == 0 and "goal: the pads alone hold only 0.91 times" in planned.output, planned.output
    assert "note: at the plan's last pose the pads alone hold only 0.91 times" in planned.output
    result = CliRunner().invoke(cli, ["execute", str(plan), "--task", str(task), "--sim", "--quiet", "--json",
                                      str(report_path)])
    assert result.exit_code == 5, result.output
    report = json.loads(report_path.read_text())
    before, after = report["final_in_grasp"], report["landed_in_grasp"]
    assert abs(before["x"] - 20.0) < 0.5 and abs(before["theta"]) < 0.5  # on target on the feature
    assert abs(after["theta"]) > 5.0 and report["release_moved"]  # and not once released
    assert report["success"] is False and report["cause"] == "moved_on_release"
    assert report["goal_error"]["theta"] == pytest.approx(after["theta"])
    assert "[cause: moved_on_release]" in result.output and "on its last feature it was within" in result.output


def test_t_shape_end_to_end_through_two_switch_overs():
    task = shipped("t-shaped")
    plan = check_plan(task, plan_task(task, seed=1))
    with running_sim_arm(log=lambda text: None) as server:
        report = execute_plan(task, plan, TcpArm(server.host, server.port), RunOptions(rate_hz=100.0, pace=False))
    assert [c.pusher for c in report.contacts] == ["left", "under-web", "left"]
    # 0.09 mm measured with Coulomb friction on the sliding pad points (1.0 mm was allowed before they slid right)
    assert report.final_error["distance"] < FINAL_BOUND_MM and abs(report.final_error["theta"]) < FINAL_BOUND_DEG


# -- a plan that does not belong to its task ----------------------------------------------------


def test_a_plan_for_another_task_is_refused_before_anything_moves(high_mu_plan):
    plan, _ = high_mu_plan
    result = CliRunner().invoke(cli, ["execute", plan, "--task", str(TASKS / "pivoting.yaml"), "--sim"])
    assert result.exit_code == 2
    assert "plan.json: task: the plan is for task" in result.output and "'horizontal-offset-high-mu'" in result.output


def test_a_plan_for_another_version_of_the_task_is_refused(high_mu_plan, tmp_path):
    import yaml

    plan, task_file = high_mu_plan
    data = yaml.safe_load(open(task_file))
    for p in data["pushers"]:
        p["mu"] = 0.2  # the low-mu pushers: the straight push is no longer stable
    edited = tmp_path / "edited.yaml"
    edited.write_text(yaml.safe_dump(data))
    result = CliRunner().invoke(cli, ["execute", plan, "--task", str(edited), "--sim"])
    assert result.exit_code == 2  # named by the plan's record of its task, before any push is re-checked
    assert "changed since the plan was made (pushers.bottom.mu, pushers.left.mu, pushers.right.mu)" in result.output
    from stablepush.plan import check_plan, load_plan
    from stablepush.task import load_task

    # check_plan itself refuses it by the same rule, and without the record it still finds the push
    with pytest.raises(PlanError, match=r"task_identity: .*changed since the plan was made \(pushers.bottom.mu"):
        check_plan(load_task(edited), load_plan(plan))
    with pytest.raises(PlanError, match=r"waypoints\[1\]: .*not a stable push"):
        check_plan(load_task(edited), dataclasses.replace(load_plan(plan), task_identity=None))


# -- faults -------------------------------------------------------------------------------------


def _start_sim_arm(*args):
    process = subprocess.Popen([sys.executable, "-m", "stablepush_cli.main", "sim-arm", "--port", "0", *args],
                               stderr=subprocess.PIPE, text=True)
    line = process.stderr.readline()
    port = int(re.search(r"listening on [\d.]+:(\d+)", line).group(1))
    threading.Thread(target=process.stderr.read, daemon=True).start()  # keep its log from blocking it
    return process, port


def test_server_gone_mid_plan_names_the_last_step_and_resume_finishes(high_mu_plan, tmp_path):
    plan, task = high_mu_plan
    runner = CliRunner()
    process, port = _start_sim_arm("--exit-after", "150")
    try:
        result = runner.invoke(cli, ["execute", plan, "--task", task, "--arm", f"127.0.0.1:{port}", "--no-pace", "--quiet",
                                     "--json", str(tmp_path / "fault.json")])
    finally:
        process.wait(timeout=30)
    assert result.exit_code == 3, result.output
    fault = json.loads((tmp_path / "fault.json").read_text())
    assert fault["success"] is False and fault["cause"] == "arm_fault" and fault["last_confirmed_step"] == 9
    assert "closed the connection" in result.output
    assert "could not be reached to stop it" in result.output
    # 149 waypoints were acknowledged: the guarded approach (51 waypoints, 3 past the plan's touch before
    # the force reads it, 5 held still: 59), then 10 per push: 9 pushes confirmed.
    step = int(re.search(r"last confirmed step: (\d+) of 20", result.output).group(1))
    assert step == 9
    assert f"--resume-from {step}" in result.output

    process, port = _start_sim_arm()
    try:
        resumed = runner.invoke(cli, ["execute", plan, "--task", task, "--arm", f"127.0.0.1:{port}", "--no-pace",
                                      "--quiet", "--resume-from", str(step)])
    finally:
        process.terminate()
        process.wait(timeout=30)
    assert resumed.exit_code == 0, resumed.output
    assert f"steps {step + 1}-20 of 20 confirmed" in resumed.output
    final = re.search(r"error ([\d.]+) mm, ([-+][\d.]+) deg", resumed.output)
    assert float(final.group(1)) < 1.0 and abs(float(final.group(2))) < FINAL_BOUND_DEG


def test_nothing_listening_is_a_clear_fault(high_mu_plan):
    plan, task = high_mu_plan
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]  # closed again when the block ends: nothing listens there
    result = CliRunner().invoke(cli, ["execute", plan, "--task", task, "--arm", f"127.0.0.1:{port}", "--quiet"])
    assert result.exit_code == 3
    assert "cannot reach the arm server" in result.output and "nothing was sent" in result.output
    assert "stablepush sim-arm" in result.output and "--sim" in result.output and "--resume-from" not in result.output


def test_a_fault_report_on_standard_output_is_json_alone(high_mu_plan, tmp_path):
    """`--json /dev/stdout | jq .` after a fault: the lines that say what was written go to stderr."""
    plan, task = high_mu_plan
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    run = subprocess.run([sys.executable, "-m", "stablepush_cli.main", "execute", plan, "--task", task, "--arm",
                          f"127.0.0.1:{port}", "--quiet", "--json", "/dev/stdout"], capture_output=True, text=True)
    assert run.returncode == 3, run.stderr
    assert json.loads(run.stdout)["cause"] == "arm_fault"


@pytest.mark.parametrize("args, says", [
    (["--sim", "--arm", "127.0.0.1:47100"], "--sim and --arm: choose one"),
    (["--sim", "--ack-timeout", "9"], "--ack-timeout: only with an arm server"),
])
def test_options_for_another_arm_are_refused_not_ignored(high_mu_plan, args, says):
    plan, task = high_mu_plan
    result = CliRunner().invoke(cli, ["execute", plan, "--task", task, "--quiet", *args])
    assert result.exit_code == 2 and says in result.output, result.output


class FakeArm:
    """An arm server that misbehaves after `good` acknowledgements, and records whether it was
    told to stop."""

    def __init__(self, good: int, bad_reply, frozen: bool = False, stall=None):
        self.good, self.bad_reply, self.frozen = good, bad_reply, frozen  # frozen: always reports the home pose
        self.stall = stall  # (seq, s): acknowledge waypoint seq that late
        self.received = []  # when each waypoint arrived (time.perf_counter)
        self.stopped = False
        self.sock = socket.create_server(("127.0.0.1", 0))
        self.port = self.sock.getsockname()[1]
        threading.Thread(target=self._serve, daemon=True).start()

    def _serve(self):
        conn, _ = self.sock.accept()
        with conn:
            reader = conn.makefile("rb")
            state = None
            for line in reader:
                msg = json.loads(line)
                if msg["type"] == "hello":
                    state = {"ee_pose": msg["scene"]["gripper_pose"], "joints": [0.0] * 7}
                    conn.sendall(encode({"type": "ready", "protocol": PROTOCOL, "arm": "fake", "state": state}))
                elif msg["type"] == "waypoint":
                    self.received.append(time.perf_counter())
                    if self.stall and msg["seq"] == self.stall[0]:
                        time.sleep(self.stall[1])
                    state = state if self.frozen else {"ee_pose": msg["pose"], "joints": [0.0] * 7}
                    if msg["seq"] < self.good:
                        conn.sendall(encode({"type": "ack", "seq": msg["seq"], "state": state}))
                    else:
                        conn.sendall(self.bad_reply(msg))
                elif msg["type"] == "stop":
                    self.stopped = True
                    conn.sendall(encode({"type": "stopped", "state": state}))
                    return


@pytest.mark.parametrize(
    "bad_reply, says",
    [
        (lambda msg: b"ack, but not JSON\n", "not a JSON line"),
        (
            lambda msg: encode({"type": "ack", "seq": msg["seq"] + 1, "state": {"ee_pose": msg["pose"]}}),
            "out-of-order acknowledgement",
        ),
        (lambda msg: encode({"type": "ack", "seq": msg["seq"]}), "field 'state' missing"),
        (
            lambda msg: encode({"type": "error", "seq": msg["seq"], "message": "joint 4 over its torque limit"}),
            "torque limit",
        ),
    ],
)
def test_bad_replies_stop_the_arm_and_name_the_last_step(bad_reply, says):
    task = shipped("horizontal-offset-high-mu")
    plan = check_plan(task, plan_task(task, seed=1))
    arm = FakeArm(good=91, bad_reply=bad_reply)  # the approach's 51 waypoints and 4 pushes of 10
    with pytest.raises(ArmFault) as fault:
        execute_plan(task, plan, TcpArm("127.0.0.1", arm.port, 5.0), RunOptions(rate_hz=100.0, pace=False))
    assert says in fault.value.reason
    assert fault.value.last_confirmed_step == 4
    assert fault.value.arm_stopped is True and arm.stopped


def test_a_paced_stream_goes_on_at_its_rate_after_the_arm_stalled():
    """After a stalled acknowledgement the executor sent the waypoints it was behind by at once
    (316 waypoints, 3.16 s of motion, in 0.17 s after a 3 s stall): a burst of motion into a real arm."""
    task = shipped("horizontal-offset-high-mu")
    plan = check_plan(task, plan_task(task, seed=1))
    arm = FakeArm(good=80, bad_reply=lambda msg: encode({"type": "error", "seq": msg["seq"], "message": "done"}),
                  stall=(20, 0.5))
    with pytest.raises(ArmFault):
        execute_plan(task, plan, TcpArm("127.0.0.1", arm.port, 5.0), RunOptions(rate_hz=100.0, pace=True))
    after = arm.received[21:71]  # 50 waypoints after the stall: 0.49 s apart at 100 Hz, however late the stall
    assert after[-1] - after[0] >= 0.45


def test_a_fault_after_the_closed_loop_replanned_offers_no_resume_of_the_plan_file(tmp_path):
    """Past a re-plan the confirmed step counts the closed loop's steps: the suggested
    `--resume-from` named a step of the plan file that was another pose, or none (41 of 40)."""
    task_file = TASKS / "large-manipulation.yaml"  # its plan ends short: the loop re-plans before the first push
    task = load_task(task_file)
    plan_file = tmp_path / "lm.plan.json"
    write_plan(check_plan(task, plan_task(task, seed=1)), str(plan_file))
    e_stop = lambda msg: encode({"type": "error", "seq": msg["seq"], "message": "e-stop"})  # noqa: E731

    def fault_after(good, *options):
        arm = FakeArm(good=good, bad_reply=e_stop)
        out = tmp_path / f"fault{good}.json"
        result = CliRunner().invoke(cli, ["execute", str(plan_file), "--task", str(task_file), "--arm",
                                          f"127.0.0.1:{arm.port}", "--no-pace", "--quiet", "--json", str(out),
                                          *options])
        assert result.exit_code == 3 and arm.stopped, result.output
        return result.stderr, json.loads(out.read_text())

    said, fault = fault_after(150, "--closed-loop")  # pushes of the re-planned steps confirmed
    assert fault["last_confirmed_step"] > 0 and fault["replanned"] is True
    assert "the closed loop had re-planned the run" in said and "--resume-from" not in said
    said, fault = fault_after(5, "--closed-loop")  # stopped before the first push: the plan file's step 0
    assert fault["last_confirmed_step"] == 0 and fault["replanned"] is False
    assert "--closed-loop --resume-from 0" in said
    said, fault = fault_after(150, "--rate", "50", "--no-guard")  # open loop: the plan file's steps, and the way on
    assert fault["replanned"] is False
    assert f"--rate 50 --no-pace --no-guard --resume-from {fault['last_confirmed_step']}\n" in said  # as it ran


def test_a_report_written_to_stdout_has_the_stream_alone(tmp_path):
    """`execute --json /dev/stdout` put the run's summary on stdout before the report."""
    task = TASKS / "horizontal-offset-high-mu.yaml"
    plan = tmp_path / "p.json"
    write_plan(check_plan(load_task(task), plan_task(load_task(task), seed=1)), str(plan))
    run = subprocess.run([sys.executable, "-m", "stablepush_cli.main", "execute", str(plan), "--task", str(task),
                          "--sim", "--quiet", "--json", "/dev/stdout"], capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr
    assert json.loads(run.stdout)["success"] is True and "verdict: landed" in run.stderr


def test_the_sim_arm_refuses_malformed_and_out_of_order_waypoints_and_stops():
    task = shipped("horizontal-offset-high-mu")
    plan = check_plan(task, plan_task(task, seed=1))
    from stablepush.execution.world import place_features, scene_description

    scene = scene_description(task, place_features(task, plan.waypoints), task.start).as_dict()
    with running_sim_arm(log=lambda text: None) as server:
        for bad, says in ((b"{not json\n", "not a JSON line"),
                          (encode({"type": "waypoint", "seq": 5, "t": 0.0, "step": 0, "phase": "push",
                                   "pose": scene["gripper_pose"]}), "out-of-order waypoint: expected seq 0, got 5"),
                          (encode({"type": "waypoint", "seq": 0, "t": 0.0, "step": 0, "phase": "push",
                                   "pose": [0, 0, 0, 2, 0, 0, 0]}), "not of unit length")):
            with socket.create_connection((server.host, server.port), timeout=30) as conn:
                reader = conn.makefile("rb")
                conn.sendall(encode({"type": "hello", "protocol": PROTOCOL, "rate_hz": 100, "scene": scene}))
                assert decode(reader.readline(), "server")["type"] == "ready"
                conn.sendall(bad)
                reply = decode(reader.readline(), "server")
                assert reply["type"] == "error" and says in reply["message"], reply
                assert reader.readline() == b""  # the server closed the connection
            arm = server.arm.sim
            assert list(arm.target) == list(arm.data.qpos[arm._arm_qpos])  # held where it was


def test_protocol_decoding_names_what_is_wrong():
    with pytest.raises(ProtocolError, match="unknown message type 'dance'"):
        decode(b'{"type": "dance"}\n', "client")
    with pytest.raises(ProtocolError, match="field 'seq' missing"):
        decode(b'{"type": "waypoint", "t": 0, "step": 1, "phase": "push", "pose": [0,0,0,1,0,0,0]}\n', "client")
    with pytest.raises(ProtocolError, match="protocol 'other/1'"):
        decode(b'{"type": "hello", "protocol": "other/1", "rate_hz": 100, "scene": {}}\n', "client")
    assert decode(encode({"type": "stop"}), "client") == {"type": "stop"}


# -- figures ------------------------------------------------------------------------------------


def test_show_writes_a_png_and_a_gif_of_the_plan(high_mu_plan, tmp_path):
    import numpy as np
    from PIL import Image

    plan, task = high_mu_plan
    png, gif = tmp_path / "plan.png", tmp_path / "plan.gif"
    result = CliRunner().invoke(cli, ["show", plan, "--task", task, "-o", str(png), "--gif", str(gif)])
    assert result.exit_code == 0, result.output
    image = np.asarray(Image.open(png).convert("L"), float)
    assert image.shape[0] > 400 and image.shape[1] > 800
    assert image.std() > 10  # not a blank canvas
    with Image.open(gif) as animation:
        assert animation.n_frames == 21  # the start and one frame per push


def test_cone_draws_the_pushers_cone_and_names_a_bad_pusher(tmp_path):
    png = tmp_path / "cone.png"
    ok = CliRunner().invoke(cli, ["cone", str(TASKS / "pivoting.yaml"), "--pusher", "left", "-o", str(png)])
    assert ok.exit_code == 0 and png.stat().st_size > 10_000
    bad = CliRunner().invoke(cli, ["cone", str(TASKS / "pivoting.yaml"), "--pusher", "nope"])
    assert bad.exit_code == 2 and "no pusher named 'nope'" in bad.output


def test_world_deviations_need_the_simulated_arm(tmp_path):
    from stablepush_cli.main import cli

    plan = tmp_path / "p.json"
    task = str(TASKS / "horizontal-offset-high-mu.yaml")
    assert CliRunner().invoke(cli, ["plan", task, "-o", str(plan)]).exit_code == 0
    result = CliRunner().invoke(cli, ["execute", str(plan), "--task", task, "--arm", "127.0.0.1:9", "--sim-mu-scale", "0.85"])
    assert result.exit_code == 2 and "--sim-mu-scale" in result.output


# -- closed loop ----------------------------------------------------------------------------------


def test_closed_loop_corrects_a_world_with_less_friction_than_the_model():
    """The low-mu offset in a world whose pads and features have 15% less mu than the task says:
    open loop its pusher slips and it ends about 1 mm from the goal; closed loop it re-plans from
    the tracked pose, robust to pushers with 15% less mu and pads with 15% more or less (a
    correction with the model's mu slipped as the plan did and ended 0.22 mm low, where no pusher
    can lift it), and lands within the final tolerance, a fifth of the goal tolerance."""
    from stablepush.execution.closed_loop import ClosedLoop
    from stablepush.sim.deviation import WorldDeviation

    task = shipped("horizontal-offset-low-mu")
    plan = check_plan(task, plan_task(task, seed=1))
    loop = ClosedLoop.for_task(task)
    open_loop = execute_plan(task, plan, SimulatedArm(deviation=WorldDeviation(mu_scale=0.85)), RunOptions(rate_hz=100.0))
    report = execute_plan(task, plan, SimulatedArm(deviation=WorldDeviation(mu_scale=0.85)),
                          RunOptions(rate_hz=100.0, closed_loop=loop))
    assert open_loop.goal_error["distance"] > 0.5, open_loop.goal_error
    assert report.closed_loop == "on"
    assert any(r.solved and r.pushes > 0 for r in report.replans), report.replans
    err = report.goal_error
    assert max(abs(err["x"]), abs(err["z"])) <= loop.final_tolerance.position, (err, open_loop.goal_error)
    assert abs(err["theta"]) <= loop.final_tolerance.angle, err
    assert report.success is True
    assert report.last_confirmed_step == report.total_steps  # the spliced plan ran to its end
    assert report.as_dict()["replans"][0]["after_step"] >= 1


def test_closed_loop_on_an_arm_without_a_tracker_runs_open_loop_and_says_so():
    from stablepush.execution.closed_loop import ClosedLoop

    task = shipped("horizontal-offset-high-mu")
    plan = check_plan(task, plan_task(task, seed=1))
    arm = FakeArm(good=10**9, bad_reply=None)  # acknowledges everything, reports no object_in_grasp
    report = execute_plan(task, plan, TcpArm("127.0.0.1", arm.port), RunOptions(rate_hz=100.0, pace=False, closed_loop=ClosedLoop.for_task(task)))
    assert report.closed_loop == "no tracker" and report.replans == []
    assert report.guard == "no tracker" and all(c.found_mm is None for c in report.contacts)
    assert report.last_confirmed_step == 20 and report.final_error is None


def test_closed_loop_thresholds_default_to_fractions_of_the_task_tolerance():
    from stablepush.execution.closed_loop import ClosedLoop

    task = shipped("t-shaped")  # tolerance [1, 1]
    loop = ClosedLoop.for_task(task)
    assert tuple(loop.threshold) == (0.5, 0.5) and tuple(loop.final_tolerance) == pytest.approx((0.2, 0.2))
    assert tuple(ClosedLoop.for_task(task, (0.3, 0.4)).threshold) == (0.3, 0.4)
    assert loop.off_by({"x": 1.0, "z": 0.0, "theta": 0.0}, (0.4, 0.0, 0.0), loop.threshold)
    assert not loop.off_by({"x": 1.0, "z": 0.0, "theta": 0.4}, (0.6, 0.0, 0.0), loop.threshold)


def test_a_correction_that_would_carry_an_unheld_object_between_features_is_refused():
    """At the high-mu offset's end the pads hold only 0.91 of the prism's weight: a correction by
    the right pusher would carry it there unheld (tried, it ended 21.7 mm / 61 deg off), so no
    correction is taken; from the start pose, where the pads hold 4.3 times it, one is."""
    from stablepush.execution.closed_loop import ClosedLoop, replan

    task = shipped("horizontal-offset-high-mu")
    loop = ClosedLoop.for_task(task)
    record, steps = replan(task, (20.095, -0.223, 0.449), "left", loop, 20, (20.0, 0.0, 0.0))
    # The search switches pushers only where the pads hold 1.5 times the weight, and finds none.
    assert not record.solved and steps == [] and record.tried[0].startswith("left alone, pusher mu -15%, pad mu +-15% in 50,000 tests: ")
    assert "every pusher, pusher mu -15%, pad mu +-15% in 500,000 tests: out of tests" in record.tried
    assert "every pusher in 500,000 tests: out of tests" in record.tried
    assert record.failure.startswith(f"{len(record.tried)} search(es) failed (")  # the line `execute` prints
    record, steps = replan(task, (0.1, -0.1, 0.3), "left", loop, 1, (1.0, 0.0, 0.0))
    assert record.solved and steps[0].pose == (0.1, -0.1, 0.3)


def test_closed_loop_options_need_closed_loop(high_mu_plan):
    plan, task = high_mu_plan
    result = CliRunner().invoke(cli, ["execute", plan, "--task", task, "--sim", "--replan-threshold", "0.3", "0.3"])
    assert result.exit_code == 2 and "--closed-loop" in result.output


def test_features_hold_the_object_at_the_world_orientation_the_model_assumes():
    """Against fixed features the model keeps the object's world orientation on each feature (the
    start's unless environment.features says): the executor places them so, turning G instead."""
    import math

    from stablepush.execution.world import place_features
    from stablepush.plan import Waypoint

    task = shipped("large-manipulation")  # start theta 0
    steps = [Waypoint(0.0, 0.0, 0.0), Waypoint(0.0, 0.0, 5.0, pusher="bottom"), Waypoint(0.0, 0.0, 10.0, pusher="left")]
    features = place_features(task, steps)
    for name in ("bottom", "left"):
        R = features[name].object_pose[:3, :3]
        assert task.feature_angle(name) == 0.0
        assert math.degrees(math.atan2(R[0, 2], R[0, 0])) == pytest.approx(0.0, abs=1e-9)  # not the 5 deg left starts at


def test_protocol_versions_arm_2_and_arm_1_are_both_served_and_others_refused():
    task = shipped("horizontal-offset-high-mu")
    plan = check_plan(task, plan_task(task, seed=1))
    from stablepush.execution.world import place_features, scene_description

    scene = scene_description(task, place_features(task, plan.waypoints), task.start).as_dict()
    with running_sim_arm(log=lambda text: None) as server:
        for version in ("stablepush.arm/1", PROTOCOL):
            with socket.create_connection((server.host, server.port), timeout=30) as conn:
                conn.sendall(encode({"type": "hello", "protocol": version, "rate_hz": 100, "scene": scene}))
                ready = decode(conn.makefile("rb").readline(), "server")
                assert ready["type"] == "ready" and ready["protocol"] == version
                assert {"x", "z", "theta"} <= set(ready["state"]["object_in_grasp"])  # the tracker field
                conn.sendall(encode({"type": "bye"}))
    assert PROTOCOL == "stablepush.arm/2"
    with pytest.raises(ProtocolError, match="stablepush.arm/3"):
        decode(encode({"type": "hello", "protocol": "stablepush.arm/3", "rate_hz": 100, "scene": {}}), "client")


def test_executing_a_moving_pusher_task_warns_that_the_arm_pushes_against_fixed_features(tmp_path):
    import yaml

    from conftest import task_text

    data = yaml.safe_load(task_text("horizontal-offset-high-mu"))
    data.setdefault("dynamics", {})["pushes"] = "by_moving_pusher"
    task_file = tmp_path / "moving.yaml"
    task_file.write_text(yaml.safe_dump(data))
    plan = tmp_path / "moving.plan.json"
    assert CliRunner().invoke(cli, ["plan", str(task_file), "-o", str(plan)]).exit_code == 0
    result = CliRunner().invoke(cli, ["execute", str(plan), "--task", str(task_file), "--sim", "--quiet"])
    assert result.exit_code == 0, result.output
    assert "by_moving_pusher" in result.output and "another cell" in result.output


def _closed_loop_within_0_2_at_0_85(tmp_path, task: str, *options: str):
    """Plan `task` (its path under data/tasks) and run it closed loop on the simulated arm in a world
    with 15% less mu, judged within 0.2 mm / 0.2 deg: the printed output and the JSON report, once
    the run exited 0 and its goal error is within 0.2 mm and 0.2 deg."""
    task_file = str(TASKS / task)
    plan, report_path = tmp_path / "task.plan.json", tmp_path / "run.json"
    assert CliRunner().invoke(cli, ["plan", task_file, "-o", str(plan)]).exit_code == 0
    result = CliRunner().invoke(cli, ["execute", str(plan), "--task", task_file, "--sim", *options, "--quiet",
                                      "--closed-loop", "--sim-mu-scale", "0.85", "--success-tolerance", "0.2", "0.2",
                                      "--json", str(report_path)])
    assert result.exit_code == 0, result.output
    report = json.loads(report_path.read_text())
    err = report["goal_error"]
    assert max(abs(err["x"]), abs(err["z"])) <= 0.2 and abs(err["theta"]) <= 0.2, err
    return result.output, report


@pytest.mark.parametrize("engine", ["mujoco", "drake"])
def test_closed_loop_lands_the_wedge_in_a_low_friction_world_and_says_so(tmp_path, engine):
    """A user's wedge (data/tasks/more/wedge-heel.yaml) whose heel stop creeps open loop: in a world
    with 15% less mu than its task, closed loop, the run lands within 0.2 mm and 0.2 deg of the goal,
    the report says success and lists the corrections with what triggered them. On Drake its goal
    puts a pad point 0.15 mm inside the heel face, where Drake's sphere-vs-convex query answered
    through that face and pushed the wedge 0.4 mm out of the grasp (sim.drake.arm._add_pad_faces)."""
    _, report = _closed_loop_within_0_2_at_0_85(tmp_path, "more/wedge-heel.yaml", "--engine", engine)
    assert report["success"] is True and report["tolerance"] == [0.2, 0.2] and report["engine"] == engine
    assert report["replans"] and all(r["trigger"] in ("plan_short", "off_plan", "off_goal") for r in report["replans"])
    assert any(r["solved"] and r["pushes"] > 0 for r in report["replans"])


def test_closed_loop_lands_the_high_mu_offset_whose_pusher_slips_with_pads_of_less_friction(tmp_path):
    """The high-mu offset at x0.85: its left pusher slips and turns the prism 0.9 deg (the pads'
    15% less mu, not the pusher's, makes it: a plan robust to the pusher's mu alone is the nominal
    plan). Corrections robust to the pads' mu too switch to the bottom pusher where the pads hold,
    and the run lands within 0.2 mm / 0.2 deg; robust to the pushers' mu alone, every correction
    after the first slipped or was refused and it ended 0.85 mm / +0.94 deg off."""
    _, report = _closed_loop_within_0_2_at_0_85(tmp_path, "horizontal-offset-high-mu.yaml")
    assert report["success"] is True and any(r["solved"] and r["pushes"] > 0 for r in report["replans"])


def test_closed_loop_plans_a_short_plan_again_to_the_goal_before_the_first_push(tmp_path):
    """The large manipulation's plan stops 1.28 unit steps short of the goal (inside the task's
    1 mm / 1 deg) where its one pusher cannot push the rest: closed loop, in a world with 15% less
    mu, the loop plans it again to 0.2 mm / 0.2 deg before the first push and the run lands there;
    the report and the printed lines say so."""
    output, report = _closed_loop_within_0_2_at_0_85(tmp_path, "large-manipulation.yaml", "-v")
    first = report["replans"][0]
    assert first["trigger"] == "plan_short" and first["solved"] and first["after_step"] == 0
    assert "before the first push: the plan ends off the goal by" in output
    assert report["success"] is True and report["total_steps"] == first["pushes"]


def test_closed_loop_lands_the_pivot_with_its_feature_off_its_place():
    """The pivot's feature 0.32 mm into the object, 0.45 mm down and turned -0.41 deg (evaluate's
    trial 2 of seed 1 with features off by up to 0.5 mm / 0.5 deg): the first touch pushes the prism
    0.38 mm off the pads' centre, about which the plan turns it. Corrections turn it about that centre
    from where it is (planner.pivot_steps) and it lands within 0.5 mm / 0.5 deg; without them every
    correction was refused and it ended 0.41 mm / -0.82 deg off. The first correction is made as
    the prism comes onto the feature, before the first push (with approaches that end where the plan
    puts the feature: a guarded approach finds it instead)."""
    from stablepush.execution.closed_loop import ClosedLoop
    from stablepush.sim.deviation import WorldDeviation

    task = shipped("pivoting")
    plan = check_plan(task, plan_task(task, seed=1))
    world = WorldDeviation(feature_offsets=(("left", 0.3219, -0.4503, -0.4070),))
    report = execute_plan(task, plan, SimulatedArm(deviation=world), RunOptions(rate_hz=100.0, guard=None, closed_loop=ClosedLoop.for_task(task), success_tolerance=(0.5, 0.5)))
    assert report.success is True, (report.goal_error, report.verdict.detail)
    first = report.replans[0]
    assert first.solved and first.trigger == "on_touch" and first.after_step == 0


def test_closed_loop_corrects_when_the_last_feature_is_met_early():
    """The hexagon's one contact (lower-left, 12 pushes to the goal) with its feature 0.49 mm off in
    x and 0.38 mm in z (evaluate's trial 74 of seed 1, the 1,000-trial table's worlds): the approach
    pushes the prism about 0.5 mm along the push before the first push, below the re-plan
    threshold, and the pushes carry it 0.55 mm past the goal, where the lower-left face cannot push
    it back. Compared when it comes onto the feature, it is re-planned then, with that pusher, and
    lands within 0.2 mm / 0.2 deg. (An approach that is not guarded: a guarded one stops at the
    feature, test_a_guarded_approach_finds_a_feature_off_its_place_and_the_run_lands.)"""
    from stablepush.execution.closed_loop import ClosedLoop
    from stablepush.sim.deviation import WorldDeviation

    task = load_task(TASKS / "more" / "hexagon-offset.yaml")
    plan = check_plan(task, plan_task(task, seed=1))
    world = WorldDeviation(pad_mu_scale=1.0846, pusher_mu_scale=0.9725, grip_scale=1.0518, mass_scale=0.9612,
                           feature_offsets=(("lower-left", 0.4906, 0.3846, 0.1700),
                                            ("bottom", 0.2018, 0.3975, -0.1038)))
    report = execute_plan(task, plan, SimulatedArm(deviation=world), RunOptions(rate_hz=100.0, guard=None, closed_loop=ClosedLoop.for_task(task), success_tolerance=(0.2, 0.2)))
    assert report.success is True, (report.goal_error, report.verdict.detail)
    touch = report.replans[0]
    assert touch.trigger == "on_touch" and touch.after_step == 0 and touch.solved and touch.kept_pusher
    assert any("on the feature of step 1: off the plan by" in line for line in report.describe(verbose=True))


def _open_loop_in(task, world, guarded=True):
    from stablepush.execution.guard import GuardedApproach

    plan = check_plan(task, plan_task(task, seed=1))
    return execute_plan(task, plan, SimulatedArm(deviation=world), RunOptions(rate_hz=100.0, guard=GuardedApproach() if guarded else None, success_tolerance=(0.5, 0.5)))


def test_a_feature_beyond_its_place_is_blamed_not_the_friction():
    """The tilted-gravity offset's left feature 0.48 mm beyond its place along the push, open loop
    with approaches that end where the plan puts the feature: the object rides with the hand about
    0.5 mm into the first push before the feature stops it, then sticks, and ends that much short of
    the goal. The verdict blames the feature (`feature_off`), and the slip after the feature met it
    is nil. 42 of the 50 misses of this plan's 1,000-trial open loop were this (docs/results/evaluate-1000-trials.md),
    all called `pusher_slipped` before."""
    from stablepush.sim.deviation import WorldDeviation

    report = _open_loop_in(load_task(TASKS / "more" / "tilted-gravity.yaml"),
                           WorldDeviation(feature_offsets=(("left", -0.48, 0.0, 0.0),)), guarded=False)
    assert report.success is False and report.verdict.cause == "feature_off", report.verdict.detail
    assert re.search(r"left's feature was met late: the object rode with the hand 0\.(4[6-9]|5[0-2]) mm into step 1",
                     report.verdict.detail)
    left = report.contacts[0]
    assert left.carried_mm == pytest.approx(0.49, abs=0.03) and left.slip_mm < 0.02 and left.found_mm is None


@pytest.mark.parametrize("task_file, offsets, found_mm, unguarded_mm", [
    # the tilted-gravity offset's left feature 0.48 mm beyond its place (the test above)
    ("tilted-gravity.yaml", (("left", -0.48, 0.0, 0.0),), 0.48, 0.52),
    # the hexagon's lower-left feature met 0.64 mm early along the approach (evaluate's trial 74 of seed 1,
    # the closed-loop test above), which the approach pushed 0.58 mm off its plan
    ("hexagon-offset.yaml", (("lower-left", 0.4906, 0.3846, 0.1700), ("bottom", 0.2018, 0.3975, -0.1038)),
     -0.64, 0.58),
])
def test_a_guarded_approach_finds_a_feature_off_its_place_and_the_run_lands(task_file, offsets, found_mm,
                                                                              unguarded_mm):
    """Open loop, no correction: the approach's slow end finds the feature by touch, where it is,
    and the contact's pushes start there; the run ends within 0.2 mm / 0.2 deg of the goal, and the
    contact's record says how far from its place the feature was found. Without the guard the same
    world ends more than 0.5 mm off."""
    from stablepush.sim.deviation import WorldDeviation

    task = load_task(TASKS / "more" / task_file)
    world = WorldDeviation(feature_offsets=offsets)
    guarded, plain = _open_loop_in(task, world), _open_loop_in(task, world, guarded=False)
    error = guarded.goal_error
    assert guarded.success and error["distance"] < 0.2 and abs(error["theta"]) < 0.2, guarded.verdict.detail
    assert guarded.guard == "on" and guarded.contacts[0].found_mm == pytest.approx(found_mm, abs=0.03)
    assert plain.guard == "off" and plain.goal_error["distance"] == pytest.approx(unguarded_mm, abs=0.03)


@pytest.mark.parametrize("task_file, turn_deg, seated_deg, error_deg, unseated_deg", [
    # the tilted-gravity offset: its 1,000-trial open-loop misses had this feature turned +0.49 to +0.50
    # deg and ended +0.50 to +0.51 deg off (docs/results/evaluate-1000-trials.md)
    ("more/tilted-gravity.yaml", 0.5, 0.5, 0.1, 0.51),
    # the pivot: its prism seats at about twice the turn, and ends about -0.2 deg off on features in place too;
    # here at -0.21 or -0.27 deg, which one decided by the last bits of the arm's IK (numpy's BLAS picks its
    # kernel by the CPU: -0.27 with AVX-512's, -0.21 with others'), so the bound lies above both
    ("pivoting.yaml", -0.4, -0.82, 0.3, -0.86),
])
def test_a_turned_feature_is_found_as_the_object_seats_and_the_run_lands(task_file, turn_deg, seated_deg, error_deg,
                                                                        unseated_deg):
    """Open loop, the left feature turned about y: the object rests turned on it after the contact's
    first push, and the pushes left are re-based there, so the run ends as it does on a feature not
    turned. The contact's record says how the object seated. Without the re-base (an approach that
    is not guarded) the turn, or twice it, stays in the final pose."""
    from stablepush.sim.deviation import WorldDeviation

    task = load_task(TASKS / task_file)
    world = WorldDeviation(feature_offsets=(("left", 0.0, 0.0, turn_deg),))
    guarded, plain = _open_loop_in(task, world), _open_loop_in(task, world, guarded=False)
    assert abs(guarded.goal_error["theta"]) < error_deg and guarded.goal_error["distance"] < 0.1, guarded.verdict.detail
    assert guarded.contacts[0].seated_deg == pytest.approx(seated_deg, abs=0.05)
    assert plain.contacts[0].seated_deg is None
    assert plain.goal_error["theta"] == pytest.approx(unseated_deg, abs=0.05)


def test_a_pusher_that_slips_on_a_feature_in_its_place_is_a_slip():
    """The high-mu offset's pusher slips in a world with 15% less friction (its pushes have 0.1 N
    of margin): the feature is where the plan says, so nothing is carried, and the verdict is
    `pusher_slipped`."""
    from stablepush.sim.deviation import WorldDeviation

    report = _open_loop_in(shipped("horizontal-offset-high-mu"),
                           WorldDeviation(pad_mu_scale=0.85, pusher_mu_scale=0.85))
    assert report.success is False and report.verdict.cause == "pusher_slipped", report.verdict.detail
    left = report.contacts[0]  # it slips turning: 0.2 mm and 0.9 deg
    assert left.slip_deg > 0.5 and left.carried_mm < 0.02


def test_closed_loop_on_drake_lands_the_t_shape_in_a_low_friction_world(tmp_path):
    """The second engine end to end: the T through two switch-overs on the Drake arm (whose contact
    solver alone decides stick and slip), mu x0.85, closed loop: it lands within 0.2 mm and
    0.2 deg, and the report says so, names the engine and lists its corrections (none were needed)."""
    _, report = _closed_loop_within_0_2_at_0_85(tmp_path, "t-shaped.yaml", "--engine", "drake")
    assert report["success"] is True and report["engine"] == "drake" and report["closed_loop"] == "on"
    assert isinstance(report["replans"], list)


def test_engine_needs_the_simulated_arm(high_mu_plan):
    plan, task = high_mu_plan
    result = CliRunner().invoke(cli, ["execute", str(plan), "--task", str(task), "--engine", "drake"])
    assert result.exit_code == 2 and "--engine" in result.output


def test_an_arm_that_never_moves_ends_the_run_in_a_fault_and_is_stopped():
    """Issue 24, item 5: a fake arm whose acks always report the home pose got "steps 1-20 of 20
    confirmed", exit 0. The executor now sees that it does not follow and stops it."""
    task = shipped("horizontal-offset-high-mu")
    arm = FakeArm(good=10**9, bad_reply=None, frozen=True)
    with pytest.raises(ArmFault, match="not following") as fault:
        execute_plan(task, check_plan(task, plan_task(task, seed=1)), TcpArm("127.0.0.1", arm.port), RunOptions(rate_hz=100.0, pace=False))
    assert arm.stopped and fault.value.last_confirmed_step < 20


def test_closed_loop_corrects_before_the_last_pose_a_switch_over_is_held_from():
    """The high-mu offset in a world of 5% less pad mu and 3% less grip (trial 62 of its 1,000-trial
    row): the left pusher sags the prism in the grasp, past the re-plan threshold only at step 12,
    where the pads hold 1.45 times its weight and no correction may switch to the bottom pusher to
    lift it; it ended 0.54 mm / +0.59 deg off. Compared with the final tolerance after the last push
    from which a switch-over is held (step 9), it is corrected there, with the bottom pusher, and
    lands."""
    from stablepush.execution.closed_loop import ClosedLoop, switch_held
    from stablepush.execution.guard import GuardedApproach
    from stablepush.sim.deviation import WorldDeviation

    task = shipped("horizontal-offset-high-mu")
    plan = check_plan(task, plan_task(task, seed=1))
    held = [switch_held(task, w.pose, "left") for w in plan.waypoints]
    assert held[:10] == [True] * 10 and not any(held[10:])
    world = WorldDeviation(pad_mu_scale=0.9523, pusher_mu_scale=1.0546, grip_scale=0.9652, mass_scale=1.0496,
                           feature_offsets=(("left", -0.1479, -0.3143, -0.4517), ("right", -0.3103, 0.4178, -0.1418),
                                            ("bottom", 0.2014, -0.2901, 0.0598)))
    report = execute_plan(task, plan, SimulatedArm(deviation=world), RunOptions(rate_hz=100.0, guard=GuardedApproach(), closed_loop=ClosedLoop.for_task(task), success_tolerance=(0.5, 0.5)))
    assert report.success is True, (report.goal_error, report.verdict.detail)
    first = report.replans[0]
    assert first.trigger == "last_switch" and first.after_step == 9 and first.solved
    assert first.pushers[0] == "bottom"
    assert any("after step 9, the last a switch-over is held from: off the plan by" in line
               for line in report.describe(verbose=True))
