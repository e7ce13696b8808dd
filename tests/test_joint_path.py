"""The shipped arm's joints along a plan (stablepush.kinematics.cell_path): the joint trajectory
reproduces the Cartesian one through forward kinematics computed apart from the solver, moves
continuously, and a plan the arm cannot follow in its cell is refused before any motion, naming
where and why."""
import dataclasses
import math

import numpy as np
import pytest
from click.testing import CliRunner

import stablepush as sp
from stablepush.frames import pose_to_matrix
from stablepush.plan import plan_task
from stablepush_cli.main import cli

from conftest import TASKS, shipped

mujoco = pytest.importorskip("mujoco")


def _forward(task, plan, path):
    """G's world pose [4x4] at each sample, through MuJoCo's own kinematics of a fresh model."""
    from stablepush.execution.world import place_features, scene_description
    from stablepush.kinematics import cell_model

    scene = scene_description(task, place_features(task, list(plan.waypoints)), plan.waypoints[0].pose)
    model = mujoco.MjModel.from_xml_string(cell_model.build_mjcf(scene))
    data = mujoco.MjData(model)
    adr = [model.jnt_qposadr[model.joint(j).id] for j in path.joints]
    site = model.site(cell_model.GRIPPER_SITE).id
    for q in path.q:
        data.qpos[adr] = q
        mujoco.mj_kinematics(model, data)
        T = np.eye(4)
        T[:3, :3], T[:3, 3] = data.site_xmat[site].reshape(3, 3), data.site_xpos[site]
        yield T


@pytest.mark.parametrize("name", ["horizontal-offset-low-mu", "horizontal-offset-high-mu", "t-shaped",
                                  "large-manipulation"])
def test_the_joint_trajectory_reproduces_the_cartesian_one_and_moves_continuously(name):
    from stablepush.kinematics.cell_path import joint_path
    from stablepush.task.model import Robot

    task = shipped(name)
    plan = plan_task(task, seed=1)
    path = joint_path(task, plan)
    traj = sp.trajectory(task, plan)
    assert len(path) == len(traj) and path.q.shape == (len(traj), 7)
    for T, p, q in zip(_forward(task, plan, path), traj.position, traj.quaternion_wxyz):
        target = pose_to_matrix([*p, *q])
        assert np.linalg.norm(T[:3, 3] - target[:3, 3]) < 1e-5  # 0.01 mm
        cos = (np.trace(T[:3, :3].T @ target[:3, :3]) - 1) / 2
        assert math.degrees(math.acos(min(1.0, cos))) < 0.01
    speed = np.abs(np.diff(path.q, axis=0)).max() * traj.rate_hz
    assert speed <= Robot().max_joint_speed and path.peak_speed == pytest.approx(speed)


def test_a_feature_out_of_the_arms_reach_is_refused_before_any_motion():
    """A feature 1.5 m away, past the shipped arm's 870 mm from its shoulder: the straight move
    out to it leaves the reach, and the check says by how much before any joint's speed or limit
    is named (the elbow straightening toward its singularity would have turned j1 too fast first)."""
    from stablepush.kinematics.cell_path import CellError, joint_path

    task = shipped("horizontal-offset-high-mu")
    far = dataclasses.replace(task, environment={**task.environment.as_dict(), "features": {"left": [1500, 0, 300, 0]}})
    with pytest.raises(CellError, match=r"\(sample \d+, plan step 0, move\) out of reach: the plan's TCP poses lie "
                                        r"up to \d+ mm beyond the arm's reach of 870 mm from its joint j2 at \[0, 0, 300\] mm"):
        joint_path(far, plan_task(far, seed=1))
    beyond = dataclasses.replace(far, environment={**far.environment.as_dict(), "home": [1400, 0, 300]})
    with pytest.raises(CellError, match=r"\(sample 0, plan step 0, move\) out of reach"):
        joint_path(beyond, plan_task(beyond, seed=1))  # G's start itself lies out of reach


def test_a_link_through_a_fixture_is_refused_naming_the_link_and_the_fixture(tmp_path):
    """The pivot with the default 20 mm retract (the shipped task retracts 10 mm for this): after its
    last push the gripper, turned 90 deg, retracts with its wrist (link6) 1 mm into the left
    feature's solid, which stands between the jaws. The simulated arm does not collide its links;
    the cell check says what a real cell would: `trajectory --joints` writes nothing, and `execute`
    exits 2 before the arm is reached (no world built)."""
    task_file = tmp_path / "pivot20.yaml"
    task_file.write_text((TASKS / "pivoting.yaml").read_text().replace("retract: 10", "retract: 20"))
    plan_file = tmp_path / "p.json"
    runner = CliRunner()
    assert runner.invoke(cli, ["plan", str(task_file), "-o", str(plan_file)]).exit_code == 0
    result = runner.invoke(cli, ["trajectory", str(plan_file), "--task", str(task_file), "-o",
                                 str(tmp_path / "p.csv"), "--joints"])
    assert result.exit_code == 2, result.output
    assert "link link6 runs 1.0 mm into feature_left" in result.output and "retract" in result.output
    assert not (tmp_path / "p.csv").exists()
    run = runner.invoke(cli, ["execute", str(plan_file), "--task", str(task_file), "--sim"])
    assert run.exit_code == 2 and "link link6 runs 1.0 mm into feature_left" in run.output, run.output
    assert "world built" not in run.output


