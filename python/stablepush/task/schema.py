"""Task files (docs/model.md section 4): read the YAML, validate every field, make a `Task`. The
checks of single fields and the YAML reader are fields.py's, the environment.robot section
robot_section.py's; a design file (design_file.py) is read with this file's object and pusher checks.

Files use mm, degrees, grams and newtons. Every bad input is refused with a `TaskError` that
names the field and the reason, before anything reaches the C++ core.
"""
from __future__ import annotations

import copy
import dataclasses
import math
from pathlib import Path
from typing import Any, Dict, List, Mapping, Optional, Sequence, Tuple

import numpy as np
import yaml

from stablepush.compiled import _core
from stablepush.errors import TaskError
from stablepush.inputs import read_capped
from stablepush.outputs import protect_input
from stablepush.task.fields import (
    LIMITS,
    MAX_TASK_BYTES,
    PLANNER_PARAMETER_RANGES,
    SUB_MM,
    _friction,
    _in_metres,
    _integer,
    _load_yaml,
    _mapping,
    _name,
    _number,
    _pair,
    _reads_as_radians,
    _shown,
    _vector,
    _yaml_problem,
    planner_limit,
    planner_parameter,
    pose_field,
)
from stablepush.task.mesh import MeshSection, PartMesh, first_pad_off_faces, load_mesh_object, slab_text
from stablepush.task.model import (
    MAX_PUSHER_POINTS,
    PLANNER_DEFAULTS,
    UNCERTAIN,
    Cell,
    PlannerSettings,
    PusherSpec,
    Task,
)
from stablepush.task.parts import (
    ANGLE,
    COORDINATE,
    ON_BOUNDARY,
    PUSHES,
    DynamicsSpec,
    GripperSpec,
    PartSpec,
    outline_corners,
)
from stablepush.task.release import goal_release_holds, needed_hold_ratio
from stablepush.task.robot_section import robot_section
from stablepush.units import MM, mm2_to_si, pose_to_si

DEFAULT_PAD_RADIUS_MM = 5.0
DEFAULT_GRAVITY = (0.0, -9.81)
DEFAULT_STEP_TIME = 0.1
DEFAULT_POLYGON_SIDES = 16
DEFAULT_PUSHER_POINTS = 3
MAX_PUSHERS = 32  # the planner holds sets of pushers as 32-bit masks
SNAP_TO_EDGE = 0.05  # mm: a pusher this close to an edge is put on it (a warning says so)
# Resource caps: each bounds the model's size (and so the time and memory to build it and to
# test a push) before anything reaches the core. docs/limits.md, "Limits".
MAX_VERTICES = 1000  # of the cross-section
MAX_PAD_RINGS = 6  # 1 + 3 r (r + 1) points per pad: 127 at the cap
MAX_PAD_POINTS = 128  # over all pads: the hold ratio's LP grows with the cube of the points (about 2 s at the cap)
MAX_PADS = 8
# A segment's cone is its end points' anyway, and building it grows fast with more (0.1 s a pusher at 50).
MAX_POLYGON_SIDES = 64
# Where the arm works (stablepush.execution): the environment section's keys but `features`, and
# their defaults (Cell says what each is).
ENVIRONMENT_DEFAULTS: Dict[str, Any] = {k: v for k, v in Cell().as_dict().items() if k not in ("features", "robot")}


def load_task(path: "str | Path", goal_in_grasp: bool = True) -> Task:
    """Read and validate a task file; raises TaskError naming the field on any problem.
    `goal_in_grasp=False` leaves out the check that the pads lie on the object at the goal, for a
    caller that replaces the goal (`reach`, whose cells say where there is no grasp)."""
    source = str(path)
    try:
        text = read_capped(path, MAX_TASK_BYTES).decode("utf-8")
        protect_input(path, "a task file")
    except ValueError as exc:  # not a regular file, too large, or not UTF-8
        raise TaskError("", f"cannot read the task file: {exc}", source) from None
    except OSError as exc:
        raise TaskError("", f"cannot read the task file ({exc.strerror or exc})", source) from None
    try:
        return parse_task(text, source, goal_in_grasp)
    except TaskError as exc:
        if exc.source is None:
            raise TaskError(exc.field, exc.reason, source) from None
        raise




