"""The cell as one MJCF tree, which both simulator engines and the cell check read: the arm
(robot.py; the shipped arm, arm.xml) plus the held object, the multi-point finger pads and the
fixed features, built from a scene (`stablepush.execution.scene.Scene`, SI units: what the
executor sends in its `hello`). The object is a union of convex pieces
(`object_solid`): a mesh part's own, which the scene carries (`stablepush.execution.part_geometry`),
or for a box or polygon part the prism of its section.

Contact settings that keep friction honest (the simulation's results rest on them, and
`stablepush.sim.fidelity` measures them):
- elliptic friction cones with impratio 100, so sticking contacts do not creep;
- noslip iterations, which remove the residual slip of MuJoCo's soft constraints;
- a small solref time constant (stiff contacts, 2.5 time steps);
- pad friction chosen per pad point by its own slip (`stablepush.sim.mujoco.friction`): the solver's stiff friction
  while it sticks, explicit Coulomb friction (mu N opposite its slip) while it slides, which
  removes the pads' drop-outs while they slide;
- each pad is a disc of point contacts laid out as the task's `pad_rings` says, so the simulated
  pad's force acts where the model's does (docs/planner.md, "The mechanics");
- multi-point convex collisions by libccd (`multiccd`, native CCD off), so a face on a face
  touches at several points; a mesh piece touches a line feature's tiles (FEATURE_TILES), so that
  the contact bears a moment by its stiffness;
- only the object touches pads and features (explicit contact pairs with the task's friction);
  the fingers are driven by force-capped joint servos, not as mocap bodies, so the pads press
  with exactly the task's grip force and friction can drag the object.
"""
from __future__ import annotations

import dataclasses
import math
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from typing import List, Optional, Sequence, Tuple

import numpy as np

from stablepush.execution.scene import Scene, SceneFeature, SceneObject
from stablepush.frames import pose_to_matrix, quat_about_y, turn
from stablepush.kinematics.robot import FINGER_JOINTS, GRIPPER_SITE, arm_model
from stablepush.task.model import Robot

OBJECT_BODY = "object"
MAX_SIM_VERTICES = 64  # the simulated object's outline; more are simplified away (simulated_outline)
PAD_PREFIX = "pad_"  # pad point geoms are named pad_<finger>_<pad>_<point>
SLAB_PREFIX = "slab_"  # a mesh part's prism of its section, which its pads press on (build_mjcf)
HAND_JOINTS = ("hand_x", "hand_z", "hand_theta")  # the kinematic hand's slide x, slide z, hinge y

# s: the coarsest step measured to pass the friction-fidelity contract (0.5 ms drops a pad point in
# the 20 mm/s creep runs; benchmarks/friction_fidelity.py --timestep-ms)
TIMESTEP = 0.0004
CONTACT_SOLREF = (0.001, 1.0)  # time constant s (2.5 time steps; MuJoCo needs at least 2), damping ratio
CONTACT_SOLIMP = (0.95, 0.99, 0.0005)
IMPRATIO = 100.0
NOSLIP_ITERATIONS = 20
NOSLIP_TOLERANCE = 1e-6  # MuJoCo's default
PAD_POINT_RADIUS = 0.0005  # m, radius of each pad contact sphere
FEATURE_DEPTH = 0.01  # m, how far a feature extends behind its contact face
FEATURE_CLEARANCE = 0.002  # m, a feature is this much narrower than the object along y on each side
FEATURE_ROD_RADIUS = 0.001  # m, the rod of a point pusher's feature
# A line feature's tiles (along its segment, along y) that the object's mesh pieces touch instead
# of its one box (build_mjcf): MuJoCo's convex collision (multiccd) gives every contact point of a
# pair the pair's one depth, so a single pair bears no moment by its stiffness; tiles have depths of
# their own. 2 x 2 bears a moment about either axis of the face.
FEATURE_TILES = (2, 2)
TILE_INFIX = "_tile"  # a feature's tile geoms are named <feature geom>_tile<k>
# m a line feature's solid stops short of an end of its segment in a reflex corner of the object
# (at most a quarter of the segment): a solid reaching the corner, placed off by any amount toward
# the adjacent face, lies in that face's path on the approach (the T's web feature over its
# flange). A real fixture must stop short too, by more than its placement error.
FEATURE_CORNER_GAP = 0.001
# The jaw servos' spring at the object's faces, in grip forces: at 2 they stay at their cap (the
# grip force) until each jaw has closed by a quarter of the thickness, and while they close at
# under grip force / kv.
JAW_SATURATION = 2.0


