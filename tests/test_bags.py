"""ROS 2 bags of a plan's trajectory (stablepush.execution.bags), read back with rosbags' own
reader: every topic with its message type, one message per trajectory sample stamped with the
bag's start plus its time, the gripper's pose equal to the CSV's row, /tf putting the object where
the plan has it (in the grasp between pushes, fixed on its feature during one), and /tf_static the
features' fixed frames."""
import csv
import io
import time

import numpy as np
import pytest
from click.testing import CliRunner
from rosbags.interfaces import QosDurability
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
START = "2026-12-01T15:00:00Z"  # the t-shaped bag's --stamp
START_NS = 1_796_137_200 * 10**9


def _matrix(transform) -> np.ndarray:
    t, q = transform.translation, transform.rotation
    return pose_to_matrix([t.x, t.y, t.z, q.w, q.x, q.y, q.z])


def _read(bag):
    """(topic -> message type, topic -> [(record time ns, message)], the connections by topic, the
    topics in the order of their first message)."""
    messages, first = {}, []
    with Reader(bag) as reader:
        connections = {c.topic: c for c in reader.connections}
        for connection, stamp, raw in reader.messages():
            if connection.topic not in messages:
                first.append(connection.topic)
            messages.setdefault(connection.topic, []).append((stamp, STORE.deserialize_cdr(raw, connection.msgtype)))
    return {t: c.msgtype for t, c in connections.items()}, messages, connections, first


def _header_stamps(messages) -> list:
    """(record time ns, header stamp ns) of every message with a header, and of each transform in a
    TFMessage."""
    out = []
    for topic, timed in messages.items():
        for stamp, msg in timed:
            headers = [t.header for t in msg.transforms] if hasattr(msg, "transforms") else (
                [m.header for m in msg.markers] if hasattr(msg, "markers") else [getattr(msg, "header", None)])
            out += [(stamp, h.stamp.sec * 10**9 + h.stamp.nanosec) for h in headers if h is not None]
    return out


@pytest.fixture(scope="module")
def t_bag(tmp_path_factory):
    scratch = tmp_path_factory.mktemp("bag")
    task_file = str(TASKS / "t-shaped.yaml")
    plan, bag, table = scratch / "t.plan.json", scratch / "t.mcap", scratch / "t.csv"
    runner = CliRunner()
    assert runner.invoke(cli, ["plan", task_file, "-o", str(plan), "--quiet"]).exit_code == 0
    for out, stamp in ((bag, ["--stamp", START]), (table, [])):
        result = runner.invoke(cli, ["trajectory", str(plan), "--task", task_file, "-o", str(out), *stamp])
        assert result.exit_code == 0, result.output
    kinds, messages, connections, first = _read(bag)
    rows = list(csv.DictReader(io.StringIO(table.read_text())))
    return kinds, messages, rows, connections, first


def test_every_topic_is_there_with_its_type_and_a_message_per_sample(t_bag):
    kinds, messages, rows, _, _ = t_bag
    assert kinds == TOPICS
    for topic in TOPICS:
        once = topic in ("/tf_static", "/stablepush/scene", "/stablepush/arm_scene")
        assert len(messages[topic]) == (1 if once else len(rows)), topic
    stamps = [stamp for stamp, _ in messages["/stablepush/gripper_pose"]]
    assert stamps == [START_NS + round(float(r["t"]) * 1e9) for r in rows]
    assert [m.data for _, m in messages["/stablepush/phase"]] == [r["phase"] for r in rows]
    assert [m.data for _, m in messages["/stablepush/step"]] == [int(r["step"]) for r in rows]
    markers = messages["/stablepush/scene"][0][1].markers
    frames = {m.header.frame_id for m in markers}
    task = shipped("t-shaped")
    assert frames == {"object", "gripper", "world"}
    assert len(markers) == 1 + len(task.gripper.pads) + 2  # the outline, each pad, the features of left and under-web


def test_the_gripper_pose_is_the_csv_row(t_bag):
    _, messages, rows, _, _ = t_bag
    for (_, msg), row in zip(messages["/stablepush/gripper_pose"], rows):
        p, q = msg.pose.position, msg.pose.orientation
        assert [p.x, p.y, p.z, q.x, q.y, q.z, q.w] == pytest.approx(
            [float(row[k]) for k in ("x", "y", "z", "qx", "qy", "qz", "qw")], abs=1e-12)
        assert msg.header.frame_id == "world"


def test_tf_puts_the_object_in_the_grasp_and_on_its_feature(t_bag):
    """Between pushes the object's pose in the grasp is the plan's at the last step; during a
    push the object stays where its feature holds it in the world."""
    _, messages, rows, _, _ = t_bag
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