def parse_task(text: "str | Mapping[str, Any]", source: Optional[str] = None, goal_in_grasp: bool = True) -> Task:
    """A task from a task file's text (YAML; str, or bytes in UTF-8), or from the mapping it holds
    (a task written in code: the same keys and units, docs/model.md section 4). Validated as
    load_task validates a file; `source` names it in errors."""
    if isinstance(text, Mapping):
        return _validate(dict(text), source, goal_in_grasp)
    if isinstance(text, bytes):
        try:
            text = text.decode("utf-8")
        except UnicodeDecodeError as exc:
            raise TaskError("", f"not UTF-8 text ({exc.reason} at byte {exc.start})", source) from None
    if not isinstance(text, str):
        raise TypeError(f"parse_task takes a task file's text or its mapping, got {type(text).__name__} "
                        f"(a path? use load_task)")
    try:
        data = _load_yaml(text)
    except TaskError:
        raise
    except yaml.YAMLError as exc:
        raise TaskError("", f"not valid YAML ({_yaml_problem(exc)})", source) from None
    if data is None:
        raise TaskError("", "the task file is empty", source)
    if isinstance(data, str) and source is None:  # parse_task("task.yaml"), meaning load_task
        raise TaskError("", f"the text is one string ({data!r:.60}), not a task; to read a task file, use "
                            f"load_task(path)", source)
    return _validate(data, source, goal_in_grasp)