def pad_points(center: Sequence[float], radius: float, rings: int) -> List[Tuple[float, float]]:
    """The points of a pad disc in G's xz-plane [m]: the centre, and ring i of 6i points at radius
    i r / rings, the first on +x (the same layout as the model's, docs/model.md section 2)."""
    points = [(center[0], center[1])]
    for i in range(1, rings + 1):
        rho = radius * i / rings
        for k in range(6 * i):
            a = 2.0 * math.pi * k / (6 * i)
            points.append((center[0] + rho * math.cos(a), center[1] + rho * math.sin(a)))
    return points


def simulated_outline(polygon: Sequence[Sequence[float]]) -> Tuple[List[Tuple[float, float]], float]:
    """The outline the simulator builds (m, in O): the polygon itself when it has at most
    MAX_SIM_VERTICES vertices, else the polygon simplified (shapely, topology kept) with the
    smallest tolerance, doubling from 0.01 mm, that brings it under the cap; with the tolerance
    used (m; 0 when unchanged). The planner always uses the full polygon; only the simulated
    world is simplified, so that it builds in bounded time (the convex decomposition is cubic in
    the vertices)."""
    pts = [_point(p) for p in polygon]
    if len(pts) <= MAX_SIM_VERTICES:
        return pts, 0.0
    from shapely.geometry import Polygon
    from shapely.geometry.polygon import orient

    shape, tolerance = Polygon(pts), 1e-5
    while True:
        simple = orient(shape.simplify(tolerance, preserve_topology=True), 1.0)
        outline = list(simple.exterior.coords)[:-1]
        if len(outline) <= MAX_SIM_VERTICES:
            return [_point(p) for p in outline], tolerance
        tolerance *= 2.0


def _point(p: Sequence[float]) -> Tuple[float, float]:
    x, z = p
    return float(x), float(z)


def convex_pieces(polygon: Sequence[Sequence[float]]) -> List[List[Tuple[float, float]]]:
    """A simple counterclockwise polygon as convex counterclockwise pieces: ear-clipping
    triangulation, then adjacent pieces merged while their union stays convex (Hertel-Mehlhorn)."""
    pts = [_point(p) for p in polygon]
    if _is_convex(pts):
        return [pts]
    pieces = triangulated(pts)
    merged = True
    while merged:
        merged = False
        for a in range(len(pieces)):
            for b in range(a + 1, len(pieces)):
                union = _merge(pieces[a], pieces[b])
                if union is not None and _is_convex([pts[i] for i in union]):
                    pieces[a] = union
                    pieces.pop(b)
                    merged = True
                    break
            if merged:
                break
    return [_drop_collinear([pts[i] for i in piece]) for piece in pieces]


def triangulated(polygon: Sequence[Sequence[float]]) -> List[List[int]]:
    """A simple counterclockwise polygon as counterclockwise triangles of its vertex indices (ear
    clipping): every vertex is a corner of some triangle."""
    pts = [tuple(map(float, p)) for p in polygon]
    index = list(range(len(pts)))
    triangles = []
    while len(index) > 3:
        for k in range(len(index)):
            i, j, after = index[k - 1], index[k], index[(k + 1) % len(index)]
            if turn(pts[i], pts[j], pts[after]) <= 0:
                continue
            if any(_in_triangle(pts[m], pts[i], pts[j], pts[after]) for m in index if m not in (i, j, after)):
                continue
            triangles.append([i, j, after])
            index.pop(k)
            break
        else:
            raise ValueError("polygon could not be triangulated (is it simple and counterclockwise?)")
    triangles.append(index)
    return triangles


def _in_triangle(p, a, b, c) -> bool:
    return turn(a, b, p) >= 0 and turn(b, c, p) >= 0 and turn(c, a, p) >= 0


def _is_convex(pts) -> bool:
    n = len(pts)
    return all(turn(pts[i - 1], pts[i], pts[(i + 1) % n]) >= -1e-15 for i in range(n))


