"""Reliability, round four (issue 69), the robot model's classes: B (encodings, bad numbers),
D (couplings), E (paths relative to the model, from any folder), F (an include that is not a
regular file) and Q (a flange whose name holds a quote). Models are the generated arms of
generated_arms.py, mutated as a lab's file might be. Each test fails on the code before its fix."""
import os
import threading

import pytest

from stablepush.task import Robot
from stablepush.task.model import Robot as RobotValue

from generated_arms import mjcf_arm, urdf_arm

mujoco = pytest.importorskip("mujoco")
from stablepush.kinematics.robot import RobotError, arm_model, robot_description  # noqa: E402

AXES6 = ("z", "y", "y", "z", "y", "z")
AXES7 = ("z", "x", "z", "-x", "z", "x", "z")


def _urdf(tmp_path, name="arm.urdf", seed=3):
    arm = urdf_arm(tmp_path / name, seed, AXES6)
    return tmp_path / name, arm


def _robot(path, arm, **changes) -> RobotValue:
    return Robot(model=str(path), flange=changes.get("flange", arm["flange"]), tcp=tuple(arm["tcp"]))


@pytest.mark.parametrize("encoding", ["ISO-8859-1", "UTF-16"])
def test_b_a_urdf_in_the_encoding_it_declares_is_read_as_declared(tmp_path, encoding):
    """Valid XML in ISO-8859-1 or UTF-16 gave exit 4 (UnicodeDecodeError)."""
    path, arm = _urdf(tmp_path)
    text = path.read_text().replace('<?xml version="1.0"?>', f'<?xml version="1.0" encoding="{encoding}"?>')
    text = text.replace('<robot name="', '<robot name="Bräcket_')
    path.write_bytes(text.encode(encoding.lower()))
    robot = _robot(path, arm)
    assert arm_model(robot).joints == tuple(f"joint_{i}" for i in range(1, 7))
    assert 'name="Bräcket_' in robot_description(robot).urdf


def test_b_a_limit_that_is_not_a_number_is_refused_naming_the_model(tmp_path):
    path, arm = _urdf(tmp_path)
    path.write_text(path.read_text().replace('velocity="2.90"', 'velocity="abc"'))
    with pytest.raises(RobotError, match=r"joint 'joint_1': limit velocity 'abc' is not a number") as error:
        arm_model(_robot(path, arm))
    assert error.value.field == "environment.robot.model"


def test_d_a_mimic_joint_in_the_arm_is_refused_by_name(tmp_path):
    """MuJoCo drops <mimic>: the joint CSV moved the mimicking joint on its own."""
    path, arm = _urdf(tmp_path)
    text = path.read_text()
    at = text.index("</joint>", text.index('name="joint_3"'))
    path.write_text(text[:at] + '<mimic joint="joint_2" multiplier="1" offset="0"/>' + text[at:])
    with pytest.raises(RobotError, match=r"joint 'joint_3' mimics 'joint_2' \(URDF <mimic>\)"):
        arm_model(_robot(path, arm))


@pytest.mark.parametrize("coupling, says", [
    ('<equality><joint joint1="q2" joint2="q4" polycoef="0 1 0 0 0"/></equality>', "an <equality> joint constraint on "
                                                                                     "joint 'q2'"),
    ('<tendon><fixed name="couple" range="-0.1 0.1" limited="true"><joint joint="q3" coef="1"/>'
     '<joint joint="q5" coef="-1"/></fixed></tendon>', "tendon 'couple' limits joint 'q3'"),
])
def test_d_an_mjcf_coupling_of_the_arms_joints_is_refused_by_name(tmp_path, coupling, says):
    """An <equality> lock or a tendon limit: check-cell said "follows", execute exit 3."""
    arm = mjcf_arm(tmp_path / "arm.xml", 5, AXES7)
    path = tmp_path / "arm.xml"
    path.write_text(path.read_text().replace("</worldbody>", "</worldbody>" + coupling))
    with pytest.raises(RobotError, match=says):
        arm_model(_robot(path, arm))


def test_e_a_urdf_meshdir_relative_to_the_model_works_from_any_folder(tmp_path, monkeypatch):
    """<mujoco><compiler meshdir="meshes"/> compiled only from the model's folder."""
    trimesh = pytest.importorskip("trimesh")
    path, arm = _urdf(tmp_path)
    (tmp_path / "meshes").mkdir()
    trimesh.creation.box([0.05, 0.05, 0.02]).export(tmp_path / "meshes" / "cap.stl")
    text = path.read_text().replace('<link name="tool0"/>', '<link name="tool0"><collision><geometry>'
                                    '<mesh filename="package://lab/meshes/cap.stl"/></geometry></collision></link>')
    path.write_text(text.replace("</robot>", '<mujoco><compiler meshdir="meshes"/></mujoco></robot>'))
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    monkeypatch.chdir(elsewhere)
    assert len(arm_model(_robot(path, arm)).joints) == 6


def test_f_an_include_that_names_a_fifo_is_refused_not_waited_on(tmp_path):
    """MuJoCo's open of the FIFO waited for a writer forever (killed after 60 s)."""
    arm = mjcf_arm(tmp_path / "arm.xml", 5, AXES7)
    path = tmp_path / "arm.xml"
    os.mkfifo(tmp_path / "parts.xml")
    path.write_text(path.read_text().replace("<worldbody>", '<include file="parts.xml"/><worldbody>'))
    outcome = []

    def build():
        try:
            arm_model(_robot(path, arm))
        except RobotError as exc:
            outcome.append(exc)

    worker = threading.Thread(target=build, daemon=True)
    worker.start()
    worker.join(30)
    assert not worker.is_alive(), "waited on the FIFO"
    (error,) = outcome
    assert "parts.xml" in str(error) and "not a regular file" in str(error)


