"""Your arm, your cell: plans run on arms the tests make up (generated_arms.py: a 6-joint URDF and
a 7-joint MJCF of other link lengths and joint axes), on both engines; the joint trajectory put
through forward kinematics computed by Drake's own parser from the lab's original file, not by the
tree stablepush builds; cells the arm cannot work in refused before any motion; the reference
bridge over a joint-level interface; and the robot's fields checked by name."""
import math
import re
import xml.etree.ElementTree as ET

import numpy as np
import pytest
import yaml
from click.testing import CliRunner

import stablepush as sp
from stablepush.errors import TaskError
from stablepush.frames import pose_to_matrix
from stablepush.plan import plan_task
from stablepush.task import Robot, with_robot
from stablepush_cli.main import cli

from conftest import TASKS, shipped
from generated_arms import mjcf_arm, urdf_arm

mujoco = pytest.importorskip("mujoco")

TASK = "horizontal-offset-low-mu"
# name -> (writer, seed, joint axes, base: x y z mm, yaw deg)
ARMS = {
    "6-joint URDF": (urdf_arm, 3, ("z", "y", "y", "z", "y", "z"), [20.0, -10.0, 5.0, 15.0], "a6.urdf"),
    "7-joint MJCF": (mjcf_arm, 5, ("z", "x", "z", "-x", "z", "x", "z"), [0.0, 0.0, 0.0, 0.0], "a7.xml"),
}


@pytest.fixture(scope="module")
def arms(tmp_path_factory):
    folder = tmp_path_factory.mktemp("arms")
    out = {}
    for name, (write, seed, axes, base, file_name) in ARMS.items():
        out[name] = {**write(folder / file_name, seed, axes), "base": base}
    return out


def _task_file(folder, name: str = TASK, **environment):
    """A shipped task file with its environment section changed, written into `folder`."""
    data = yaml.safe_load((TASKS / f"{name}.yaml").read_text())
    data.setdefault("environment", {}).update(environment)
    path = folder / f"{name}.yaml"
    path.write_text(yaml.safe_dump(data))
    return path


def _on(arm: dict, task_name: str = TASK):
    return with_robot(shipped(task_name), arm["model"], arm["flange"], arm["tcp"], arm["base"])


def _X_FG(tcp) -> np.ndarray:
    from scipy.spatial.transform import Rotation

    X = np.eye(4)
    X[:3, :3] = Rotation.from_euler("xyz", tcp[3:], degrees=True).as_matrix()
    X[:3, 3] = np.asarray(tcp[:3]) / 1e3
    return X


def _drake_forward(robot: Robot, joint_names, rows):
    """G's world pose [4x4] for each row of joint positions: Drake's parser reads the lab's own
    file (URDF or MJCF), its root welded at the robot's base; G is the flange's frame times the TCP."""
    d = pytest.importorskip("pydrake.all")
    plant = d.MultibodyPlant(0.0)
    parser = d.Parser(plant)
    (instance,) = parser.AddModels(robot.model)
    if robot.model.endswith(".urdf"):
        x, y, z, yaw = robot.base
        X_WB = d.RigidTransform(d.RollPitchYaw(0, 0, math.radians(yaw)), [x / 1e3, y / 1e3, z / 1e3])
        plant.WeldFrames(plant.world_frame(), plant.GetFrameByName("base", instance), X_WB)
    else:
        assert robot.base == (0.0, 0.0, 0.0, 0.0)  # an MJCF's root body stands where its file says
    plant.Finalize()
    context = plant.CreateDefaultContext()
    flange = plant.GetFrameByName(robot.flange, instance)
    X_FG = _X_FG(robot.tcp)
    for q in rows:
        for name, value in zip(joint_names, q):
            plant.GetJointByName(name, instance).set_angle(context, float(value))
        yield flange.CalcPoseInWorld(context).GetAsMatrix4() @ X_FG


def _within(T, pose, mm=0.01, deg=0.01) -> bool:
    target = pose_to_matrix(pose)
    cos = (np.trace(T[:3, :3].T @ target[:3, :3]) - 1) / 2
    return (np.linalg.norm(T[:3, 3] - target[:3, 3]) * 1e3 <= mm
            and math.degrees(math.acos(max(-1.0, min(1.0, cos)))) <= deg)