def _merge(p: List[int], q: List[int]):
    """The union of two pieces sharing an edge (as a vertex cycle), or None."""
    for i in range(len(p)):
        a, b = p[i], p[(i + 1) % len(p)]
        for j in range(len(q)):
            if q[j] == b and q[(j + 1) % len(q)] == a:
                rest = [q[(j + 2 + k) % len(q)] for k in range(len(q) - 2)]
                return p[: i + 1] + rest + p[i + 1:]
    return None


def _drop_collinear(pts):
    n = len(pts)
    return [pts[i] for i in range(n) if abs(turn(pts[i - 1], pts[i], pts[(i + 1) % n])) > 1e-15]


def _axis_aligned_rectangle(piece) -> bool:
    if len(piece) != 4:
        return False
    xs = sorted({round(p[0], 12) for p in piece})
    zs = sorted({round(p[1], 12) for p in piece})
    return len(xs) == 2 and len(zs) == 2


def _prism_inertia(polygon, thickness: float, mass: float, com) -> np.ndarray:
    """Inertia tensor [kg m^2] about `com` (x, z in O) of a uniform prism, axes of O (y = thickness)."""
    pts = np.asarray(polygon, float) - np.asarray(com, float)
    area = sxx = szz = sxz = 0.0
    for (x0, z0), (x1, z1) in zip(pts, np.roll(pts, -1, axis=0)):
        c = x0 * z1 - x1 * z0
        area += c / 2
        sxx += c * (x0 * x0 + x0 * x1 + x1 * x1) / 12  # integral of x^2 dA
        szz += c * (z0 * z0 + z0 * z1 + z1 * z1) / 12
        sxz += c * (x0 * z1 + 2 * x0 * z0 + 2 * x1 * z1 + x1 * z0) / 24
    density = mass / area
    mx, mz, mxz = density * sxx, density * szz, density * sxz
    my = mass * thickness**2 / 12
    return np.array([[my + mz, 0.0, -mxz], [0.0, mx + mz, 0.0], [-mxz, 0.0, mx + my]])


def found(element: ET.Element, path: str) -> ET.Element:
    """The first element at `path` under `element`; ValueError when there is none (a model the
    arm's MJCF does not describe)."""
    hit = element.find(path)
    if hit is None:
        raise ValueError(f"the arm's MJCF has no {path}")
    return hit


def mjcf_numbers(values) -> str:
    """Numbers as an MJCF attribute: space-separated, each exact (repr)."""
    return " ".join(repr(float(v)) for v in values)


def arm_tree(scene: Scene, kinematic_hand: bool = False, robot: Optional[Robot] = None) -> ET.Element:
    """The arm of `robot` (robot.arm_model: the shipped arm when None) as an MJCF element tree, its
    finger servos capped at the scene's grip force; with `kinematic_hand` the shipped arm is
    replaced by a hand at the scene's gripper pose that moves in G's plane through three joints
    (HAND_JOINTS) whose motion the caller prescribes: the same fingers, pads and contacts without
    the arm, for measuring friction alone (`stablepush.sim.fidelity`). Both engines read the arm from this tree
    (MuJoCo whole, Drake through its MJCF parser)."""
    root = arm_model(None if kinematic_hand else robot).arm_tree()
    if kinematic_hand:
        _replace_arm_by_kinematic_hand(root, scene.gripper_pose)
    # The finger servos close toward y = 0 and press with at most the grip force. They press with
    # exactly that only while saturated: at the object's faces, half its thickness from y = 0,
    # their spring must exceed the cap, or they press with kp t/2 (the shipped kp gave 20 N on a
    # 10 mm part gripped with 40 N, and no grip force cured its release).
    grip_force = scene.gripper.grip_force
    for finger in FINGER_JOINTS:
        act = found(root, f".//actuator/position[@name='{finger}']")
        act.set("forcerange", mjcf_numbers((-grip_force, grip_force)))
        act.set("forcelimited", "true")
        stiff = JAW_SATURATION * grip_force / (scene.object.thickness / 2)
        kp = act.get("kp")
        if kp is None:
            raise ValueError(f"the arm's MJCF gives the servo of {finger} no kp")
        act.set("kp", repr(max(float(kp), stiff)))
    return root


