"""ROS 2 bags of a plan's trajectory (stablepush.execution.bags), read back with rosbags' own
reader: every topic with its message type, one message per trajectory sample stamped with its
time, the gripper's pose equal to the CSV's row, and /tf putting the object where the plan has it
(in the grasp between pushes, fixed on its feature during one)."""
import csv
import io

import numpy as np
import pytest
from click.testing import CliRunner
from rosbags.rosbag2 import Reader
from rosbags.typesys import Stores, get_typestore

from stablepush.execution import timed_trajectory
from stablepush.execution.bags import TOPICS
from stablepush.execution.world import place_features
from stablepush.frames import grasp_transform, pose_to_matrix
from stablepush.plan import check_plan, plan_task
from stablepush_cli.main import cli

from conftest import TASKS, shipped

STORE = get_typestore(Stores.ROS2_HUMBLE)


def _matrix(transform) -> np.ndarray:
    t, q = transform.translation, transform.rotation
    return pose_to_matrix([t.x, t.y, t.z, q.w, q.x, q.y, q.z])


@pytest.fixture(scope="module")
def t_bag(tmp_path_factory):
    scratch = tmp_path_factory.mktemp("bag")
    task_file = str(TASKS / "t-shaped.yaml")
    plan, bag, table = scratch / "t.plan.json", scratch / "t.mcap", scratch / "t.csv"
    runner = CliRunner()
    assert runner.invoke(cli, ["plan", task_file, "-o", str(plan), "--quiet"]).exit_code == 0
    for out in (bag, table):
        result = runner.invoke(cli, ["trajectory", str(plan), "--task", task_file, "-o", str(out)])
        assert result.exit_code == 0, result.output
    messages = {}
    with Reader(bag) as reader:
        kinds = {c.topic: c.msgtype for c in reader.connections}
        for connection, stamp, raw in reader.messages():
            messages.setdefault(connection.topic, []).append((stamp, STORE.deserialize_cdr(raw, connection.msgtype)))
    rows = list(csv.DictReader(io.StringIO(table.read_text())))
    return kinds, messages, rows


def test_every_topic_is_there_with_its_type_and_a_message_per_sample(t_bag):
    kinds, messages, rows = t_bag
    assert kinds == TOPICS
    for topic in TOPICS:
        once = topic in ("/stablepush/scene", "/stablepush/arm_scene")
        assert len(messages[topic]) == (1 if once else len(rows)), topic
    stamps = [stamp for stamp, _ in messages["/stablepush/gripper_pose"]]
    assert stamps == [round(float(r["t"]) * 1e9) for r in rows]
    assert [m.data for _, m in messages["/stablepush/phase"]] == [r["phase"] for r in rows]
    assert [m.data for _, m in messages["/stablepush/step"]] == [int(r["step"]) for r in rows]
    markers = messages["/stablepush/scene"][0][1].markers
    frames = {m.header.frame_id for m in markers}
    task = shipped("t-shaped")
    assert frames == {"object", "gripper", "world"}
    assert len(markers) == 1 + len(task.pads) + 2  # the outline, each pad, the features of left and under-web


def test_the_gripper_pose_is_the_csv_row(t_bag):
    _, messages, rows = t_bag
    for (_, msg), row in zip(messages["/stablepush/gripper_pose"], rows):
        p, q = msg.pose.position, msg.pose.orientation
        assert [p.x, p.y, p.z, q.x, q.y, q.z, q.w] == pytest.approx(
            [float(row[k]) for k in ("x", "y", "z", "qx", "qy", "qz", "qw")], abs=1e-12)
        assert msg.header.frame_id == "world"


def test_tf_puts_the_object_in_the_grasp_and_on_its_feature(t_bag):
    """Between pushes the object's pose in the grasp is the plan's at the last step; during a
    push the object stays where its feature holds it in the world."""
    _, messages, rows = t_bag
    task = shipped("t-shaped")
    plan = check_plan(task, plan_task(task, seed=1))
    features = place_features(task, list(plan.waypoints))
    for (_, tf), row in zip(messages["/tf"], rows):
        (to_gripper, to_object) = tf.transforms
        assert (to_gripper.header.frame_id, to_gripper.child_frame_id) == ("world", "gripper")
        assert (to_object.header.frame_id, to_object.child_frame_id) == ("gripper", "object")
        step = plan.waypoints[int(row["step"])]
        if row["phase"] == "push":
            T_WO = _matrix(to_gripper.transform) @ _matrix(to_object.transform)
            assert np.allclose(T_WO, features[step.pusher].object_pose, atol=1e-9)
        else:
            assert np.allclose(_matrix(to_object.transform), grasp_transform(step.pose), atol=1e-9)


def test_a_bag_needs_a_checked_plan(tmp_path):
    result = CliRunner().invoke(cli, ["trajectory", str(tmp_path / "none.json"), "--task",
                                      str(TASKS / "t-shaped.yaml"), "-o", str(tmp_path / "x.mcap")])
    assert result.exit_code == 2 and not (tmp_path / "x.mcap").exists()
    assert len(timed_trajectory(shipped("t-shaped"), check_plan(shipped("t-shaped"),
                                                                plan_task(shipped("t-shaped"), seed=1)))) > 0