def _validate(data: Any, source: Optional[str], goal_in_grasp: bool = True) -> Task:
    top = _mapping("", data, ["object", "gripper", "pushers", "start", "goal"],
                   ["name", "gravity", "dynamics", "planner", "environment", "uncertainty"])
    name = _name("name", top["name"]) if "name" in top else _default_name(source)
    notes: List[str] = []
    vertices, thickness, mass, com, inertia, mesh = _validate_object(top["object"], source, notes)

    section_defect = _core.CrossSection.defect([mm2_to_si(v) for v in vertices])  # numbered as written
    if section_defect:
        raise TaskError("object.polygon", section_defect)
    section = _core.CrossSection([mm2_to_si(v) for v in outline_corners(vertices)])
    if "com" in top["object"] and not section.contains_disc(mm2_to_si(com), 0.0):
        notes.extend(_com_outside(vertices, com))

    grip = _mapping("gripper", top["gripper"], ["grip_force", "mu"], ["pad_rings", "pads"])
    grip_force = _number("gripper.grip_force", grip["grip_force"], LIMITS["force"])
    mu = _friction("gripper.mu", grip["mu"])
    pad_rings = _integer("gripper.pad_rings", grip.get("pad_rings", 1), 0, MAX_PAD_RINGS)
    if "pads" in grip:
        if not isinstance(grip["pads"], list) or not 1 <= len(grip["pads"]) <= MAX_PADS:
            raise TaskError("gripper.pads", f"must be a list of 1 to {MAX_PADS} {{center: [x, z], radius: r}}")
        listed = []
        for i, pad in enumerate(grip["pads"]):
            path = f"gripper.pads[{i}]"
            pad = _mapping(path, pad, ["center", "radius"], [])
            listed.append((_pair(f"{path}.center", pad["center"], COORDINATE),
                         _number(f"{path}.radius", pad["radius"], LIMITS["length"])))
        pads = tuple(listed)
    else:
        pads = (((0.0, 0.0), DEFAULT_PAD_RADIUS_MM), ((0.0, 0.0), DEFAULT_PAD_RADIUS_MM))
    points = len(pads) * (1 + 3 * pad_rings * (pad_rings + 1))
    if points > MAX_PAD_POINTS:
        raise TaskError("gripper.pad_rings", f"{len(pads)} pads of {pad_rings} rings make {points} pad points; "
                                             f"at most {MAX_PAD_POINTS} (fewer rings or pads)")

    gravity = _pair("gravity", top.get("gravity", list(DEFAULT_GRAVITY)), LIMITS["gravity"])
    dyn = _mapping("dynamics", top.get("dynamics", {}), [], ["step_time", "friction_polygon_sides", "pushes"])
    pushes = dyn.get("pushes", PUSHES[0])
    if pushes not in PUSHES:
        raise TaskError("dynamics.pushes", f"must be one of {', '.join(PUSHES)}, got {pushes!r}")
    step_time = _number("dynamics.step_time", dyn.get("step_time", DEFAULT_STEP_TIME), LIMITS["step_time"])
    sides = _integer("dynamics.friction_polygon_sides", dyn.get("friction_polygon_sides", DEFAULT_POLYGON_SIDES), 3,
                     MAX_POLYGON_SIDES)

    # A unit slip the refusals below explain: the object, or a pusher, in metres.
    units = _units_hint(vertices, thickness, top["object"])
    pushers = _validate_pushers(top["pushers"], section, notes, units)
    start = pose_field("start", top["start"])
    goal = pose_field("goal", top["goal"])
    gripper = GripperSpec(grip_force=grip_force, mu=mu, pad_rings=pad_rings, pads=pads)
    core_gripper = gripper.core()
    grasped = [("start", start), ("goal", goal)] if goal_in_grasp else [("start", start)]
    for label, q in grasped:
        inside = core_gripper.pads_inside(section, pose_to_si(q))
        for i, ok in enumerate(inside):
            if not ok:
                where = f"gripper.pads[{i}]" if "pads" in grip else "gripper (default pads)"
                raise TaskError(label, f"{where} does not lie inside the object at the {label} pose {list(q)}"
                                + units)
    if mesh is not None:
        _check_pad_faces(mesh, pads, "pads" in grip, grasped)

    planner = _validate_planner(top.get("planner", {}))
    uncertain = _mapping("uncertainty", top.get("uncertainty", {}), [], list(UNCERTAIN))
    uncertainty = {key: _number(f"uncertainty.{key}", v, (0.0, 0.9)) for key, v in uncertain.items()}
    # A point pusher's stable pushes are a surface on which the required wrench lies in its wedge's
    # plane; that wrench moves with pad mu x grip force and with mass, so the surfaces of the
    # corners meet at isolated motions at most (docs/model.md, "Point pushers and the box").
    widened = [key for key in ("pad_mu", "grip_force", "mass") if uncertainty.get(key, 0.0) > 0.0]
    for i, p in enumerate(pushers):
        if p.is_point and widened:
            notes.append(f"pushers[{i}] ({p.name}): a point pusher makes no push robust to "
                         f"{', '.join('uncertainty.' + key for key in widened)} (its stable pushes move with pad mu "
                         f"x grip force and with mass; "
                         f"a width in pusher_mu alone is fine): plans will not use it")
    environment = _validate_environment(top.get("environment", {}), [p.name for p in pushers], source)
    # Pads in metres on an object in metres: the object's own warning says so.
    notes.extend(_sub_millimetre(pads if "pads" in grip and not units else (), environment))
    notes.extend(_in_radians([("start", start), ("goal", goal)], planner.tolerance[1]))
    task = Task(
        name=name, object=PartSpec(vertices=vertices, thickness=thickness, mass=mass, com=com, inertia=inertia,
                                   mesh=mesh),
        gripper=gripper, gravity=gravity,
        dynamics=DynamicsSpec(step_time=step_time, friction_polygon_sides=sides, pushes=pushes),
        pushers=pushers, start=start, goal=goal, planner=planner, environment=environment, source=source,
        uncertainty=uncertainty,
        warnings=tuple(notes + _implausible(vertices, thickness, mass, grip_force, mu, pushers, gravity)),
    )
    if goal_in_grasp and not environment.end_on_feature:
        task = dataclasses.replace(task, warnings=task.warnings + tuple(goal_hold_warnings(task)))
    return task