def test_joints_are_written_as_columns_and_other_outputs_are_refused(tmp_path):
    task_file = TASKS / "t-shaped.yaml"
    plan_file = tmp_path / "t.json"
    runner = CliRunner()
    assert runner.invoke(cli, ["plan", str(task_file), "-o", str(plan_file)]).exit_code == 0
    out = tmp_path / "t.csv"
    result = runner.invoke(cli, ["trajectory", str(plan_file), "--task", str(task_file), "-o", str(out), "--joints"])
    assert result.exit_code == 0, result.output
    header = out.read_text().splitlines()[0].split(",")
    assert header == (["t"] + [f"j{k}_rad{unit}" for unit in ("", "_s", "_s2") for k in range(1, 8)]
                      + ["phase", "step"])
    quat = runner.invoke(cli, ["trajectory", str(plan_file), "--task", str(task_file), "-o", str(out), "--joints",
                               "--quat", "wxyz"])
    assert quat.exit_code == 2 and "--joints" in quat.output


def test_the_bags_joint_trajectory_read_back_by_rosbags_carries_out_the_gripper_poses(tmp_path):
    """Read with rosbags' own reader (not our writer): the JointTrajectory's points, through forward
    kinematics, are the bag's gripper poses; /joint_states holds the same positions, sample by sample."""
    from rosbags.highlevel import AnyReader

    task_file = TASKS / "horizontal-offset-low-mu.yaml"
    plan_file, bag = tmp_path / "p.json", tmp_path / "p.mcap"
    runner = CliRunner()
    assert runner.invoke(cli, ["plan", str(task_file), "-o", str(plan_file)]).exit_code == 0
    result = runner.invoke(cli, ["trajectory", str(plan_file), "--task", str(task_file), "-o", str(bag), "--joints"])
    assert result.exit_code == 0, result.output
    with AnyReader([bag]) as reader:
        def messages(topic):
            connections = [c for c in reader.connections if c.topic == topic]
            return [reader.deserialize(raw, c.msgtype) for c, _, raw in reader.messages(connections=connections)]

        (trajectory,) = messages("/stablepush/joint_trajectory")
        states = messages("/joint_states")
        poses = messages("/stablepush/gripper_pose")
    assert list(trajectory.joint_names) == [f"j{k}" for k in range(1, 8)] == list(states[0].name)
    times = [p.time_from_start.sec + p.time_from_start.nanosec * 1e-9 for p in trajectory.points]
    assert all(b > a for a, b in zip(times, times[1:])) and len(states) == len(poses) == len(times)
    task = sp.load_task(task_file)
    plan = sp.load_plan(plan_file)
    path = dataclasses.make_dataclass("Path", ["joints", "q"])(
        [f"j{k}" for k in range(1, 8)], np.array([p.positions for p in trajectory.points]))
    for T, pose, state, point in zip(_forward(task, plan, path), poses, states, trajectory.points):
        assert np.allclose(state.position, point.positions)
        p, q = pose.pose.position, pose.pose.orientation
        target = pose_to_matrix([p.x, p.y, p.z, q.w, q.x, q.y, q.z])
        assert np.linalg.norm(T[:3, 3] - target[:3, 3]) < 1e-5
        cos = (np.trace(T[:3, :3].T @ target[:3, :3]) - 1) / 2
        assert math.degrees(math.acos(min(1.0, cos))) < 0.01


def _central(t, values):
    """d values / dt at the inner samples from their neighbours, as a test writes it out."""
    return (values[2:] - values[:-2]) / (t[2:] - t[:-2])[:, None]


