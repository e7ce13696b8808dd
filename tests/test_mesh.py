"""Mesh input (object: {shape: mesh}): the section, simplification and the solid's mass
properties, checked against the core's uniform prism and against shapely; a mesh task planned end
to end."""
import math

import numpy as np
import pytest
import trimesh
import yaml
from shapely.geometry import Polygon

import stablepush as sp
from stablepush import _core
from stablepush.errors import PadFaceError, TaskError
from stablepush.plan import plan_task
from stablepush.task import load_task, parse_task
from stablepush.task.mesh import (
    MeshSection,
    PartMesh,
    _solid_in_o,
    first_pad_off_faces,
    load_mesh_object,
    pad_face_problem,
)

from conftest import ROOT

BRACKET = ROOT / "data" / "tasks" / "more" / "l-bracket-mesh.yaml"


def test_the_shipped_bracket_gives_its_outline_and_a_prisms_mass_properties():
    task = load_task(BRACKET)
    outline = [(-30, -25), (30, -25), (30, -5), (-10, -5), (-10, 25), (-30, 25)]
    assert sorted(task.object.vertices) == sorted(map(lambda p: (float(p[0]), float(p[1])), outline))
    assert task.object.thickness == pytest.approx(25.0) and task.object.mass == pytest.approx(1.41e-3 * 45_000)
    # For an extrusion the solid's com and moment about y are the uniform prism's (core, independently).
    section = _core.CrossSection([(x * 1e-3, z * 1e-3) for x, z in outline])
    prism = _core.RigidBody.uniform(section, task.object.mass * 1e-3)
    assert np.allclose(np.array(task.object.com) * 1e-3, prism.com, atol=1e-12)
    assert task.object.inertia == pytest.approx(prism.inertia, rel=1e-9)


def test_a_mesh_task_is_planned_end_to_end():
    task = load_task(BRACKET)
    plan = plan_task(task, seed=1)
    assert plan.solved
    assert len(sp.trajectory(task, sp.check_plan(task, plan))) > 0


def _cylinder(tmp_path, sections=256):
    solid = trimesh.creation.cylinder(radius=20.0, height=25.0, sections=sections)  # axis z
    solid.apply_transform(trimesh.transformations.rotation_matrix(math.pi / 2, [1, 0, 0]))  # axis y
    path = tmp_path / "disc.stl"
    solid.export(path)
    return path


def test_a_fine_section_is_simplified_within_its_tolerance(tmp_path):
    path = _cylinder(tmp_path)
    for tolerance in (0.01, 0.1, 1.0):
        obj = load_mesh_object(path, "object", MeshSection(tolerance=tolerance), mass=100.0)
        assert obj.section_vertices >= 256 and len(obj.vertices) <= obj.section_vertices
        exact = Polygon([(20 * math.cos(a), 20 * math.sin(a)) for a in np.linspace(0, 2 * math.pi, 2048)])
        # Simplified within the tolerance (plus the 256-gon's own sagitta, 0.003 mm).
        assert Polygon(obj.vertices).hausdorff_distance(exact) <= tolerance + 0.01
    assert len(load_mesh_object(path, "object", MeshSection(tolerance=1.0), mass=100.0).vertices) < 40


@pytest.mark.parametrize("edit, field, says", [
    ({"density": 1.0}, "object", "give exactly one of mass (g) and density"),
    ({"plane_y": 40.0}, "object.plane_y", "outside the mesh"),
    ({"file": "nowhere.stl"}, "object.file", "no such file"),
    ({"file": "y" * 300}, "object.file", "cannot look up"),  # longer than a file name may be
    ({"size": [1, 2, 3]}, "object.size", "not for shape: mesh"),
])
def test_mesh_mistakes_name_the_field(tmp_path, edit, field, says):
    path = _cylinder(tmp_path)
    obj = {"shape": "mesh", "file": path.name, "mass": 100.0, **edit}
    text = (f"object: {obj}\ngripper: {{grip_force: 10, mu: 0.5}}\n"
            f"pushers: [{{name: left, from: [-20, 0.0001], to: [-20, -0.0001], mu: 0.5}}]\nstart: [0, 0, 0]\n"
            f"goal: [1, 0, 0]\n")
    with pytest.raises(TaskError) as error:
        parse_task(text, source=str(tmp_path / "task.yaml"))
    assert error.value.field == field and says in error.value.reason


