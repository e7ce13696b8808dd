"""A mesh part is simulated as itself: the scene carries its convex pieces (CoACD's for a
non-convex part, its own hull for a convex one), MuJoCo and Drake build them, and a run's report
names what was simulated. The friction-fidelity contract on a mesh part is in
test_friction_fidelity.py."""
import json
import math
import sys
import xml.etree.ElementTree as ET

import numpy as np
import pytest
import trimesh
import yaml
from scipy.spatial import ConvexHull

from stablepush.execution import RunOptions
from stablepush.execution.part_geometry import part_pieces
from stablepush.execution.protocol import ProtocolError, check_scene
from stablepush.execution.run import run_plan
from stablepush.execution.scene import Scene
from stablepush.execution.world import place_features, scene_description
from stablepush.extras import MissingExtra
from stablepush.kinematics.cell_model import FEATURE_TILES, build_mjcf
from stablepush.plan import Waypoint, check_plan, plan_task
from stablepush.sim import fidelity
from stablepush.task import load_task

from conftest import ROOT, shipped

BRACKET = ROOT / "data" / "tasks" / "more" / "l-bracket-mesh.yaml"


def _scene(task, pusher="left"):
    steps = [Waypoint(*task.start), Waypoint(*task.start, pusher=pusher)]
    return scene_description(task, place_features(task, steps), task.start)


def _flanged(tmp_path):
    """A part whose solid is not the prism of its section: a 46 x 20 mm section, 36 mm thick at a
    6 mm flange and 20 mm across the rest (the flanged bushing of test_mesh.py), gripped on the flange."""
    profile = [(-20, -10), (20, -10), (20, -18), (26, -18), (26, 18), (20, 18), (20, 10), (-20, 10)]  # x, y
    path = fidelity.write_extrusion(profile, 20.0, tmp_path / "bushing.stl")  # the profile in x, z: turned below
    solid = trimesh.load_mesh(path)
    solid.apply_transform(trimesh.transformations.rotation_matrix(math.pi / 2, [1, 0, 0]))  # its z -> y
    solid.export(path)
    data = {"object": {"shape": "mesh", "file": path.name, "mass": 50},
            "gripper": {"grip_force": 10, "mu": 0.5, "pads": [{"center": [23, 0], "radius": 2}] * 2},
            "pushers": [{"name": "left", "from": [-20, 10], "to": [-20, -10], "mu": 0.5}],
            "start": [0, 0, 0], "goal": [0, 0, 0]}
    (tmp_path / "bushing.yaml").write_text(yaml.safe_dump(data))
    return load_task(tmp_path / "bushing.yaml")


def _mesh_vertices(root, name):
    mesh = root.find(f".//asset/mesh[@name='{name}']")
    return np.array([float(v) for v in mesh.get("vertex").split()]).reshape(-1, 3)


def test_the_scene_of_a_mesh_task_carries_its_convex_pieces():
    task = load_task(BRACKET)
    scene = _scene(task)
    obj = json.loads(json.dumps(scene.as_dict()))["object"]  # as sent over the wire
    assert obj["geometry"].startswith("l-bracket.stl: CoACD, 2 convex pieces")
    pieces = [np.array(p) for p in obj["mesh"]["pieces"]]
    assert len(pieces) == 2
    # In metres, in O, and together the solid: 60 x 25 x 50 mm, 45,000 mm^3.
    everything = np.vstack(pieces)
    assert np.allclose(everything.min(axis=0), [-0.030, -0.0125, -0.025], atol=1e-6)
    assert np.allclose(everything.max(axis=0), [0.030, 0.0125, 0.025], atol=1e-6)
    assert sum(ConvexHull(p).volume for p in pieces) == pytest.approx(45_000e-9, rel=1e-3)
    # The solid's inertia about its centre of mass, I_yy the task's.
    inertia = np.array(obj["mesh"]["inertia"])
    assert inertia[1, 1] == pytest.approx(obj["inertia"], rel=1e-9) and np.allclose(inertia, inertia.T)
    assert obj["mesh"]["com_y"] == pytest.approx(0.0, abs=1e-9)
    check_scene(scene.as_dict())
    assert Scene.from_dict(json.loads(json.dumps(scene.as_dict()))) == scene  # read back as sent


def test_a_box_or_polygon_part_is_the_prism_of_its_section():
    obj = _scene(shipped("t-shaped")).object
    assert obj.mesh is None and obj.geometry == "prism of the section, 25 mm thick"
    assert "mesh" not in obj.as_dict()


def test_a_convex_mesh_part_is_its_own_hull_without_coacd(tmp_path, monkeypatch):
    trimesh.creation.box(extents=(40.0, 20.0, 30.0)).export(tmp_path / "block.stl")
    text = ("object: {shape: mesh, file: block.stl, mass: 50}\ngripper: {grip_force: 10, mu: 0.5}\n"
            "pushers: [{name: left, from: [-20, 15], to: [-20, -15], mu: 0.5}]\nstart: [0, 0, 0]\ngoal: [0, 0, 0]\n")
    (tmp_path / "block.yaml").write_text(text)
    monkeypatch.setitem(sys.modules, "coacd", None)  # not installed
    task = load_task(tmp_path / "block.yaml")
    built = part_pieces(task.object.mesh)
    assert built.description == "block.stl: convex, its own hull" and len(built.pieces) == 1
    assert len(built.pieces[0]) == 8