def test_the_bags_joint_trajectory_carries_velocities_and_accelerations_of_its_timing_in_the_base_link(tmp_path):
    """Issue 68, item 5: read back with rosbags, each JointTrajectory point's velocities are the
    positions' change over time_from_start (central differences; the first from the start at rest
    at t = 0, where G's start pose puts the joints), its accelerations the velocities' likewise, both
    zero at the last point, where the arm stays; the trajectory is given in the arm's base link
    (arm.xml's link0); /joint_states carries the same velocities; the CSV the same numbers."""
    import csv

    from rosbags.highlevel import AnyReader

    from stablepush.kinematics.cell_path import joint_path

    task_file = TASKS / "horizontal-offset-low-mu.yaml"
    plan_file, bag, table = tmp_path / "p.json", tmp_path / "p.mcap", tmp_path / "p.csv"
    runner = CliRunner()
    assert runner.invoke(cli, ["plan", str(task_file), "-o", str(plan_file)]).exit_code == 0
    for out in (bag, table):
        result = runner.invoke(cli, ["trajectory", str(plan_file), "--task", str(task_file), "-o", str(out), "--joints"])
        assert result.exit_code == 0, result.output
    with AnyReader([bag]) as reader:
        connections = [c for c in reader.connections if c.topic in ("/stablepush/joint_trajectory", "/joint_states")]
        read = {}
        for c, _, raw in reader.messages(connections=connections):
            read.setdefault(c.topic, []).append(reader.deserialize(raw, c.msgtype))
    (trajectory,), states = read["/stablepush/joint_trajectory"], read["/joint_states"]
    assert trajectory.header.frame_id == "link0"
    t = np.array([p.time_from_start.sec + p.time_from_start.nanosec * 1e-9 for p in trajectory.points])
    q = np.array([p.positions for p in trajectory.points])
    qd = np.array([p.velocities for p in trajectory.points])
    qdd = np.array([p.accelerations for p in trajectory.points])
    assert qd.shape == qdd.shape == q.shape
    assert np.abs(qd).max() > 0.1  # the arm moves
    assert np.allclose(qd[1:-1], _central(t, q), atol=1e-9)
    assert np.allclose(qdd[1:-1], _central(t, qd), atol=1e-6)
    assert not qd[-1].any() and not qdd[-1].any()
    task, plan = sp.load_task(task_file), sp.load_plan(plan_file)
    start = joint_path(task, plan).start
    assert np.allclose(qd[0], (q[1] - start) / t[1], atol=1e-9)
    assert np.allclose(qdd[0], qd[1] / t[1], atol=1e-6)
    assert np.allclose([s.velocity for s in states], qd)
    rows = list(csv.DictReader(table.open()))
    assert np.allclose([[float(r[f"j{k}_rad_s"]) for k in range(1, 8)] for r in rows], qd)
    assert np.allclose([[float(r[f"j{k}_rad_s2"]) for k in range(1, 8)] for r in rows], qdd)


def test_an_arm_whose_base_stands_too_far_is_out_of_reach_by_how_much_not_at_a_joint_limit(tmp_path):
    """A lab's six-joint URDF arm (joints within +-2.6 rad) with its base 3 m from the cell: no
    posture gets G there, and the refusal says so with the numbers, before IK names a joint that
    stopped at its limit. The reach is the chain's length from its shoulder (joint_2, which joint_1
    turns in place): the links on to the flange and the TCP's 110 mm, measured on the model."""
    from stablepush.kinematics.cell_path import CellError, joint_path
    from stablepush.task import with_robot

    from generated_arms import link_lengths, urdf_arm

    task = shipped("horizontal-offset-high-mu")
    plan = plan_task(task, seed=1)
    arm = urdf_arm(tmp_path / "arm.urdf", 1, ["z", "y", "y", "z", "y", "z"])
    joint_path(with_robot(task, arm["model"], arm["flange"], arm["tcp"], [0, 0, 0, 0]), plan)  # follows at home
    far = with_robot(task, arm["model"], arm["flange"], arm["tcp"], [3000, 0, 0, 0])
    with pytest.raises(CellError) as refused:
        joint_path(far, plan)
    reason = str(refused.value).split("approach) ")[1]
    lengths = link_lengths(1, 6)
    reach, shoulder = (sum(lengths[1:]) + 0.110) * 1e3, (0.08 + lengths[0]) * 1e3
    assert reason.startswith("out of reach: the plan's TCP poses lie up to ") and "limit" not in reason, reason
    assert f"beyond the arm's reach of {reach:.0f} mm from its joint joint_2 at [3000, 0, {shoulder:.0f}] mm" in reason
    assert "its base at [3000, 0, 0] mm (environment.robot.base, --base)" in reason
    beyond = float(reason.split("up to ")[1].split(" mm")[0])
    traj = sp.trajectory(far, plan)
    farthest = np.linalg.norm(np.asarray(traj.position) - [3.0, 0.0, shoulder / 1e3], axis=1).max() * 1e3
    assert beyond == pytest.approx(farthest - reach, abs=1.0)