def test_an_open_surface_is_refused(tmp_path):
    box = trimesh.creation.box([60, 25, 40])
    box.update_faces(np.arange(len(box.faces)) != 0)  # one triangle gone: no longer closed
    box.export(tmp_path / "open.stl")
    with pytest.raises(TaskError, match="not a closed surface"):
        load_mesh_object(tmp_path / "open.stl", "object", mass=10.0)


def test_a_mesh_in_metres_is_named_as_such(tmp_path):
    """An STL in metres used to be refused only for its pads, with no word of units or scale."""
    solid = trimesh.creation.cylinder(radius=0.020, height=0.025, sections=64)
    solid.apply_transform(trimesh.transformations.rotation_matrix(math.pi / 2, [1, 0, 0]))
    solid.export(tmp_path / "disc_m.stl")
    text = ("object: {shape: mesh, file: disc_m.stl, mass: 100}\ngripper: {grip_force: 10, mu: 0.5}\n"
            "pushers: [{name: left, at: [-0.0199, 0.0005], mu: 0.5}]\nstart: [0, 0, 0]\ngoal: [0.001, 0, 0]\n")
    with pytest.raises(TaskError, match=r"only 0.04 mm across: written in metres\? \(object.scale: 1000"):
        parse_task(text, source=str(tmp_path / "task.yaml"))


def test_a_mesh_in_metres_with_a_mass_and_pushers_in_mm_is_named_as_such(tmp_path):
    """A 50 x 20 x 10 mm box written in metres, its mass and pushers in mm: the mass hid the scale
    (no density to go out of range), and the error blamed a pusher's distance from the edge alone."""
    trimesh.creation.box(extents=(0.05, 0.02, 0.01)).export(tmp_path / "part.stl")
    text = ("object: {shape: mesh, file: part.stl, mass: 45}\ngripper: {grip_force: 10, mu: 0.5}\n"
            "pushers: [{name: left, from: [-25, -5], to: [-25, 5], mu: 0.5}]\nstart: [0, 0, 0]\ngoal: [10, 0, 0]\n")
    with pytest.raises(TaskError) as error:
        parse_task(text, source=str(tmp_path / "task.yaml"))
    assert error.value.field == "pushers[0]" and "not on the object's boundary" in error.value.reason
    assert error.value.reason.endswith("; the object is only 0.05 mm across: written in metres? (object.scale: 1000 "
                                       "reads a mesh in metres)"), error.value.reason


def test_a_density_that_gives_a_mass_out_of_range_names_density_and_the_scale(tmp_path):
    """A mesh in mm read with scale: 0.001 came out 0.04 mm across, and the error blamed object.mass,
    which the file does not have."""
    _cylinder(tmp_path)
    text = ("object: {shape: mesh, file: disc.stl, density: 1.4, scale: 0.001}\ngripper: {grip_force: 10, mu: 0.5}\n"
            "pushers: [{name: left, at: [-0.0199, 0.0005], mu: 0.5}]\nstart: [0, 0, 0]\ngoal: [0.001, 0, 0]\n")
    with pytest.raises(TaskError) as error:
        parse_task(text, source=str(tmp_path / "task.yaml"))
    assert error.value.field == "object.density"
    assert error.value.reason.endswith("outside 0.001 to 1e+07 g; the object is only 0.04 mm across with "
                                       "object.scale: 0.001: a mesh in mm takes none, one in metres scale: 1000")


def _washer(tmp_path):
    ring = trimesh.creation.annulus(r_min=8.0, r_max=20.0, height=10.0, sections=64)  # axis z
    ring.apply_transform(trimesh.transformations.rotation_matrix(math.pi / 2, [1, 0, 0]))  # axis y
    ring.export(tmp_path / "washer.stl")
    return tmp_path / "washer.stl"


def test_a_section_with_a_hole_is_refused(tmp_path):
    """A washer used to be planned on its outer outline alone, with the pads over its hole."""
    with pytest.raises(TaskError, match=r"1 hole\(s\)") as error:
        load_mesh_object(_washer(tmp_path), "object", mass=10.0)
    assert error.value.field == "object.plane_y"