def test_a_non_convex_part_without_coacd_names_the_extra_and_planning_does_not_need_it(tmp_path, monkeypatch):
    task = fidelity.as_mesh_part(shipped("t-shaped"), tmp_path)
    monkeypatch.setitem(sys.modules, "coacd", None)
    plan = check_plan(task, plan_task(task, seed=1))
    assert plan.solved
    from stablepush.execution.trajectory import timed_trajectory

    assert len(timed_trajectory(task, plan).t) > 0  # the CSV export needs no simulator's part either
    with pytest.raises(MissingExtra, match=r"coacd.*stablepush\[sim\]"):
        _scene(task)


def test_a_decomposition_is_the_same_every_time(tmp_path):
    from stablepush.execution import part_geometry

    task = fidelity.notched_pivoting(shipped("pivoting"), tmp_path)
    first = part_pieces(task.object.mesh)
    part_geometry._pieces.cache_clear()
    again = part_pieces(task.object.mesh)
    assert first is not again and first.description == again.description
    assert all(np.array_equal(a, b) for a, b in zip(first.pieces, again.pieces))


def test_the_mjcf_of_a_mesh_task_holds_its_pieces_as_mesh_geoms(tmp_path):
    task = _flanged(tmp_path)
    scene = _scene(task)
    root = ET.fromstring(build_mjcf(scene))
    body = root.find(".//body[@name='object']")
    geoms = [g for g in body.findall("geom") if not g.get("name").startswith("slab_")]
    assert [g.get("type") for g in geoms] == ["mesh"] * len(scene.object.mesh.pieces)
    for geom, piece in zip(geoms, scene.object.mesh.pieces):
        assert np.allclose(_mesh_vertices(root, geom.get("mesh")), piece)
    # The solid, not the 36 mm slab: its shaft is 20 mm across.
    ys = np.vstack([_mesh_vertices(root, g.get("mesh")) for g in geoms])[:, 1]
    assert np.isclose(ys, 0.010).any() and np.isclose(ys, -0.010).any()
    # Features touch the pieces by their tiles, each tile every piece; pads the prism of the section
    # under them (slab_*).
    pairs = [(p.get("geom1"), p.get("geom2")) for p in root.iter("pair")]
    tiles = {a for a, _ in pairs if a.startswith("feature_left_tile")}
    assert len(tiles) == math.prod(FEATURE_TILES) and not any(a == "feature_left" for a, _ in pairs)
    assert {(a, b) for a, b in pairs if a in tiles} == {(t, g.get("name")) for t in tiles for g in geoms}
    assert {b for a, b in pairs if a.startswith("pad_")} == {g.get("name") for g in body.findall("geom")
                                                            if g.get("name").startswith("slab_")}


def test_the_drake_world_of_a_mesh_task_holds_its_pieces_as_convex_shapes(tmp_path):
    pytest.importorskip("pydrake")
    from stablepush.sim.drake.arm import DrakeGrasp

    task = _flanged(tmp_path)
    scene = _scene(task)
    grasp = DrakeGrasp(scene, kinematic_hand=True)
    inspector = grasp.plant.EvalSceneGraphInspector(grasp.plant_context)
    pieces = scene.object.mesh.pieces
    assert len(grasp._pieces) == len(pieces)
    for geometry, piece in zip(grasp._pieces, pieces):
        shape = inspector.GetShape(geometry)
        assert type(shape).__name__ == "Convex"
        hull = shape.GetConvexHull()
        corners = np.array([hull.vertex(i) for i in range(hull.num_vertices())])
        assert ConvexHull(corners).volume == pytest.approx(ConvexHull(piece).volume, rel=1e-9)
        assert np.allclose(corners.min(axis=0), np.min(piece, axis=0)) and np.allclose(corners.max(axis=0),
                                                                                      np.max(piece, axis=0))


def test_a_malformed_mesh_in_a_scene_is_refused():
    scene = _scene(load_task(BRACKET))
    for edit, says in ((lambda m: m["pieces"][0].__delitem__(slice(3, None)), r"pieces\[0\] must be a list of 4"),
                       (lambda m: m["pieces"][1][0].__setitem__(1, float("nan")), r"pieces\[1\]\[0\]\[1\]"),
                       (lambda m: m.pop("inertia"), "has no 'inertia'"),
                       (lambda m: m["inertia"][2].__setitem__(2, -1.0), r"inertia\[2\]\[2\]")):
        broken = json.loads(json.dumps(scene.as_dict()))
        edit(broken["object"]["mesh"])
        with pytest.raises(ProtocolError, match=says):
            check_scene(broken)


@pytest.mark.slow
@pytest.mark.parametrize("engine", ["mujoco", "drake"])
def test_the_shipped_mesh_part_is_planned_run_and_lands_as_its_mesh(engine, tmp_path):
    if engine == "drake":
        pytest.importorskip("pydrake")
    from stablepush.execution.run import JsonReport
    from stablepush.sim.local_arm import SimulatedArm

    task = load_task(BRACKET)
    plan = check_plan(task, plan_task(task, seed=1))
    arm = SimulatedArm(engine)
    run = run_plan(task, plan, arm, RunOptions(rate_hz=100.0), [JsonReport(str(tmp_path / "run.json"))])
    report = run.report_or_fault()
    assert report.success, report.verdict
    assert report.simulated_geometry.startswith("l-bracket.stl: CoACD, 2 convex pieces")
    assert f"simulated as: {report.simulated_geometry}" in report.describe()
    written = json.loads((tmp_path / "run.json").read_text())
    assert written["simulated_geometry"] == report.simulated_geometry and written["engine"] == engine
    assert arm._scene.object.mesh is not None  # the world it built was the mesh's