def goal_hold_warnings(task: Task) -> List[str]:
    """What to change when the pads alone cannot hold the object at the goal (Task.goal_hold_ratios):
    a run releases it there and it moves (the verdict's `moved_on_release`). Empty when they hold
    it whichever pusher pushes last, or when planner.min_hold_ratio already makes the plan end
    where they hold it through the release. The numbers it gives are the release's (release.py):
    the weight and the retract's acceleration, anywhere within the goal's tolerance."""
    ratios = task.goal_hold_ratios()
    weak = {name: r for name, r in ratios.items() if r < 1.0}
    if not weak:
        return []
    box = " (at the least favourable corner of the uncertainty box)" if any(task.uncertainty.values()) else ""
    best = max(ratios.values())
    if best < 1.0:
        # The release's hold is linear in pad mu x grip force (the friction that balances the load
        # scales with it): the force with which every pusher's end holds, rounded up to 0.1 N.
        least = min(goal_release_holds(task).values())
        force = math.ceil(task.gripper.grip_force / least * 10.0) / 10.0 if least > 0.0 else 0.0
        grip = (f"gripper.grip_force {force:g} N or more" if least > 0.0
                else "no grip force does: the pads hold nothing with gripper.mu 0")
        return [f"goal: the pads alone hold only {best:.2f} times the object's weight at the goal{box}: when the "
                f"last feature lets go the object moves in the grasp and the run misses (moved_on_release). "
                f"Grip harder ({grip}: the weight and the arm's acceleration as it lets go, anywhere within "
                f"planner.tolerance), choose a goal where the pads hold it, or end the run on the feature "
                f"(environment.end_on_feature: true)"]
    need = needed_hold_ratio(task, [n for n in ratios if n not in weak])
    if task.planner.min_hold_ratio >= need:
        return []
    return [f"goal: the pads alone hold the object at the goal only when the last push is by "
            f"{', '.join(n for n in ratios if n not in weak)}{box}; a plan that ends with "
            f"{', '.join(weak)} leaves it to move on release (moved_on_release): planner.min_hold_ratio: {need:g} "
            f"makes the plan end where they hold it (the weight and the arm's acceleration as it lets go)"]


def _default_name(source: Optional[str]) -> str:
    """A task without `name:` is named after its file (its stem), else "task"."""
    stem = Path(source).stem if source else ""
    return stem if stem and stem.isprintable() and len(stem) <= 100 else "task"


def _units_hint(vertices, thickness, obj: dict) -> str:
    """For an error that a unit slip explains: an object under 2 mm across was written in metres."""
    size = max(max(x for x, _ in vertices) - min(x for x, _ in vertices),
               max(z for _, z in vertices) - min(z for _, z in vertices), thickness)
    if size >= 2.0:
        return ""
    if obj.get("shape") != "mesh":
        return f"; the object is only {size:.3g} mm across: written in metres? (task files use mm)"
    if obj.get("scale", 1.0) != 1.0:  # a scale that shrank a mesh in mm
        return (f"; the object is only {size:.3g} mm across with object.scale: {obj['scale']:g}: a mesh in mm "
                f"takes none, one in metres scale: 1000")
    return f"; the object is only {size:.3g} mm across: written in metres? (object.scale: 1000 reads a mesh in metres)"


AIR_DENSITY = 1.2e-3  # g/cm^3: a solid lighter than this is a unit slip