def pad_layout(scene: Scene) -> List[Tuple[str, str, float, Tuple[float, float]]]:
    """Every pad contact point as (name, finger body, side, (x, z) in G [m]): pad i sits on finger
    i mod 2 (the task lists the opposed pads in pairs), `side` is the finger's inner face (+1 on
    finger_pos, -1 on finger_neg), the points as `pad_points` lays them out."""
    gripper = scene.gripper
    out = []
    for f, (finger, side) in enumerate(zip(FINGER_JOINTS, (1.0, -1.0))):
        for p, pad in list(enumerate(gripper.pads))[f::2]:
            for k, point in enumerate(pad_points(pad.center, pad.radius, gripper.pad_rings)):
                out.append((f"{PAD_PREFIX}{finger}_{p}_{k}", finger, side, point))
    return out


def object_inertia(obj: SceneObject) -> np.ndarray:
    """The object's inertia tensor [kg m^2] about its centre of mass (object_com), axes of O: a mesh
    part's solid's, else a uniform prism of its outline; with the task's own moment about y either
    way (docs/model.md section 4)."""
    if obj.mesh is not None:
        inertia = np.array(obj.mesh.inertia, float)
    else:
        inertia = _prism_inertia(obj.polygon, obj.thickness, obj.mass, obj.com)
    inertia[1, 1] = obj.inertia
    return inertia


def object_com(obj: SceneObject) -> Tuple[float, float, float]:
    """The object's centre of mass in O [m]: the task's x and z, and along y a mesh part's solid's
    (a prism's lies on its middle plane, y = 0)."""
    com_y = obj.mesh.com_y if obj.mesh is not None else 0.0
    return float(obj.com[0]), float(com_y), float(obj.com[1])


def object_pieces(obj: SceneObject) -> List[Tuple[str, list, bool]]:
    """The section's convex pieces: (name, convex ccw outline in O's xz [m], whether the piece is
    an axis-aligned rectangle). The prism of these is what a box or polygon part is simulated as
    (object_solid); Drake's pads touch deep prisms of them on any part (sim.drake.arm._add_pad_faces)."""
    pieces = convex_pieces(simulated_outline(obj.polygon)[0])
    return [(f"object_piece{i}", piece, _axis_aligned_rectangle(piece)) for i, piece in enumerate(pieces)]


@dataclass(frozen=True)
class SolidPiece:
    """A convex piece of the simulated object: its corners (n x 3, in O [m]), and whether it is an
    axis-aligned box in O, which the engines build as a box (their box queries are exact)."""

    name: str
    vertices: np.ndarray
    box: bool

    def box_center_size(self) -> Tuple[np.ndarray, np.ndarray]:
        """A box piece's centre and full extents along O's axes [m]."""
        low, high = self.vertices.min(axis=0), self.vertices.max(axis=0)
        return (low + high) / 2, high - low


def object_solid(obj: SceneObject, half_y: Optional[float] = None) -> List[SolidPiece]:
    """The solid the engines build of the scene's object, as convex pieces: a mesh part's own
    (the object's `mesh`, part_geometry.py), else the prism of each of the section's pieces
    (object_pieces), `half_y` [m] either side of the xz-plane (default half the thickness; a mesh
    part's y is scaled to it, as the video's ghost is drawn thinner)."""
    half = obj.thickness / 2
    half_y = half if half_y is None else half_y
    if obj.mesh is not None:
        scale = np.array([1.0, half_y / half, 1.0])
        return [SolidPiece(f"object_piece{i}", np.asarray(piece, float) * scale, False)
                for i, piece in enumerate(obj.mesh.pieces)]
    return [SolidPiece(name, np.array([(x, sy * half_y, z) for sy in (-1, 1) for x, z in outline]), rectangle)
            for name, outline, rectangle in object_pieces(obj)]


def simulated_geometry(obj: SceneObject) -> str:
    """What solid the engines build of the scene's object, in words: a run's report names it."""
    if obj.mesh is not None:
        return obj.geometry or f"a mesh part, {len(obj.mesh.pieces)} convex pieces"
    return f"prism of the section, {obj.thickness * 1e3:g} mm thick"