def test_several_bodies_are_refused(tmp_path):
    """Two boxes 500 mm apart used to give one box's section with both boxes' mass."""
    a, b = trimesh.creation.box([40, 25, 40]), trimesh.creation.box([40, 25, 40])
    b.apply_translation([500, 0, 0])
    trimesh.util.concatenate([a, b]).export(tmp_path / "two.stl")
    with pytest.raises(TaskError, match="2 separate bodies") as error:
        load_mesh_object(tmp_path / "two.stl", "object", mass=10.0)
    assert error.value.field == "object.file"


def _extruded(outline, cap, height):
    """A polygon in x, y (its triangles given) extruded along z: one closed body."""
    n = len(outline)
    vertices = [(x, y, 0.0) for x, y in outline] + [(x, y, height) for x, y in outline]
    faces = [(a, c, b) for a, b, c in cap] + [(a + n, b + n, c + n) for a, b, c in cap]
    for i in range(n):
        j = (i + 1) % n
        faces += [(i, j, j + n), (i, j + n, i + n)]
    solid = trimesh.Trimesh(vertices, faces)
    solid.fix_normals()
    assert solid.is_watertight and solid.body_count == 1
    return solid


def test_a_flanged_part_gripped_on_its_shaft_is_warned_about(tmp_path):
    """A flanged bushing gripped across its 20 mm shaft was modelled, silently, as a slab of the
    flange's 36 mm."""
    profile = [(-20, -10), (20, -10), (20, -18), (26, -18), (26, 18), (20, 18), (20, 10), (-20, 10)]  # x, y
    cap = [(0, 1, 6), (0, 6, 7), (1, 2, 3), (1, 3, 4), (1, 4, 6), (6, 4, 5)]
    _extruded(profile, cap, 20.0).export(tmp_path / "bushing.stl")
    obj = load_mesh_object(tmp_path / "bushing.stl", "object", mass=50.0)
    assert obj.thickness == pytest.approx(36.0)
    (note,) = obj.notes
    assert "20 mm thick across the grasp" in note and "slab of 36 mm" in note
    assert not load_mesh_object(_cylinder(tmp_path), "object", mass=10.0).notes  # a disc: the same everywhere


def test_a_section_in_two_pieces_is_refused(tmp_path):
    """One body (a U) cut across both its arms: the model would keep one arm's outline."""
    u = [(-30, -5), (30, -5), (30, 35), (20, 35), (20, 5), (-20, 5), (-20, 35), (-30, 35)]  # in x, y
    cap = [(0, 1, 4), (0, 4, 5), (1, 2, 3), (1, 3, 4), (0, 5, 6), (0, 6, 7)]  # the U in triangles, by hand
    solid = _extruded(u, cap, 40.0)
    solid.export(tmp_path / "u.stl")
    with pytest.raises(TaskError, match="2 separate pieces") as error:
        load_mesh_object(tmp_path / "u.stl", "object", MeshSection(plane_y=25.0), mass=10.0)
    assert error.value.field == "object.plane_y"


@pytest.mark.parametrize("thickness", [0.001, 1_000_000.0])
def test_a_mesh_of_an_implausible_thickness_is_refused(tmp_path, thickness):
    box = trimesh.creation.box([40, thickness, 40])
    box.export(tmp_path / "slab.stl")
    with pytest.raises(TaskError, match="thick along y") as error:
        load_mesh_object(tmp_path / "slab.stl", "object", mass=10.0)
    assert error.value.field == "object.file" and "scale" in error.value.reason


# The pads' faces (docs/model.md section 4, "Mesh parts"): the model takes the grasp to be two pads
# pressing on two parallel planar faces a slab's thickness apart; a mesh part is checked to be that
# under every pad along the path.