@pytest.fixture(scope="module")
def now_bag(tmp_path_factory):
    """The t-shaped bag written by the library with the default start, and the Unix ns just
    before and after it was written."""
    from stablepush.execution.bags import write_bag

    bag = tmp_path_factory.mktemp("now") / "t.mcap"
    task = shipped("t-shaped")
    plan = check_plan(task, plan_task(task, seed=1))
    before = time.time_ns()
    write_bag(bag, task, plan, timed_trajectory(task, plan))
    return before, time.time_ns(), task, plan, _read(bag)


def test_the_bag_starts_at_its_stamp_and_every_header_moves_with_it(t_bag):
    """--stamp (issue 57, item 6): the bag's first message is at the given start, and every header
    stamp (each transform's and marker's too) is its message's record time, start + t."""
    _, messages, rows, _, _ = t_bag
    assert min(stamp for timed in messages.values() for stamp, _ in timed) == START_NS
    pairs = _header_stamps(messages)
    assert len(pairs) > 4 * len(rows) and all(record == header for record, header in pairs)


def test_the_default_stamp_is_now(now_bag):
    """Without a start the bag starts when it is written, not in 1970: a bag played beside live
    data lies in its time."""
    before, after, _, _, (_, messages, _, _) = now_bag
    first = min(stamp for timed in messages.values() for stamp, _ in timed)
    assert before <= first <= after
    assert all(record == header for record, header in _header_stamps(messages))


def test_a_stamp_is_unix_seconds_or_iso_8601_with_its_zone(tmp_path):
    from stablepush.execution.bags import parse_stamp

    assert parse_stamp("1796137200.25") == parse_stamp("2026-12-01T16:00:00.25+01:00") == START_NS + 250_000_000
    assert parse_stamp(START) == parse_stamp("2026-12-01T15:00:00z") == START_NS
    for bad, why in (("2026-12-01T15:00:00", "no zone"), ("yesterday", "expected Unix seconds"),
                     ("-1", "expected Unix seconds"), ("2040-01-01T00:00:00Z", "int32 seconds")):
        with pytest.raises(ValueError, match=why):
            parse_stamp(bad)
    task_file = str(TASKS / "t-shaped.yaml")
    assert CliRunner().invoke(cli, ["plan", task_file, "-o", str(tmp_path / "t.plan.json"), "--quiet"]).exit_code == 0
    for out, bad in (("t.mcap", "2026-12-01T15:00:00"), ("t.csv", START)):
        result = CliRunner().invoke(cli, ["trajectory", str(tmp_path / "t.plan.json"), "--task", task_file, "-o",
                                          str(tmp_path / out), "--stamp", bad])
        assert result.exit_code == 2 and "--stamp" in result.output and not (tmp_path / out).exists()
        assert ("no zone" if out == "t.mcap" else "only with a .mcap") in result.output
    # execute's --stamp is its recording's start: without --record it would be dropped silently
    result = CliRunner().invoke(cli, ["execute", str(tmp_path / "t.plan.json"), "--task", task_file, "--sim",
                                      "--stamp", START])
    assert result.exit_code == 2 and "--stamp: only with --record" in result.output


def test_tf_static_holds_each_features_frame_once_transient_local(now_bag):
    """/tf_static, first and once: world -> feature_<pusher> for each feature the plan uses, at the
    middle of its contact segment with z its normal and the segment along x; offered transient
    local, as tf2's static broadcaster offers it. /tf moves only the gripper and the object."""
    _, _, task, plan, (kinds, messages, connections, first) = now_bag
    assert kinds["/tf_static"] == "tf2_msgs/msg/TFMessage" and first[0] == "/tf_static"
    (qos,) = connections["/tf_static"].ext.offered_qos_profiles
    assert qos.durability == QosDurability.TRANSIENT_LOCAL
    ((_, static),) = messages["/tf_static"]
    features = place_features(task, list(plan.waypoints))
    frames = {t.child_frame_id: t for t in static.transforms}
    assert set(frames) == {f"feature_{name}" for name in features} == {"feature_left", "feature_under-web"}
    for name, feature in features.items():
        to_feature = frames[f"feature_{name}"]
        assert to_feature.header.frame_id == "world"
        T_WF = _matrix(to_feature.transform)
        assert np.allclose(T_WF[:3, 3], (feature.start + feature.end) / 2, atol=1e-12)
        assert np.allclose(T_WF[:3, 2], feature.normal / np.linalg.norm(feature.normal), atol=1e-12)
        for end in (feature.start, feature.end):  # the contact segment lies on the frame's x axis
            assert np.allclose((np.linalg.inv(T_WF) @ [*end, 1.0])[1:3], 0, atol=1e-12)
    on_tf = {(t.header.frame_id, t.child_frame_id) for _, tf in messages["/tf"] for t in tf.transforms}
    assert on_tf == {("world", "gripper"), ("gripper", "object")}


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
    with Reader(bag) as reader:  # the shipped arm's joints; it is MJCF, with no URDF for /robot_description
        assert {c.topic: c.msgtype for c in reader.connections} == {**RUN_TOPICS,
                                                                    "/joint_states": "sensor_msgs/msg/JointState"}
        for connection, stamp, raw in reader.messages():
            messages.setdefault(connection.topic, []).append(STORE.deserialize_cdr(raw, connection.msgtype))
    for topic in ("/tf", "/stablepush/commanded_pose", "/stablepush/gripper_pose", "/stablepush/object_pose",
                  "/stablepush/object_in_grasp", "/stablepush/pusher", "/stablepush/phase", "/stablepush/step",
                  "/joint_states"):
        assert len(messages[topic]) == run["waypoints"], topic
    assert all(list(m.name) == [f"j{k}" for k in range(1, 8)] for m in messages["/joint_states"])
    corrections = [json.loads(m.data) for m in messages.get("/stablepush/correction", [])]
    assert run["replans"] and corrections == run["replans"]
    (verdict,) = [json.loads(m.data) for m in messages["/stablepush/verdict"]]
    assert verdict["success"] == run["success"] and verdict["cause"] == run["cause"]
    assert {m.data for m in messages["/stablepush/pusher"]} >= {"", "bottom", "left"}
    last = messages["/stablepush/object_in_grasp"][-1].pose.position
    assert last.x * 1e3 == pytest.approx(run["released_in_grasp"]["x"], abs=1e-6)
    bad = CliRunner().invoke(cli, ["execute", str(plan), "--task", task, "--sim", "--record", str(tmp_path / "x.bag")])
    assert bad.exit_code == 2 and "--record" in bad.output