def add_object_geoms(body: ET.Element, assets: ET.Element, obj: SceneObject, half_y: float, rgba: str, prefix: str = "",
                     **attributes: str) -> List[str]:
    """The object's pieces (object_solid, `half_y` m either side of the xz-plane) as geoms of
    `body`: a box piece as a box, any other as a mesh in `assets` (m, in O); `attributes` go on
    every geom (e.g. mass), names start with `prefix`. Returns the geoms' names."""
    names = []
    for piece in object_solid(obj, half_y):
        name = prefix + piece.name
        if piece.box:
            center, size = piece.box_center_size()
            ET.SubElement(body, "geom", {"name": name, "type": "box", **attributes, "pos": mjcf_numbers(center),
                                         "size": mjcf_numbers(size / 2), "rgba": rgba})
        else:
            ET.SubElement(assets, "mesh", name=name, vertex=mjcf_numbers(np.ravel(piece.vertices)))
            ET.SubElement(body, "geom", {"name": name, "type": "mesh", "mesh": name, **attributes, "rgba": rgba})
        names.append(name)
    return names


def feature_solid(feature: SceneFeature, obj: SceneObject) -> dict:
    """A feature's fixed solid in W: a box whose contact face is the pusher's segment (less
    FEATURE_CORNER_GAP, or a quarter of it, at an end in a reflex corner of the object's polygon),
    extending FEATURE_DEPTH behind it (`center`, `angle` about y, `half_size`), or for a point
    pusher a rod along y (`center`, `radius`, `half_length`). It is FEATURE_CLEARANCE narrower than
    the object `obj` (the scene's, m) on each side along y, so that it touches the object's face and
    never a pad."""
    a = np.asarray(feature.start, float)
    b = np.asarray(feature.end, float)
    n = np.asarray(feature.normal, float)
    half_y = max(obj.thickness / 2 - FEATURE_CLEARANCE, 0.001)
    length = float(np.linalg.norm(b - a))
    if length > 0:
        t = (b - a) / length
        corners = _reflex_corners_in_world(obj.polygon, feature.object_pose)
        in_corner = lambda p: any(np.linalg.norm(p - c) < 1e-6 for c in corners)  # noqa: E731
        gap = min(FEATURE_CORNER_GAP, length / 4)
        a, b = (a + t * gap if in_corner(a) else a), (b - t * gap if in_corner(b) else b)
        length = float(np.linalg.norm(b - a))
        return {"kind": "box", "center": (a + b) / 2 - n * FEATURE_DEPTH / 2, "angle": math.atan2(-t[2], t[0]),
                "half_size": (length / 2, half_y, FEATURE_DEPTH / 2)}
    return {"kind": "rod", "center": a - n * FEATURE_ROD_RADIUS, "radius": FEATURE_ROD_RADIUS, "half_length": half_y}


def _reflex_corners_in_world(polygon: Sequence[Sequence[float]], object_pose: Sequence[float]) -> List[np.ndarray]:
    """The vertices of a counterclockwise polygon (O's x, z, m) whose interior angle exceeds 180
    deg, in W with the object at `object_pose` (x, y, z, qw, qx, qy, qz)."""
    n, T_WO = len(polygon), pose_to_matrix(object_pose)
    return [(T_WO @ np.array([v[0], 0.0, v[1], 1.0]))[:3] for k, v in enumerate(polygon)
            if turn(polygon[k - 1], v, polygon[(k + 1) % n]) < -1e-15]  # a right turn, as _is_convex counts one