@pytest.mark.slow
@pytest.mark.parametrize("engine", ["mujoco", "drake"])
@pytest.mark.parametrize("name", list(ARMS))
def test_a_generated_arm_runs_a_shipped_task_open_loop_within_half_a_millimetre(arms, name, engine):
    """The task on the lab's arm, servoed by the simulator (its joints from the model, the jaws on
    its flange at the TCP, its base where the cell puts it), lands within 0.5 mm and 0.5 deg."""
    if engine == "drake":
        pytest.importorskip("pydrake.all")
    from stablepush.execution.run import RunOptions, run_plan
    from stablepush.sim.local_arm import SimulatedArm

    task = _on(arms[name])
    plan = plan_task(task, seed=1)
    arm = SimulatedArm(engine, robot=task.environment.robot)
    run = run_plan(task, plan, arm, RunOptions(success_tolerance=(0.5, 0.5)))
    assert len(arm.state()["joints"]) == len(ARMS[name][2])
    assert run.fault is None, run.fault
    error = run.report.final_error
    assert run.report.success and error["distance"] <= 0.5 and abs(error["theta"]) <= 0.5, error


@pytest.mark.slow
@pytest.mark.parametrize("engine", ["mujoco", "drake"])
@pytest.mark.parametrize("name", list(ARMS))
def test_a_generated_arm_passes_the_friction_contracts_pivot_on_the_arm(arms, name, engine):
    """The contract's last part on the lab's arm: the first 30 deg of the pivot, on its servos."""
    if engine == "drake":
        pytest.importorskip("pydrake.all")
    from stablepush.sim import fidelity

    result = fidelity.pivot_on_arm(_on(arms[name], "pivoting"), engine=engine)
    assert result.error_mm <= fidelity.ARM_PIVOT_LIMIT_MM, result
    assert abs(result.error_deg) <= fidelity.ARM_PIVOT_LIMIT_DEG, result


@pytest.mark.parametrize("name", list(ARMS))
def test_the_joint_trajectory_through_the_labs_own_model_reproduces_the_cartesian_one(arms, name):
    from stablepush.kinematics.cell_path import joint_path

    task = _on(arms[name])
    plan = plan_task(task, seed=1)
    path = joint_path(task, plan)
    traj = sp.trajectory(task, plan)
    assert path.joints == tuple(f"{'joint_' if name.endswith('URDF') else 'q'}{i + 1}"
                                for i in range(len(ARMS[name][2])))
    rows = range(0, len(path), 7)
    for k, T in zip(rows, _drake_forward(task.environment.robot, path.joints, path.q[list(rows)])):
        assert _within(T, [*traj.position[k], *traj.quaternion_wxyz[k]]), k


def test_the_joint_trajectory_bag_read_back_by_rosbags_matches_forward_kinematics(arms, tmp_path):
    pytest.importorskip("rosbags")
    from rosbags.highlevel import AnyReader

    arm = arms["6-joint URDF"]
    task_file = TASKS / f"{TASK}.yaml"
    plan_file, bag = tmp_path / "p.json", tmp_path / "j.mcap"
    runner = CliRunner()
    assert runner.invoke(cli, ["plan", str(task_file), "-o", str(plan_file)]).exit_code == 0
    result = runner.invoke(cli, ["trajectory", str(plan_file), "--task", str(task_file), "--joints", "-o", str(bag),
                                 "--robot", arm["model"], "--flange", arm["flange"], "--tcp", *map(str, arm["tcp"]),
                                 "--base", *map(str, arm["base"])])
    assert result.exit_code == 0, result.output
    with AnyReader([bag]) as reader:
        (connection,) = [c for c in reader.connections if c.topic == "/stablepush/joint_trajectory"]
        assert connection.msgtype == "trajectory_msgs/msg/JointTrajectory"
        (message,) = [reader.deserialize(raw, c.msgtype) for c, _, raw in reader.messages(connections=[connection])]
    names = list(message.joint_names)
    assert names == [f"joint_{i}" for i in range(1, 7)]
    times = [p.time_from_start.sec + p.time_from_start.nanosec * 1e-9 for p in message.points]
    assert all(b > a for a, b in zip(times, times[1:]))
    task = _on(arm)
    traj = sp.trajectory(task, sp.load_plan(plan_file))
    assert len(message.points) == len(traj)
    rows = list(range(0, len(traj), 11))
    forward = _drake_forward(task.environment.robot, names, [message.points[k].positions for k in rows])
    for k, T in zip(rows, forward):
        assert _within(T, [*traj.position[k], *traj.quaternion_wxyz[k]]), k


