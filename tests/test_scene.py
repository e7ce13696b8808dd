"""The Scene value (stablepush.execution.scene): JSON only at the wire, in the protocol's form; a
world's deviation makes a new one; a resumed run's scene is the same world."""
import dataclasses
import json

import pytest

from stablepush.execution.protocol import ProtocolError, check_scene, read_scene
from stablepush.execution.scene import Scene
from stablepush.execution.world import place_features, scene_description
from stablepush.plan import Waypoint
from stablepush.pose import Pose
from stablepush.sim.deviation import WorldDeviation

from conftest import shipped


def _scene(name="t-shaped", in_grasp=None):
    task = shipped(name)
    features = place_features(task, [Waypoint(*task.start)], every_pusher=True)
    return scene_description(task, features, task.start if in_grasp is None else in_grasp)


def test_the_wire_form_is_the_protocols():
    """The keys of hello.scene, in order, as arm/2 documents them (a lab's bridge reads them)."""
    wire = _scene().as_dict()
    assert list(wire) == ["task", "gravity", "object", "gripper", "features", "gripper_pose", "object_pose",
                          "object_in_grasp"]
    assert list(wire["object"]) == ["polygon", "thickness", "mass", "com", "inertia", "geometry"]
    assert list(wire["gripper"]) == ["grip_force", "mu", "pad_rings", "pads"]
    assert list(wire["gripper"]["pads"][0]) == ["center", "radius"]
    assert list(wire["features"][0]) == ["pusher", "from", "to", "normal", "mu", "object_pose"]
    assert len(wire["gripper_pose"]) == len(wire["object_pose"]) == 7
    assert wire["object_in_grasp"] == list(shipped("t-shaped").start)
    check_scene(json.loads(json.dumps(wire)))


def test_a_scene_read_back_from_the_wire_is_the_scene_sent():
    scene = _scene()
    back = read_scene(json.loads(json.dumps(scene.as_dict())))
    assert back == scene and back.as_dict() == scene.as_dict()
    assert isinstance(back.object_in_grasp, Pose) and back.object_in_grasp == Pose(*shipped("t-shaped").start)


def test_the_optional_fields_stay_out_of_the_wire_form_when_not_said():
    wire = _scene().as_dict()
    for key in ("task", "object_in_grasp"):
        wire.pop(key)
    wire["object"].pop("geometry")
    back = Scene.from_dict(wire)
    assert back.task is None and back.object_in_grasp is None and back.object.geometry is None
    assert back.as_dict() == wire


def test_read_scene_refuses_what_check_scene_refuses():
    wire = _scene().as_dict()
    wire["gripper"]["mu"] = -1
    with pytest.raises(ProtocolError, match="scene.gripper.mu"):
        read_scene(wire)


def test_a_deviation_makes_a_new_scene_and_leaves_the_given_one():
    scene = _scene()
    wire = json.dumps(scene.as_dict())
    world = WorldDeviation(mu_scale=0.5, grip_scale=2.0, mass_scale=3.0,
                           feature_offsets=(("web", 1.0, 0.0, 0.0),)).apply(scene)
    assert json.dumps(scene.as_dict()) == wire  # frozen: nothing to mutate
    assert world is not scene and world.gripper.mu == scene.gripper.mu * 0.5
    assert world.object.mass == scene.object.mass * 3.0
    moved = {f.pusher: f for f in world.features}["web"]
    before = {f.pusher: f for f in scene.features}["web"]
    assert moved.start[0] == pytest.approx(before.start[0] + 1e-3, abs=1e-12)
    with pytest.raises(dataclasses.FrozenInstanceError):
        world.gripper.mu = 1.0  # type: ignore[misc]


def test_a_resumed_run_is_the_same_world_and_another_task_is_not():
    task = shipped("t-shaped")
    start, later = _scene(), _scene(in_grasp=(task.start[0] + 1.0, task.start[1], task.start[2]))
    assert start != later and start.same_world(later) and later.same_world(start)
    assert not start.same_world(None)
    assert not start.same_world(dataclasses.replace(start, gravity=(0.0, -9.0)))
    assert not start.same_world(_scene("pivoting"))