def build_mjcf(scene: Scene, kinematic_hand: bool = False, robot: Optional[Robot] = None) -> str:
    """The complete MJCF of a scene (`stablepush.execution.scene.Scene`): `arm_tree`
    of `robot` plus the solver options, the pad points, the held object, the features and the
    contact pairs."""
    root = arm_tree(scene, kinematic_hand, robot)
    gx, gz = scene.gravity
    ET.SubElement(root, "option", timestep=repr(TIMESTEP), gravity=mjcf_numbers((gx, 0.0, gz)), cone="elliptic",
                  impratio=repr(IMPRATIO), noslip_iterations=str(NOSLIP_ITERATIONS),
                  noslip_tolerance=repr(NOSLIP_TOLERANCE), integrator="implicitfast")
    # libccd, not MuJoCo's native CCD: with native CCD the wedge's convex mesh slid 0.6 mm along
    # its heel stop in 12 pushes that the model, Drake and libccd all hold (docs/results/engines-cross-engine.md),
    # and with the feature tiles the notched pivot's bar still turned 0.15 deg in the world where
    # libccd turns it 0.03 (its pads on the section's non-rectangular pieces).
    found(root, "option").append(ET.Element("flag", multiccd="enable", nativeccd="disable"))
    worldbody = found(root, "worldbody")
    obj = scene.object
    half_thickness = obj.thickness / 2

    # The pads: point spheres on the inner side of each finger, in G's xz-plane.
    pad_names = []
    for name, finger, side, (px, pz) in pad_layout(scene):
        body = found(root, f".//body[@name='{finger}']")
        ET.SubElement(body, "geom", name=name, type="sphere", size=repr(PAD_POINT_RADIUS),
                      pos=mjcf_numbers((px, side * PAD_POINT_RADIUS, pz)), mass="0.0001", rgba="0.2 0.2 0.2 1")
        pad_names.append(name)

    # The held object: a free body of convex pieces in O (object_solid).
    x, y, z, w, qx, qy, qz = scene.object_pose
    body = ET.SubElement(worldbody, "body", name=OBJECT_BODY, pos=mjcf_numbers((x, y, z)),
                         quat=mjcf_numbers((w, qx, qy, qz)))
    ET.SubElement(body, "freejoint", name=OBJECT_BODY)
    inertia = object_inertia(obj)
    ET.SubElement(body, "inertial", pos=mjcf_numbers(object_com(obj)), mass=repr(obj.mass),
                  fullinertia=mjcf_numbers((inertia[0, 0], inertia[1, 1], inertia[2, 2], inertia[0, 1], inertia[0, 2],
                                            inertia[1, 2])))
    assets = root.find("asset")
    if assets is None:
        assets = ET.SubElement(root, "asset")
    piece_names = add_object_geoms(body, assets, obj, half_thickness, "0.85 0.55 0.25 1", mass="0")
    pad_faces = piece_names
    if obj.mesh is not None:
        # A mesh part's pads press on the prism of its section, massless and unseen, not on its
        # pieces: MuJoCo's sphere-vs-convex-mesh contact (libccd) turned the pivoting box, built as
        # one mesh, 0.11 deg in the world where its box primitive turns 0.01 deg (the contract's
        # limit is 0.1). The planner takes a plan only where the pads rest on the solid's flat faces
        # at +-thickness/2, so the prism's faces under the pads are the solid's.
        section = dataclasses.replace(obj, mesh=None)
        pad_faces = add_object_geoms(body, assets, section, half_thickness, "0 0 0 0", prefix=SLAB_PREFIX, mass="0")

    # The features: fixed solids whose contact face is the pusher's segment. A mesh piece touches a
    # line feature's tiles (FEATURE_TILES), a box piece its box (box-box contacts have their own depths).
    contact = ET.SubElement(root, "contact")
    mesh_pieces = [n for n in piece_names if found(body, f"geom[@name='{n}']").get("type") == "mesh"]
    box_pieces = [n for n in piece_names if n not in mesh_pieces]
    for feature in scene.features:
        name = feature_geom(feature.pusher)
        solid = feature_solid(feature, obj)
        if solid["kind"] == "box":
            ET.SubElement(worldbody, "geom", name=name, type="box", pos=mjcf_numbers(solid["center"]),
                          quat=mjcf_numbers(quat_about_y(solid["angle"])), size=mjcf_numbers(solid["half_size"]),
                          rgba="0.3 0.5 0.8 1")
        else:
            c, h = solid["center"], solid["half_length"]
            ET.SubElement(worldbody, "geom", name=name, type="capsule", size=repr(solid["radius"]),
                          fromto=mjcf_numbers((*(c - [0, h, 0]), *(c + [0, h, 0]))), rgba="0.3 0.5 0.8 1")
        for piece in box_pieces:
            _pair(contact, name, piece, feature.mu)
        tiles = _add_feature_tiles(worldbody, name, solid) if solid["kind"] == "box" and mesh_pieces else [name]
        for tile in tiles:
            for piece in mesh_pieces:
                _pair(contact, tile, piece, feature.mu)
    for pad in pad_names:
        for piece in pad_faces:
            _pair(contact, pad, piece, scene.gripper.mu)
    return ET.tostring(root, encoding="unicode")