def test_a_fixture_out_of_the_arms_reach_is_refused_before_any_motion(arms, tmp_path):
    """The feature 1.5 m out: `execute --sim` on the 7-joint arm exits 2 naming where the arm gives
    up, and no world was built (nothing moved)."""
    arm = arms["7-joint MJCF"]
    task_file = _task_file(tmp_path, features={"left": [1500, 0, 300, 0]})
    plan_file = tmp_path / "far.json"
    runner = CliRunner()
    assert runner.invoke(cli, ["plan", str(task_file), "-o", str(plan_file)]).exit_code == 0
    robot = ["--robot", arm["model"], "--flange", arm["flange"], "--tcp", *map(str, arm["tcp"])]
    result = runner.invoke(cli, ["execute", str(plan_file), "--task", str(task_file), "--sim", *robot])
    assert result.exit_code == 2, result.output
    assert re.search(r"the arm cannot follow the plan: .*plan step \d+, move\) (out of reach|joint q\d would turn|no joint "
                     r"positions)", result.output)
    assert "world built" not in result.output
    checked = runner.invoke(cli, ["check-cell", str(plan_file), "--task", str(task_file), *robot])
    assert checked.exit_code == 2 and "the arm cannot follow the plan" in checked.output


def test_an_arm_server_named_by_a_model_is_checked_before_it_is_reached(arms, tmp_path):
    """With --arm and --robot the plan is checked against the model first: nothing listens on the
    port, and the refusal (exit 2), not the connection (exit 3), is what the run says."""
    import socket

    arm = arms["7-joint MJCF"]
    task_file = _task_file(tmp_path, features={"left": [1500, 0, 300, 0]})
    plan_file = tmp_path / "far.json"
    runner = CliRunner()
    assert runner.invoke(cli, ["plan", str(task_file), "-o", str(plan_file)]).exit_code == 0
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    result = runner.invoke(cli, ["execute", str(plan_file), "--task", str(task_file), "--arm", f"127.0.0.1:{port}",
                                 "--robot", arm["model"], "--flange", arm["flange"], "--tcp", *map(str, arm["tcp"])])
    assert result.exit_code == 2, result.output
    assert "the arm cannot follow the plan" in result.output


class _SimulatedJoints:
    """A JointInterface over a simulated arm, as a lab's would be over its driver."""

    def __init__(self, task, plan, engine="mujoco"):
        from stablepush.execution.world import place_features, scene_description
        from stablepush.sim.engines import make_arm

        steps = list(plan.waypoints)
        scene = scene_description(task, place_features(task, steps), steps[0].pose)
        self.sim = make_arm(engine, scene, robot=task.environment.robot)
        self.joint_names = self.sim.arm.joints
        self.sent = 0

    def read_joints(self):
        return self.sim.state()["joints"]

    def send(self, positions, duration):
        self.sim.advance(duration, np.asarray(positions))
        self.sent += 1

    def halt(self):
        self.sim.stop()

    def wrist_force(self):
        return self.sim.state(contact_force=True)["contact_force"]

    def object_in_grasp(self):
        return self.sim.state()["object_in_grasp"]

    def close(self):
        pass


def test_the_reference_bridge_runs_a_plan_on_a_joint_level_interface(arms):
    from stablepush.bridge import JointInterface, JointTrajectoryArm
    from stablepush.execution.run import RunOptions, run_plan

    task = _on(arms["6-joint URDF"])
    plan = plan_task(task, seed=1)
    joints = _SimulatedJoints(task, plan)
    JointInterface.register(_SimulatedJoints)
    run = run_plan(task, plan, JointTrajectoryArm(joints, task.environment.robot),
                   RunOptions(pace=False, success_tolerance=(0.5, 0.5)))
    assert run.fault is None, run.fault
    assert run.report.success and joints.sent == run.report.waypoints


def _bag_messages(bag):
    """topic -> (its connection, its messages), read back with rosbags' own reader."""
    from rosbags.highlevel import AnyReader

    out = {}
    with AnyReader([bag]) as reader:
        for connection in reader.connections:
            out[connection.topic] = (connection, [reader.deserialize(raw, connection.msgtype) for _, _, raw in
                                                  reader.messages(connections=[connection])])
    return out


def _base_transform(messages):
    (static,) = messages["/tf_static"][1]
    (base,) = [t for t in static.transforms if t.child_frame_id == "base"]
    assert base.header.frame_id == "world"
    return base.transform