def _implausible(vertices, thickness, mass, grip_force, mu, pushers, gravity) -> List[str]:
    """Warnings for magnitudes no cell has, each naming the field and the likely unit slip."""
    out = []
    size = max(max(x for x, _ in vertices) - min(x for x, _ in vertices),
               max(z for _, z in vertices) - min(z for _, z in vertices), thickness)
    if size < 2.0:
        out.append(f"object: {size:g} mm across; written in metres? Task files use mm")
    elif size > 2000.0:
        out.append(f"object: {size:g} mm across (over 2 m); written in micrometres, or meant in mm?")
    if mass > 50_000.0:
        out.append(f"object.mass: {mass:g} g (over 50 kg); task files use grams")
    # Shoelace area [mm^2] times thickness: the prism's volume, and its density in g/cm^3.
    area = abs(sum(x0 * z1 - x1 * z0 for (x0, z0), (x1, z1) in zip(vertices, vertices[1:] + vertices[:1]))) / 2
    density = mass / (area * thickness) * 1e3
    if density < AIR_DENSITY:
        out.append(f"object.mass: {mass:g} g in {area * thickness / 1e3:.3g} cm^3 is {density:.2g} g/cm^3, lighter "
                   f"than air; written in kg? Task files use grams")
    if grip_force > 500.0:
        out.append(f"gripper.grip_force: {grip_force:g} N per pad (over 500 N); task files use newtons")
    for path, value in [("gripper.mu", mu)] + [(f"pushers[{i}].mu", p.mu) for i, p in enumerate(pushers)]:
        if value > 3.0:
            out.append(f"{path}: {value:g}; a friction coefficient over 3 is unusual (a percentage?)")
    g = math.hypot(*gravity)
    if g != 0.0 and abs(g - 9.81) > 0.5:
        out.append(f"gravity: |g| = {g:g} m/s^2, neither 0 (a horizontal grasp plane) nor about 9.81; "
                   f"task files give gravity in m/s^2")
    return out


def _com_outside(vertices, com) -> List[str]:
    """A centre of mass given outside the outline's convex hull, where no prism of this section has
    one: right only for a part that reaches beyond the section along y."""
    from shapely.geometry import Point, Polygon  # here: only a com off the outline needs it

    off = Polygon(vertices).convex_hull.distance(Point(com))
    if off <= ON_BOUNDARY:
        return []
    return [f"object.com: {list(com)} mm lies {off:.3g} mm outside the object's outline (its convex hull), where "
            f"no solid of this section has its centre of mass; right only for a part that reaches beyond the "
            f"section along y (com is in mm, in O)"]


def _sub_millimetre(pads, environment: Cell) -> List[str]:
    """Warnings for lengths in range but under SUB_MM where a cell's are millimetres to metres (a
    pad's radius, the retract and spacings, world positions near 0 in every coordinate): each
    reads as written in metres."""
    out = [f"gripper.pads[{i}].radius: {radius:g} mm" + _in_metres(radius)
           for i, (_, radius) in enumerate(pads) if radius < SUB_MM]
    lengths = {key: getattr(environment, key) for key in ("retract", "station_spacing", "lane_offset")}
    out += [f"environment.{key}: {value:g} mm" + _in_metres(value) for key, value in lengths.items() if value < SUB_MM]
    places = [("environment.home", list(environment.home))]
    places += [(f"environment.features.{name}", list(pose[:3])) for name, pose in environment.features.items()]
    out += [f"{path}: [{', '.join(f'{v:g}' for v in p)}] mm" + _in_metres(p)
            for path, p in places if any(p) and max(map(abs, p)) < SUB_MM]
    return out




def _in_radians(poses, tolerance: float) -> List[str]:
    """Warnings for the poses' angles (label, (x, z, theta)) that read as written in radians; `tolerance`
    is planner.tolerance's angle [deg]."""
    out = []
    for label, (_, _, theta) in poses:
        if _reads_as_radians(theta) or (0.0 < abs(theta) <= min(tolerance, 2.0 * math.pi) and theta != round(theta)):
            degrees = math.degrees(theta)
            out.append(f"{label}[2]: {theta:g} deg; written in radians? ({theta:g} rad is {degrees:.3g} deg; "
                       f"task files use degrees)")
    return out




MESH_KEYS = ["file", "scale", "plane_y", "tolerance", "density"]