def feature_geom(pusher: str) -> str:
    """The name of the geom of pusher `pusher`'s feature in a model built by `build_mjcf`."""
    return f"feature_{pusher}"


def feature_geoms(model, pusher: str) -> List[int]:
    """The ids of the geoms of pusher `pusher`'s feature in a model built by `build_mjcf`: its solid
    and the tiles that a mesh piece touches (FEATURE_TILES)."""
    name = feature_geom(pusher)
    return [g for g in range(model.ngeom) if model.geom(g).name == name
            or model.geom(g).name.startswith(name + TILE_INFIX)]


def feature_tiles(solid: dict) -> List[Tuple[np.ndarray, Tuple[float, float, float]]]:
    """A box feature's solid (feature_solid) cut into FEATURE_TILES boxes, each (centre in W [m],
    half sizes along the solid's axes): their union is the solid."""
    (n_along, n_y), (hx, hy, hz) = FEATURE_TILES, solid["half_size"]
    c, s = math.cos(solid["angle"]), math.sin(solid["angle"])
    along = np.array([c, 0.0, -s])  # the solid's x axis in W: rotated by `angle` about y
    half = (hx / n_along, hy / n_y, hz)
    return [(np.asarray(solid["center"], float) + along * (-hx + half[0] * (2 * i + 1))
             + np.array([0.0, -hy + half[1] * (2 * j + 1), 0.0]), half)
            for i in range(n_along) for j in range(n_y)]


def _add_feature_tiles(worldbody: ET.Element, name: str, solid: dict) -> List[str]:
    """The tiles of box feature `name` (feature_tiles) as unseen geoms of `worldbody`; their names."""
    names = []
    for k, (center, half) in enumerate(feature_tiles(solid)):
        names.append(f"{name}{TILE_INFIX}{k}")
        ET.SubElement(worldbody, "geom", name=names[-1], type="box", pos=mjcf_numbers(center),
                      quat=mjcf_numbers(quat_about_y(solid["angle"])), size=mjcf_numbers(half), rgba="0 0 0 0")
    return names


def pad_geoms(model) -> List[int]:
    """The ids of the pad point geoms of a model built by `build_mjcf`."""
    return [g for g in range(model.ngeom) if model.geom(g).name.startswith(PAD_PREFIX)]


def _replace_arm_by_kinematic_hand(root: ET.Element, gripper_pose: Sequence[float]) -> None:
    """Swap the arm for a body at G's pose with HAND_JOINTS and the arm's own fingers, finger
    servos and jaw coupling (so the grasp is the arm's, without the arm's dynamics)."""
    worldbody = found(root, "worldbody")
    arm_base = found(worldbody, "body")
    fingers = [found(root, f".//body[@name='{f}']") for f in FINGER_JOINTS]
    worldbody.remove(arm_base)
    x, y, z, w, qx, qy, qz = gripper_pose
    hand = ET.SubElement(worldbody, "body", name="hand", pos=mjcf_numbers((x, y, z)),
                         quat=mjcf_numbers((w, qx, qy, qz)))
    for name, kind, axis in zip(HAND_JOINTS, ("slide", "slide", "hinge"), ((1, 0, 0), (0, 0, 1), (0, 1, 0))):
        ET.SubElement(hand, "joint", name=name, type=kind, axis=mjcf_numbers(axis), armature="1e4", damping="0")
    ET.SubElement(hand, "geom", type="box", size="0.01 0.01 0.01", pos="0 0 -0.1", mass="1")
    ET.SubElement(hand, "site", name=GRIPPER_SITE, size="0.004")
    for finger in fingers:  # in the arm they sit at G's pose in the hand; here the hand is G
        finger.set("pos", "0 0 0")
        finger.set("quat", "1 0 0 0")
        hand.append(finger)
    actuators = found(root, "actuator")
    for act in list(actuators):
        if act.get("name") not in FINGER_JOINTS:
            actuators.remove(act)


def _pair(contact: ET.Element, geom1: str, geom2: str, mu: float) -> None:
    ET.SubElement(contact, "pair", geom1=geom1, geom2=geom2, condim="3",
                  friction=mjcf_numbers((mu, mu, 0.0, 0.0, 0.0)), solref=mjcf_numbers(CONTACT_SOLREF),
                  solimp=mjcf_numbers(CONTACT_SOLIMP))