def test_a_run_on_a_labs_arm_records_its_joints_and_its_urdf_for_a_viewer(arms, tmp_path):
    """Issue 68, item 5: a run through the joint-level bridge, recorded (BagRecording) and read back
    with rosbags: /joint_states names the URDF's joints with the positions the arm reported at each
    waypoint, /robot_description holds the URDF's text once, offered transient local as
    robot_state_publisher offers it, and /tf_static puts the URDF's root link where the robot
    stands; `trajectory --joints -o X.mcap` gives its JointTrajectory in that link and the URDF too."""
    pytest.importorskip("rosbags")
    from rosbags.interfaces import QosDurability

    from stablepush.bridge import JointInterface, JointTrajectoryArm
    from stablepush.execution.run import BagRecording, RunOptions, run_plan

    arm = arms["6-joint URDF"]
    task = _on(arm)
    plan = plan_task(task, seed=1)
    joints = _SimulatedJoints(task, plan)
    JointInterface.register(_SimulatedJoints)
    bag = tmp_path / "run.mcap"
    run = run_plan(task, plan, JointTrajectoryArm(joints, task.environment.robot),
                   RunOptions(pace=False, success_tolerance=(0.5, 0.5)), [BagRecording(str(bag))])
    assert run.fault is None and run.written, run.fault
    messages = _bag_messages(bag)
    connection, states = messages["/joint_states"]
    assert connection.msgtype == "sensor_msgs/msg/JointState" and len(states) == run.report.waypoints
    assert all(list(s.name) == [f"joint_{i}" for i in range(1, 7)] for s in states)
    reported = np.array([s.joints for s in run.recording.samples])
    assert np.allclose([s.position for s in states], reported) and np.ptp(reported, axis=0).max() > 0.1
    connection, (description,) = messages["/robot_description"]
    assert connection.msgtype == "std_msgs/msg/String" and description.data == open(arm["model"]).read()
    (qos,) = connection.ext.offered_qos_profiles
    assert qos.durability == QosDurability.TRANSIENT_LOCAL
    base = _base_transform(messages)
    x, y, z, yaw = arm["base"]
    assert [base.translation.x, base.translation.y, base.translation.z] == pytest.approx([x / 1e3, y / 1e3, z / 1e3])
    assert [base.rotation.w, base.rotation.z] == pytest.approx([math.cos(math.radians(yaw) / 2),
                                                                math.sin(math.radians(yaw) / 2)])

    task_file = TASKS / f"{TASK}.yaml"
    plan_file, planned = tmp_path / "p.json", tmp_path / "j.mcap"
    assert CliRunner().invoke(cli, ["plan", str(task_file), "-o", str(plan_file)]).exit_code == 0
    result = CliRunner().invoke(cli, ["trajectory", str(plan_file), "--task", str(task_file), "--joints", "-o",
                                      str(planned), "--robot", arm["model"], "--flange", arm["flange"], "--tcp",
                                      *map(str, arm["tcp"]), "--base", *map(str, arm["base"])])
    assert result.exit_code == 0, result.output
    messages = _bag_messages(planned)
    (trajectory,) = messages["/stablepush/joint_trajectory"][1]
    assert trajectory.header.frame_id == "base"
    assert messages["/robot_description"][1][0].data == open(arm["model"]).read()
    assert _base_transform(messages).translation.x == pytest.approx(arm["base"][0] / 1e3)


def test_a_run_on_an_mjcf_arm_records_its_joints_and_no_urdf(arms, tmp_path):
    """An MJCF arm has no URDF to give a viewer: its run's bag has /joint_states (and its base link
    in /tf_static), and no /robot_description."""
    pytest.importorskip("rosbags")
    from stablepush.execution.run import BagRecording, RunOptions, run_plan
    from stablepush.kinematics.robot import arm_model
    from stablepush.sim.local_arm import SimulatedArm

    task = _on(arms["7-joint MJCF"])
    plan = plan_task(task, seed=1)
    bag = tmp_path / "run.mcap"
    run = run_plan(task, plan, SimulatedArm(robot=task.environment.robot), RunOptions(), [BagRecording(str(bag))])
    assert run.fault is None and run.written
    messages = _bag_messages(bag)
    assert "/robot_description" not in messages
    names = arm_model(task.environment.robot).joints
    assert len(names) == 7 and all(tuple(s.name) == names for s in messages["/joint_states"][1])
    assert len(messages["/joint_states"][1]) == run.report.waypoints
    (static,) = messages["/tf_static"][1]
    assert arm_model(task.environment.robot).base_link in {t.child_frame_id for t in static.transforms}