def _check_pad_faces(mesh: PartMesh, pads, named: bool, grasped) -> None:
    """A mesh part's pads at the start (and goal) rest on its two slab faces (task.mesh
    pad_face_problem): TaskError naming the pose, the pad and what it found."""
    for label, q in grasped:
        found = first_pad_off_faces(mesh, pads, [q])
        if found is not None:
            _, i, (x, z), problem = found
            where = f"gripper.pads[{i}]" if named else "gripper (default pads)"
            raise TaskError(label, f"{where} at the {label} pose {list(q)} (its disc at x, z = {x:.3g}, {z:.3g} mm "
                                   f"of the part) {problem}: {slab_text(mesh)}")


def _validate_object(obj: Any, source: Optional[str], notes: List[str]):
    obj = _mapping("object", obj, ["shape"], ["mass", "size", "polygon", "thickness", "com", "inertia"] + MESH_KEYS)
    shape = obj["shape"]
    if shape != "mesh":
        for key in MESH_KEYS:
            if key in obj:
                raise TaskError(f"object.{key}", "only for shape: mesh")
        if "mass" not in obj:
            raise TaskError("object.mass", "missing")
    if shape == "mesh":
        return _mesh_object(obj, source, notes)
    if shape == "box":
        if "polygon" in obj:
            raise TaskError("object.polygon", "only for shape: polygon (a box takes size)")
        if "thickness" in obj:
            raise TaskError("object.thickness", "only for shape: polygon (a box's thickness is size[1])")
        if "size" not in obj:
            raise TaskError("object.size", "missing (a box needs [L along x, B along y, H along z] in mm)")
        length, thickness, height = _vector("object.size", obj["size"], 3, LIMITS["length"])
        x, z = length / 2, height / 2
        vertices: Tuple[Tuple[float, float], ...] = ((-x, -z), (x, -z), (x, z), (-x, z))
    elif shape == "polygon":
        if "size" in obj:
            raise TaskError("object.size", "only for shape: box (a polygon takes polygon and thickness)")
        if "polygon" not in obj:
            raise TaskError("object.polygon", "missing (a list of [x, z] vertices in mm)")
        poly = obj["polygon"]
        if not isinstance(poly, list) or not 3 <= len(poly) <= MAX_VERTICES:
            raise TaskError("object.polygon", f"must be a list of 3 to {MAX_VERTICES} [x, z] vertices"
                                              + (f", got {len(poly)}" if isinstance(poly, list) else ""))
        vertices = tuple(_pair(f"object.polygon[{i}]", v, COORDINATE) for i, v in enumerate(poly))
        thickness = _number("object.thickness", obj.get("thickness", 25.0), LIMITS["length"])
    else:
        raise TaskError("object.shape", f"must be box, polygon or mesh, got {_shown(shape)}")
    mass = _number("object.mass", obj["mass"], LIMITS["mass"])
    com = _pair("object.com", obj["com"], COORDINATE) if "com" in obj else None
    inertia = _number("object.inertia", obj["inertia"], LIMITS["inertia"]) if "inertia" in obj else None
    return vertices, thickness, mass, com, inertia, None


def _onto_edge(section: "_core.CrossSection", edge: int, p: Tuple[float, float]) -> Tuple[float, float]:
    """p (mm) projected onto edge `edge` of the section."""
    vertices = section.vertices
    u = np.array(vertices[edge]) / MM
    v = np.array(vertices[(edge + 1) % len(vertices)]) / MM
    t = float(np.clip(np.dot(np.array(p) - u, v - u) / np.dot(v - u, v - u), 0.0, 1.0))
    x, z = (float(c) for c in u + t * (v - u))
    return x, z