def test_f_an_include_is_put_in_place_and_compiles(tmp_path, monkeypatch):
    arm = mjcf_arm(tmp_path / "arm.xml", 5, AXES7)
    path = tmp_path / "arm.xml"
    (tmp_path / "extra.xml").write_text('<mujoco><default><geom rgba="1 0 0 1"/></default></mujoco>')
    path.write_text(path.read_text().replace("<worldbody>", '<include file="extra.xml"/><worldbody>'))
    monkeypatch.chdir(tmp_path.parent)
    assert len(arm_model(_robot(path, arm)).joints) == 7


def test_q_a_flange_whose_name_holds_a_quote_is_found(tmp_path):
    """"the model has no link "fl'ange"" while listing it."""
    path, arm = _urdf(tmp_path)
    path.write_text(path.read_text().replace('"tool0"', '"fl\'ange"'))
    assert len(arm_model(_robot(path, arm, flange="fl'ange")).joints) == 6


def _scene_model(robot):
    """The MuJoCo model of a shipped task's scene on `robot` (compiled: a repeated name fails here)."""
    from stablepush.execution.world import place_features, scene_description
    from stablepush.kinematics.cell_model import build_mjcf
    from stablepush.plan import plan_task

    from conftest import shipped

    task = shipped("horizontal-offset-low-mu")
    plan = plan_task(task, seed=1)
    features = place_features(task, list(plan.waypoints))
    xml = build_mjcf(scene_description(task, features, task.start), robot=robot)
    return mujoco.MjModel.from_xml_string(xml)


def test_c_the_shipped_arm_given_as_a_labs_model_keeps_its_names_apart_from_the_jaws(tmp_path):
    """arm.xml as --robot: exit 4 "repeated name" (its own finger_pos, finger_neg, G, floor)."""
    from stablepush.kinematics.robot import ARM_XML

    robot = Robot(model=str(ARM_XML), flange="hand", tcp=(0.0, 0.0, 110.0, 0.0, 180.0, 0.0))
    model = _scene_model(robot)
    assert model.joint("finger_pos").id != model.joint("robot/finger_pos").id
    assert arm_model(robot).joints == tuple(f"j{i}" for i in range(1, 8))


def test_c_a_labs_links_and_geoms_named_as_the_projects_are_renamed_not_taken_for_them(tmp_path):
    """Links named object and feature_left, and a geom named floor 0.3 m up: the cell check took
    the lab's floor for the floor."""
    path, arm = _urdf(tmp_path)
    text = path.read_text().replace('"link3"', '"object"').replace('"link4"', '"feature_left"')
    text = text.replace('<link name="base">', '<link name="base"><collision name="floor"><origin xyz="0 0 0.3"/>'
                                              '<geometry><box size="0.05 0.05 0.01"/></geometry></collision>')
    path.write_text(text)
    model = _scene_model(_robot(path, arm))
    assert model.body("robot/object").id != model.body("object").id
    assert model.geom("floor").type == mujoco.mjtGeom.mjGEOM_PLANE and model.geom("floor").pos[2] == 0.0
    assert model.geom("robot/floor").type == mujoco.mjtGeom.mjGEOM_BOX
    assert robot_description(_robot(path, arm)).base_link == "base"


def test_c_an_arm_joint_named_as_the_jaws_is_refused_by_name(tmp_path):
    path, arm = _urdf(tmp_path)
    path.write_text(path.read_text().replace('"joint_2"', '"finger_pos"'))
    with pytest.raises(RobotError, match="the arm's joint 'finger_pos' has a name stablepush gives its own jaws"):
        arm_model(_robot(path, arm))


def test_c_every_name_a_scene_adds_is_one_a_labs_model_is_kept_apart_from():
    """PROJECT_NAMES and PROJECT_PREFIXES cover every name cell_model.py and the jaws add (so a lab's
    model is renamed wherever it could clash)."""
    from stablepush.kinematics.robot import ARM_XML, is_project_name

    model = _scene_model(None)
    arm = mujoco.MjModel.from_xml_path(str(ARM_XML))
    shipped_arm = {mujoco.mj_id2name(arm, kind, i) for kind, count in ((mujoco.mjtObj.mjOBJ_BODY, arm.nbody),
                                                                         (mujoco.mjtObj.mjOBJ_GEOM, arm.ngeom),
                                                                         (mujoco.mjtObj.mjOBJ_JOINT, arm.njnt))
                   for i in range(count)}
    added = {mujoco.mj_id2name(model, kind, i) for kind, count in ((mujoco.mjtObj.mjOBJ_BODY, model.nbody),
                                                                     (mujoco.mjtObj.mjOBJ_GEOM, model.ngeom),
                                                                     (mujoco.mjtObj.mjOBJ_JOINT, model.njnt),
                                                                     (mujoco.mjtObj.mjOBJ_SITE, model.nsite))
             for i in range(count)} - shipped_arm - {None, "world"}
    assert added and all(is_project_name(name) for name in added), sorted(added)