def test_the_bridge_refuses_an_interface_of_other_joints_and_ends_a_failing_one_in_a_fault(arms):
    from stablepush.bridge import JointTrajectoryArm
    from stablepush.errors import ArmFault
    from stablepush.execution.arm import ArmError
    from stablepush.execution.run import RunOptions, run_plan

    task = _on(arms["6-joint URDF"])
    plan = plan_task(task, seed=1)
    joints = _SimulatedJoints(task, plan)
    joints.joint_names = ("a", "b")
    with pytest.raises(ArmError, match="names the joints"):
        JointTrajectoryArm(joints, task.environment.robot)
    joints.joint_names = joints.sim.arm.joints

    def broken(positions, duration):
        raise ConnectionError("controller went away")

    joints.send = broken
    run = run_plan(task, plan, JointTrajectoryArm(joints, task.environment.robot), RunOptions(pace=False))
    assert isinstance(run.fault, ArmFault) and "send: ConnectionError: controller went away" in str(run.fault)


def test_the_shipped_arm_is_the_default_and_moves_with_its_base():
    """No robot: arm.xml as it is. The shipped arm on a raised, turned base is built by the same
    path as a lab's and still lands (its IK finds the posture from the base's frame)."""
    from stablepush.execution.run import RunOptions, run_plan
    from stablepush.kinematics.robot import ARM_XML, arm_model
    from stablepush.sim.local_arm import SimulatedArm

    assert ET.tostring(arm_model(None).tree) == ET.tostring(ET.parse(ARM_XML).getroot())
    task = with_robot(shipped(TASK), base=[-30.0, 20.0, 10.0, 8.0])
    assert arm_model(task.environment.robot).joints == ("j1", "j2", "j3", "j4", "j5", "j6", "j7")
    plan = plan_task(task, seed=1)
    run = run_plan(task, plan, SimulatedArm(robot=task.environment.robot), RunOptions(success_tolerance=(0.5, 0.5)))
    assert run.fault is None and run.report.success


def test_a_task_file_names_its_arm_relative_to_itself(arms, tmp_path):
    arm = arms["6-joint URDF"]
    (tmp_path / "cell").mkdir()
    model = tmp_path / "cell" / "arm.urdf"
    model.write_text(open(arm["model"]).read())
    task_file = _task_file(tmp_path / "cell", robot={"model": "arm.urdf", "flange": "tool0",
                                                     "tcp": [0, 0, 110, 0, 180, 0]})
    task = sp.load_task(task_file)
    assert task.environment.robot.model == str(model.resolve())
    assert task.environment.robot.base == (0.0, 0.0, 0.0, 0.0)


@pytest.mark.parametrize("section, field", [
    ("{model: arm.urdf, tcp: [0, 0, 110, 0, 180, 0]}", "environment.robot.flange"),
    ("{model: arm.urdf, flange: tool0}", "environment.robot.tcp"),
    ("{model: nowhere.urdf, flange: tool0, tcp: [0, 0, 110, 0, 180, 0]}", "environment.robot.model"),
    ("{model: arm.stl, flange: tool0, tcp: [0, 0, 110, 0, 180, 0]}", "environment.robot.model"),
    ("{model: arm.urdf, flange: tool0, tcp: [0, 0, 110, 0, 180]}", "environment.robot.tcp"),
    ("{model: arm.urdf, flange: tool0, tcp: [0, 0, .inf, 0, 180, 0]}", "environment.robot.tcp[2]"),
    ("{base: [0, 0, 0]}", "environment.robot.base"),
    ("{max_joint_speed: 0}", "environment.robot.max_joint_speed"),
    ("{reach: 3}", "environment.robot.reach"),
])
def test_a_bad_robot_section_is_refused_naming_the_field(tmp_path, section, field):
    (tmp_path / "arm.urdf").write_text("<robot name='x'/>")
    task_file = _task_file(tmp_path, robot=yaml.safe_load(section))
    with pytest.raises(TaskError) as refused:
        sp.load_task(task_file)
    assert f": {field}: " in str(refused.value), str(refused.value)