def _mesh_object(obj: dict, source: Optional[str], notes: List[str]):
    """shape: mesh (stablepush.task.mesh): the file relative to the task file's directory; `mass` g or
    `density` g/cm^3; `scale` to mm; `plane_y` mm (default: the centre of mass's); `tolerance` mm
    of the simplified section (default 0.1). com and inertia come from the solid unless given."""
    for key in ("size", "polygon", "thickness"):
        if key in obj:
            raise TaskError(f"object.{key}", "not for shape: mesh (the mesh gives the section and thickness)")
    if "file" not in obj:
        raise TaskError("object.file", "missing (an STL, OBJ or PLY file, relative to the task file)")
    if not isinstance(obj["file"], str) or not obj["file"]:
        raise TaskError("object.file", f"must be a file name, got {_shown(obj['file'])}")
    base = Path(source).parent if source else Path.cwd()
    path = base / obj["file"]
    try:
        found = path.is_file()
    except OSError as exc:  # is_file() lets some errors through, e.g. a name longer than the system allows
        raise TaskError("object.file", f"cannot look up {_shown(obj['file'])}: {exc.strerror}") from None
    if not found:
        what = "not a regular file (a device, a FIFO or a directory)" if path.exists() else "no such file"
        raise TaskError("object.file", f"{what}: {path}")
    section = MeshSection(scale=_number("object.scale", obj.get("scale", 1.0), (1e-6, 1e6)),
                          plane_y=_number("object.plane_y", obj["plane_y"], COORDINATE) if "plane_y" in obj else None,
                          tolerance=_number("object.tolerance", obj.get("tolerance", 0.1), (1e-4, 100.0)))
    mesh = load_mesh_object(
        path, "object", section,
        mass=_number("object.mass", obj["mass"], LIMITS["mass"]) if "mass" in obj else None,
        density=_number("object.density", obj["density"], (1e-3, 100.0)) if "density" in obj else None,
        max_vertices=MAX_VERTICES, thickness_range=LIMITS["length"])
    com = _pair("object.com", obj["com"], COORDINATE) if "com" in obj else mesh.com
    inertia = _number("object.inertia", obj["inertia"], LIMITS["inertia"]) if "inertia" in obj else mesh.inertia
    lowest, highest = LIMITS["mass"]
    if not lowest <= mesh.mass <= highest:  # only a density can give it: a mass given was checked above
        hint = _units_hint(mesh.vertices, mesh.thickness, obj) or "; are object.scale and object.density right?"
        raise TaskError("object.density", f"gives the solid {mesh.mass:.4g} g, outside {lowest:g} to {highest:g} g"
                                          + hint)
    notes.extend(mesh.notes)
    return mesh.vertices, mesh.thickness, mesh.mass, com, inertia, mesh.part


def _validate_pushers(value: Any, section: "_core.CrossSection", notes: List[str],
                      units: str = "") -> Tuple[PusherSpec, ...]:
    """The pushers, each on the object's boundary. `units`: _units_hint's for the object, added to
    a pusher's refusal (a mesh in metres puts every pusher in mm far off it)."""
    if not isinstance(value, list) or not value:
        raise TaskError("pushers", "must be a non-empty list")
    if len(value) > MAX_PUSHERS:
        raise TaskError("pushers", f"at most {MAX_PUSHERS} pushers, got {len(value)}")
    specs: List[PusherSpec] = []
    for i, raw in enumerate(value):
        path = f"pushers[{i}]"
        if isinstance(raw, dict) and "at" in raw:
            raw = _mapping(path, raw, ["name", "at", "mu"], [])
            if "from" in raw or "to" in raw:
                raise TaskError(path, "give either at (a point pusher) or from/to (a segment), not both")
            a = b = _pair(f"{path}.at", raw["at"], COORDINATE)
            points = 1
        else:
            raw = _mapping(path, raw, ["name", "from", "to", "mu"], ["points"])
            a = _pair(f"{path}.from", raw["from"], COORDINATE)
            b = _pair(f"{path}.to", raw["to"], COORDINATE)
            if a == b:
                raise TaskError(f"{path}.to", "equals from; a point pusher is written at: [x, z]")
            points = _integer(f"{path}.points", raw.get("points", DEFAULT_PUSHER_POINTS), 2, MAX_PUSHER_POINTS)
        name = _name(f"{path}.name", raw["name"])
        if any(s.name == name for s in specs):
            raise TaskError(f"{path}.name", f"duplicate pusher name {name!r}")
        mu = _friction(f"{path}.mu", raw["mu"])
        edge, distance = section.nearest_edge(mm2_to_si(a), mm2_to_si(b))
        if ON_BOUNDARY < distance / MM <= SNAP_TO_EDGE:  # a rounding slip: put it on that edge, and say so
            a, b = (_onto_edge(section, edge, a), _onto_edge(section, edge, b))
            if a == b and points > 1:
                raise TaskError(path, "lies across a vertex; it must lie along one edge")
            corners = section.vertices
            ends = [[round(float(c) / MM, 6) for c in corners[i % len(corners)]] for i in (edge, edge + 1)]
            notes.append(f"{path}: {distance / MM:.3g} mm off the object's edge from {ends[0]} to {ends[1]} mm; "
                         f"moved onto it")
        try:
            _core.Pusher.on_boundary(section, name, mm2_to_si(a), mm2_to_si(b), mu, points)
        except ValueError as exc:
            # Ends within a millimetre of O's origin, on an object larger than that: a pusher in metres.
            slip = units or (_in_metres(a if a == b else [a, b]) if max(map(abs, a + b)) <= SUB_MM else "")
            raise TaskError(path, str(exc) + slip) from None
        specs.append(PusherSpec(name=name, a=a, b=b, mu=mu, points=points))
    return tuple(specs)