def test_the_bridge_example_replays_a_bag_to_the_sim_arm(tmp_path):
    """examples/bag_to_arm.py streams a bag's gripper poses to an arm server over stablepush.arm/2;
    on the simulated arm the object ends where the plan does (the T: its grasp holds it when the
    gripper backs off the last feature, where the bag's stream ends)."""
    import importlib.util

    from stablepush.sim.server import running_sim_arm

    spec = importlib.util.spec_from_file_location("bag_to_arm", TASKS.parent.parent / "examples" / "bag_to_arm.py")
    bridge = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(bridge)
    task_file = str(TASKS / "t-shaped.yaml")
    plan, bag = tmp_path / "p.plan.json", tmp_path / "p.mcap"
    assert CliRunner().invoke(cli, ["plan", task_file, "-o", str(plan), "--quiet"]).exit_code == 0
    assert CliRunner().invoke(cli, ["trajectory", str(plan), "--task", task_file, "-o", str(bag)]).exit_code == 0
    with running_sim_arm(log=lambda text: None) as server:
        state = bridge.replay(bag, server.host, server.port)
    end = shipped("t-shaped").goal  # the plan ends at the goal pose itself
    where = state["object_in_grasp"]
    assert abs(where["x"] - end[0]) < 0.3 and abs(where["z"] - end[1]) < 0.3 and abs(where["theta"] - end[2]) < 0.3
    with pytest.raises(ValueError, match="cannot read it as a ROS 2 bag"):
        bridge.read_bag(tmp_path / "p.plan.json")


def test_a_recorded_run_reads_back_with_its_corrections_and_verdict(tmp_path):
    """`execute --record` (issue 22, item 2): the low-mu offset closed loop in a world with 15% less
    mu, recorded and read back: a sample per acknowledged waypoint on every per-sample topic, each
    correction the report lists, the verdict, and the tracker's last pose in the grasp."""
    import json

    from stablepush.execution.bags import RUN_TOPICS

    task = str(TASKS / "horizontal-offset-low-mu.yaml")
    plan, bag, report = tmp_path / "p.plan.json", tmp_path / "run.mcap", tmp_path / "run.json"
    assert CliRunner().invoke(cli, ["plan", task, "-o", str(plan), "--quiet"]).exit_code == 0
    result = CliRunner().invoke(cli, ["execute", str(plan), "--task", task, "--sim", "--quiet", "--closed-loop",
                                      "--sim-mu-scale", "0.85", "--record", str(bag), "--json", str(report)])
    assert result.exit_code in (0, 5), result.output
    run = json.loads(report.read_text())
    messages = {}
    with Reader(bag) as reader:
        assert {c.topic: c.msgtype for c in reader.connections} == RUN_TOPICS
        for connection, stamp, raw in reader.messages():
            messages.setdefault(connection.topic, []).append(STORE.deserialize_cdr(raw, connection.msgtype))
    for topic in ("/tf", "/stablepush/commanded_pose", "/stablepush/gripper_pose", "/stablepush/object_pose",
                  "/stablepush/object_in_grasp", "/stablepush/pusher", "/stablepush/phase", "/stablepush/step"):
        assert len(messages[topic]) == run["waypoints"], topic
    corrections = [json.loads(m.data) for m in messages.get("/stablepush/correction", [])]
    assert run["replans"] and corrections == run["replans"]
    (verdict,) = [json.loads(m.data) for m in messages["/stablepush/verdict"]]
    assert verdict["success"] == run["success"] and verdict["cause"] == run["cause"]
    assert {m.data for m in messages["/stablepush/pusher"]} >= {"", "bottom", "left"}
    last = messages["/stablepush/object_in_grasp"][-1].pose.position
    assert last.x * 1e3 == pytest.approx(run["released_in_grasp"]["x"], abs=1e-6)
    bad = CliRunner().invoke(cli, ["execute", str(plan), "--task", task, "--sim", "--record", str(tmp_path / "x.bag")])
    assert bad.exit_code == 2 and "--record" in bad.output


def test_every_quaternion_topic_is_continuous_past_half_a_turn(tmp_path):
    """A plan that turns the object 200 deg in the grasp: on /tf (world -> gripper and gripper ->
    object) each quaternion lies in the hemisphere of the one before."""
    import dataclasses

    from stablepush.execution.bags import write_bag

    task = shipped("pivoting")
    turned = dataclasses.replace(task, goal=(0.0, 0.0, 200.0), planner={**task.planner, "step": [1.0, 5.0]})
    plan = check_plan(turned, plan_task(turned, seed=1))
    write_bag(tmp_path / "turn.mcap", turned, plan, timed_trajectory(turned, plan))
    quats = {"gripper": [], "object": []}
    with Reader(tmp_path / "turn.mcap") as reader:
        for connection, _, raw in reader.messages():
            if connection.topic == "/tf":
                for transform in STORE.deserialize_cdr(raw, connection.msgtype).transforms:
                    q = transform.transform.rotation
                    quats[transform.child_frame_id].append([q.w, q.x, q.y, q.z])
    for frame, q in quats.items():
        q = np.array(q)
        assert (np.sum(q[1:] * q[:-1], axis=1) > 0.99).all(), frame