def test_a_recorded_run_is_stamped_from_its_start_with_the_features_static(tmp_path):
    """`execute --record --stamp` (issue 57, item 6): the bag starts at the given start with
    /tf_static (transient local) world -> each of the plan's features, and every header stamp is
    its message's record time; a stamp that is not a time is refused naming --stamp."""
    task = str(TASKS / "horizontal-offset-low-mu.yaml")
    plan, bag = tmp_path / "p.plan.json", tmp_path / "run.mcap"
    assert CliRunner().invoke(cli, ["plan", task, "-o", str(plan), "--quiet"]).exit_code == 0
    result = CliRunner().invoke(cli, ["execute", str(plan), "--task", task, "--sim", "--quiet", "--record", str(bag),
                                      "--stamp", "1796137200"])
    assert result.exit_code in (0, 5), result.output
    _, messages, connections, first = _read(bag)
    assert first[0] == "/tf_static" and messages["/tf_static"][0][0] == START_NS
    assert min(stamp for timed in messages.values() for stamp, _ in timed) == START_NS
    (qos,) = connections["/tf_static"].ext.offered_qos_profiles
    assert qos.durability == QosDurability.TRANSIENT_LOCAL
    ((_, static),) = messages["/tf_static"]
    assert {(t.header.frame_id, t.child_frame_id) for t in static.transforms} == {
        ("world", "feature_bottom"), ("world", "feature_left"), ("world", "link0")}
    pairs = _header_stamps(messages)
    assert len(pairs) > len(messages["/tf"]) and all(record == header for record, header in pairs)
    bad = CliRunner().invoke(cli, ["execute", str(plan), "--task", task, "--sim", "--record", str(tmp_path / "x.mcap"),
                                   "--stamp", "soon"])
    assert bad.exit_code == 2 and "--stamp" in bad.output and "expected Unix seconds" in bad.output


def test_a_recording_is_stamped_from_when_the_run_started_by_default(tmp_path):
    """Without a start a recording's stamps count from its first acknowledgement, less the stream's
    time then: now, not 1970."""
    from stablepush.execution.bags import RunRecording
    from stablepush.execution.stream import ArmWaypoint

    recording = RunRecording()
    pose = [0.4, 0.0, 0.3, 1.0, 0.0, 0.0, 0.0]
    before = time.time_ns()
    for k in range(3):
        recording(ArmWaypoint(seq=k, t=0.01 * (k + 1), step=0, completes=False, phase="move", pose=tuple(pose)),
                  {"ee_pose": pose}, None)
    after = time.time_ns()
    recording.write(tmp_path / "run.mcap", {"success": None})
    _, messages, _, _ = _read(tmp_path / "run.mcap")
    stamps = [stamp for stamp, _ in messages["/stablepush/gripper_pose"]]
    assert before <= stamps[0] <= after and np.diff(stamps).tolist() == [10_000_000, 10_000_000]


def test_every_quaternion_topic_is_continuous_past_half_a_turn(tmp_path):
    """A plan that turns the object 200 deg in the grasp: on /tf (world -> gripper and gripper ->
    object) each quaternion lies in the hemisphere of the one before."""
    import dataclasses

    from stablepush.execution.bags import write_bag

    task = shipped("pivoting")
    turned = dataclasses.replace(task, goal=(0.0, 0.0, 200.0), planner=task.planner.replace(step=[1.0, 5.0]))
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