def _validate_environment(value: Any, pusher_names: Sequence[str], source: Optional[str] = None) -> Cell:
    """The environment section with defaults filled in. `features` maps a pusher's name to the
    object's world pose [x, y, z mm, theta deg about world y] while it rests on that pusher's
    feature; pushers not listed get a feature placed by the executor (stablepush.execution)."""
    env = _mapping("environment", value, [], list(ENVIRONMENT_DEFAULTS) + ["features", "robot"])
    out: Dict[str, Any] = {key: env.get(key, default) for key, default in ENVIRONMENT_DEFAULTS.items()}
    out["home"] = list(_vector("environment.home", out["home"], 3, COORDINATE))
    for key in ("retract", "lane_offset", "station_spacing"):
        out[key] = _number(f"environment.{key}", out[key], LIMITS["length"])
    if not isinstance(out["end_on_feature"], bool):
        raise TaskError("environment.end_on_feature", f"must be true or false, got {out['end_on_feature']!r:.40}")
    features = env.get("features", {})
    if not isinstance(features, dict):
        raise TaskError("environment.features", "must map pusher names to [x, y, z, theta] (mm, deg)")
    out["features"] = {}
    for name, pose in features.items():
        if name not in pusher_names:
            raise TaskError(f"environment.features.{name}",
                            f"no pusher named {name!r} (the task has {', '.join(pusher_names)})")
        _vector(f"environment.features.{name}", pose, 4)
        out["features"][name] = [_number(f"environment.features.{name}[{i}]", v, COORDINATE if i < 3 else ANGLE)
                                 for i, v in enumerate(pose)]
    if "robot" in env:
        out["robot"] = robot_section(env["robot"], source)
    return Cell.from_mapping(out)




def _validate_planner(value: Any) -> PlannerSettings:
    """The planner section, each key within its range, with defaults for those left out."""
    planner = _mapping("planner", value, [], list(PLANNER_DEFAULTS) + list(PLANNER_PARAMETER_RANGES))
    out = copy.deepcopy(PLANNER_DEFAULTS)  # its lists are the task's own, not the defaults'
    if "time_limit" in planner:
        out["time_limit"] = planner_limit("planner.time_limit", planner["time_limit"])
    for key in ("step", "tolerance"):
        if key in planner:
            out[key] = list(_pair(f"planner.{key}", planner[key], LIMITS[key]))
    for key in ("min_margin", "sampling_margin", "min_hold_ratio", "end_within"):
        if key in planner:
            out[key] = _number(f"planner.{key}", planner[key], LIMITS[key])
    for key, value in planner.items():
        if key in PLANNER_PARAMETER_RANGES:
            out[key] = planner_parameter(f"planner.{key}", key, value)
    return PlannerSettings.from_mapping(out)