def _revolved(tmp_path, name, profile, axis, sections=64, turn=0.0):
    """A solid of revolution of `profile` ((r, h) mm, closed on the axis) about `axis` ("x": in the
    grasp plane, "y": the gripping axis), turned `turn` rad about y."""
    solid = trimesh.creation.revolve(np.array(profile, float), sections=sections)  # about z
    to_axis = {"x": trimesh.transformations.rotation_matrix(math.pi / 2, [0, 1, 0]),
               "y": trimesh.transformations.rotation_matrix(-math.pi / 2, [1, 0, 0])}[axis]
    solid.apply_transform(to_axis)
    solid.apply_transform(trimesh.transformations.rotation_matrix(turn, [0, 1, 0]))
    assert solid.is_watertight
    solid.export(tmp_path / name)
    return tmp_path / name


def _mesh_task(file, pushers, start, goal, pads=None):
    gripper = {"grip_force": 20, "mu": 0.5, **({"pads": pads} if pads else {})}
    return {"object": {"shape": "mesh", "file": file, "density": 1.2}, "gripper": gripper, "pushers": pushers,
            "start": start, "goal": goal, "gravity": [0, -9.81]}


def test_pads_on_a_round_shaft_are_refused_naming_the_pose_the_pad_and_what_they_touch(tmp_path):
    """The flanged bushing (20 mm shaft along x, 36 mm flange, pads of radius 4 mm on the shaft) was
    planned and simulated as a 36 mm slab."""
    _revolved(tmp_path, "bushing.stl", [(0, -20), (10, -20), (10, 20), (18, 20), (18, 25), (0, 25)], "x")
    pads = [{"center": [0, 0], "radius": 4}, {"center": [0, 0], "radius": 4}]
    data = _mesh_task("bushing.stl", [{"name": "bottom", "from": [-20, -10], "to": [20, -10], "mu": 0.6}],
                      [0, 0, 0], [5, 0, 0], pads)
    with pytest.raises(TaskError) as error:
        parse_task(data, source=str(tmp_path / "task.yaml"))
    assert error.value.field == "start"
    reason = error.value.reason
    assert reason.startswith("gripper.pads[0] at the start pose [0.0, 0.0, 0.0]"), reason
    assert "curved faces on both sides" in reason and "to 20 mm apart" in reason and "slab 36 mm thick" in reason


def test_pads_over_a_step_in_thickness_are_refused_at_the_goal(tmp_path):
    """A puck 20 mm thick inside r = 20 mm and 12 mm thick out to r = 35 mm: the goal puts the pads
    on the thinner ring."""
    _revolved(tmp_path, "stepped.stl", [(0, -10), (20, -10), (20, -6), (35, -6), (35, 6), (20, 6), (20, 10), (0, 10)],
              "y", sections=8, turn=math.pi / 8)
    side = 35 * math.cos(math.pi / 8)  # the octagon's flat side on +x
    data = _mesh_task("stepped.stl", [{"name": "right", "from": [side, -10], "to": [side, 10], "mu": 0.6}],
                      [5, 0, 0], [-27, 0, 0])
    with pytest.raises(TaskError) as error:
        parse_task(data, source=str(tmp_path / "task.yaml"))
    assert error.value.field == "goal" and "faces 12 mm apart" in error.value.reason, error.value.reason


def _dimpled(tmp_path):
    """A flat puck 20 mm thick with a dimple 1 mm deep, 3 mm in radius, at the centre of each face."""
    return _revolved(tmp_path, "dimpled.stl", [(0, -9), (3, -9), (3, -10), (35, -10), (35, 10), (3, 10), (3, 9),
                                               (0, 9)], "y", sections=8, turn=math.pi / 8)


def test_a_path_over_a_dimple_is_refused_though_its_start_and_goal_rest_flat(tmp_path):
    _dimpled(tmp_path)
    side = 35 * math.cos(math.pi / 8)
    data = _mesh_task("dimpled.stl", [{"name": "right", "from": [side, -10], "to": [side, 10], "mu": 0.6}],
                      [10, 0, 0], [-10, 0, 0])
    task = parse_task(data, source=str(tmp_path / "task.yaml"))  # the start and goal rest flat
    with pytest.raises(PadFaceError) as error:
        plan_task(task, seed=1)
    assert error.value.field == "gripper.pads[0]"
    assert "takes the pad off the part's faces just after waypoint" in error.value.reason
    assert "18 to 20 mm apart" in error.value.reason