@pytest.mark.parametrize("model, flange, match", [
    ('<mujoco><worldbody><body name="b"><freejoint/><geom size="0.1"/><body name="f"/></body></worldbody></mujoco>',
     "f", "free joint"),
    ('<mujoco><worldbody><body name="b"><joint axis="0 0 1"/><geom size="0.1"/><body name="f"/></body></worldbody>'
     '</mujoco>', "f", "has no name"),
    ('<mujoco><worldbody><body name="b"><joint name="j"/><geom size="0.1"/></body></worldbody></mujoco>', "tool0",
     "no link 'tool0'"),
    ('<mujoco><worldbody><body name="b"><joint name="j" type="banana"/></body></worldbody></mujoco>', "b",
     "MuJoCo cannot compile"),
])
def test_a_model_that_cannot_carry_the_jaws_is_refused_naming_why(tmp_path, model, flange, match):
    from stablepush.kinematics.robot import RobotError
    from stablepush.sim.local_arm import SimulatedArm

    path = tmp_path / "arm.xml"
    path.write_text(model)
    robot = Robot(model=str(path), flange=flange)
    with pytest.raises(RobotError, match=match):
        SimulatedArm(robot=robot)


def test_the_sim_arm_server_serves_a_labs_arm_and_a_run_over_tcp_lands(arms):
    """`stablepush sim-arm --robot ...` in a thread: a run over the protocol, checked against the
    same model first (ModelledArm), lands."""
    from stablepush.execution import TcpArm
    from stablepush.execution.run import RunOptions, run_plan
    from stablepush.kinematics.cell_path import ModelledArm, modelled
    from stablepush.sim.server import running_sim_arm

    task = _on(arms["7-joint MJCF"])
    robot = task.environment.robot
    assert modelled(TcpArm("127.0.0.1", 1), Robot()).__class__ is TcpArm  # no model named: not checked
    plan = plan_task(task, seed=1)
    with running_sim_arm(log=lambda text: None, robot=robot) as server:
        arm = modelled(TcpArm(server.host, server.port), robot)
        assert isinstance(arm, ModelledArm)
        run = run_plan(task, plan, arm, RunOptions(pace=False, success_tolerance=(0.5, 0.5)))
    assert run.fault is None and run.report.success, run.fault


@pytest.mark.slow
def test_evaluate_runs_its_trials_on_the_arm_it_is_given(arms, tmp_path):
    """Every trial's world is built on the lab's arm: a robot whose flange the model lacks is
    refused before any trial, and a good one lands the trials."""
    arm = arms["6-joint URDF"]
    task_file = TASKS / f"{TASK}.yaml"
    runner = CliRunner()
    common = ["evaluate", str(task_file), "--trials", "2", "--workers", "1", "--quiet", "--robot", arm["model"],
              "--tcp", *map(str, arm["tcp"])]
    refused = runner.invoke(cli, [*common, "--flange", "link9"])
    assert refused.exit_code == 2 and "no link 'link9'" in refused.output, refused.output
    result = runner.invoke(cli, [*common, "--flange", arm["flange"], "--json", str(tmp_path / "e.json")])
    assert result.exit_code == 0, result.output
    assert "landed 2 of 2" in result.output


@pytest.mark.parametrize("command", ["check-cell", "execute"])
def test_an_output_naming_the_robot_model_is_refused_before_any_work(arms, tmp_path, command):
    """--json (or -o) naming the arm's URDF, given as --robot or as the task's environment.robot:
    exit 2 "refusing to write over it" before anything runs, the model as it was."""
    import shutil

    arm = arms["6-joint URDF"]
    model = tmp_path / "arm6.urdf"
    shutil.copy(arm["model"], model)
    text = model.read_text()
    task_file = _task_file(tmp_path)
    plan_file = tmp_path / "t.json"
    runner = CliRunner()
    assert runner.invoke(cli, ["plan", str(task_file), "-o", str(plan_file)]).exit_code == 0
    robot = ["--robot", str(model), "--flange", arm["flange"], "--tcp", *map(str, arm["tcp"])]
    out = {"check-cell": ["--json"], "execute": ["--sim", "--json"]}[command]
    result = runner.invoke(cli, [command, str(plan_file), "--task", str(task_file), *robot, *out, str(model)])
    assert result.exit_code == 2, result.output
    assert "a robot model this process read; refusing to write over it" in result.output, result.output
    assert "world built" not in result.output
    assert model.read_text() == text