def test_plan_refuses_a_path_off_the_faces_with_exit_2(tmp_path):
    from click.testing import CliRunner

    from stablepush_cli.main import cli

    _dimpled(tmp_path)
    side = 35 * math.cos(math.pi / 8)
    data = _mesh_task("dimpled.stl", [{"name": "right", "from": [side, -10], "to": [side, 10], "mu": 0.6}],
                      [10, 0, 0], [-10, 0, 0])
    (tmp_path / "task.yaml").write_text(yaml.safe_dump(data))
    result = CliRunner().invoke(cli, ["plan", str(tmp_path / "task.yaml"), "-o", str(tmp_path / "plan.json")])
    assert result.exit_code == 2, result.output
    assert "gripper.pads[0]: the plan's path takes the pad off the part's faces" in result.output
    assert not (tmp_path / "plan.json").exists()


@pytest.mark.parametrize("seed", range(6))
def test_pads_anywhere_on_a_box_rest_flat_and_off_its_edges_do_not(tmp_path, seed):
    """Generated boxes and pads: a disc inside the box's face rests on the slab; one crossing the
    face's edge hangs over it; the same box sheared along y (its faces tilted) is refused as tilted."""
    rng = np.random.default_rng(seed)
    length, thickness, height = rng.uniform(20, 80), rng.uniform(5, 40), rng.uniform(20, 80)
    radius = rng.uniform(1, min(length, height) / 5)
    box = trimesh.creation.box([length, thickness, height])
    box.export(tmp_path / "box.stl")
    part = PartMesh(str(tmp_path / "box.stl"), 1.0, 0.0, thickness, 0.1)
    for _ in range(5):
        inside = (rng.uniform(-1, 1) * (length / 2 - radius * 1.01), rng.uniform(-1, 1) * (height / 2 - radius * 1.01))
        assert pad_face_problem(part, inside, radius) is None
    over = (length / 2 - radius / 2, 0.0)
    assert pad_face_problem(part, over, radius).startswith("hangs over the part's edge")
    sheared = box.copy()
    slope = rng.uniform(0.05, 0.3)  # the +y face rises by slope per mm of x: a tilt of atan(slope)
    sheared.vertices[:, 1] += np.where(sheared.vertices[:, 1] > 0, slope * sheared.vertices[:, 0], 0.0)
    sheared.export(tmp_path / "sheared.stl")
    part = PartMesh(str(tmp_path / "sheared.stl"), 1.0, 0.0, float(sheared.extents[1]), 0.1)
    problem = pad_face_problem(part, (0.0, 0.0), radius)
    assert problem is not None and "a tilted +y face" in problem, problem
    assert f"{math.degrees(math.atan(slope)):.2g} deg off" in problem


def test_the_shipped_bracket_rests_flat_along_its_plan():
    task = load_task(BRACKET)
    plan = plan_task(task, seed=1)
    assert plan.solved
    assert first_pad_off_faces(task.object.mesh, task.gripper.pads, [w.pose for w in plan.waypoints]) is None


def test_a_mesh_file_rewritten_after_the_task_was_read_is_named_not_mistaken(tmp_path):
    """The pads' faces were checked on a cached solid of the file's earlier content (the fuzz
    rewrites one file name): the solid is pinned to the bytes the task read."""
    trimesh.creation.box([60, 20, 40]).export(tmp_path / "part.stl")
    data = _mesh_task("part.stl", [{"name": "left", "from": [-30, 10], "to": [-30, -10], "mu": 0.6}], [0, 0, 0],
                      [5, 0, 0])
    first = parse_task(data, source=str(tmp_path / "task.yaml"))
    assert first.object.mesh.solid().extents[1] == pytest.approx(20.0)
    trimesh.creation.box([60, 30, 40]).export(tmp_path / "part.stl")
    second = parse_task(data, source=str(tmp_path / "task.yaml"))
    assert second.object.mesh.solid().extents[1] == pytest.approx(30.0)  # not the cached 20 mm solid
    assert first.object.mesh.solid().extents[1] == pytest.approx(20.0)  # what the first task read, while cached
    _solid_in_o.cache_clear()
    with pytest.raises(TaskError, match="changed since the task was read"):
        first.object.mesh.solid()
