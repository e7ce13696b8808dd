"""Objects given as meshes (STL, OBJ, PLY; read by trimesh): the cross-section at the grasp plane,
simplified to a stated tolerance, and the mass, centre of mass and moment of inertia of the solid.

The mesh's own axes are O's (docs/model.md section 1): x and z span the grasp plane, y is the
gripping axis (pad to pad). The grasp plane is the plane y = plane_y of the mesh. Units: the mesh's,
times `scale`, must give mm.
"""
from __future__ import annotations

import hashlib
import io
import math
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path
from typing import Dict, List, Optional, Sequence, Tuple

import numpy as np

from stablepush.errors import TaskError
from stablepush.frames import point_in_object
from stablepush.inputs import read_capped
from stablepush.outputs import protect_input

G_PER_CM3 = 1e-3  # g/mm^3 per g/cm^3
# Read by trimesh from bytes capped here (a binary STL of 1.3 million triangles), in these formats
# only: others pull in optional readers (3MF needs lxml) or archives that expand past any cap.
MAX_MESH_BYTES = 64_000_000
MESH_FORMATS = ("stl", "obj", "ply", "off")
# A solid thinner than this fraction under its full extent somewhere across the grasp is noted.
THICKNESS_VARIATION = 0.1


@dataclass(frozen=True)
class PartMesh:
    """The solid a mesh task's part is, kept beside the section the model plans with: the file,
    the scale into mm, and where O's y = 0 lies in the scaled mesh (`center_y`, mm: the middle of
    its extent along y, where the model's slab is centred). `tolerance` (mm) is the section's
    simplification bound, also the bound within which a pad's face counts as the slab's. `digest`
    (SHA-256 of the file's bytes as the task read them; "" for none) pins the solid to the section
    the task took from it."""

    file: str  # absolute path
    scale: float
    center_y: float  # mm
    thickness: float  # mm: the solid's extent along y (the model's slab)
    tolerance: float  # mm
    digest: str = ""

    def solid(self):
        """The solid in O (a trimesh.Trimesh in mm; y = 0 the slab's centre), read once per file
        content (cached: treat it as read-only). TaskError (object.file) when the file no longer
        holds what the task read."""
        return _solid_in_o(self.file, self.scale, self.center_y, self.digest)


# How a pad's disc is sampled for the face check: the centre and rings of 6i points out to the rim
# (as the model's pad points, docs/model.md section 2), fine enough that a 1 mm step or hole
# under a 4 mm pad falls between no two points.
FACE_RINGS = 3
RIM = 0.999  # the outer ring just inside the rim: a pad the section holds may touch its edge


def pad_faces(part: PartMesh, center: Tuple[float, float], radius: float) -> Tuple[np.ndarray, np.ndarray]:
    """What a pad's disc, centred at `center` (x, z mm in O) with `radius` mm, rests on at the
    part's -y and +y sides: per sample point (the centre first), the y (mm) of the first face a ray
    along the gripping axis meets from outside the solid, and that face's tilt (deg) from the axis,
    NaN where it meets none. Two arrays (-y side, +y side), each n x 2: (y, tilt)."""
    points = [(center[0], center[1])]
    for i in range(1, FACE_RINGS + 1):
        rho = RIM * radius * i / FACE_RINGS
        points += [(center[0] + rho * np.cos(a), center[1] + rho * np.sin(a))
                   for a in np.linspace(0.0, 2 * np.pi, 6 * i, endpoint=False)]
    solid = part.solid()
    outside = part.thickness / 2 + 1.0
    sides = []
    for sign in (-1.0, 1.0):  # from below the -y face upward, from above the +y face downward
        origins = np.array([(x, sign * outside, z) for x, z in points])
        directions = np.tile([0.0, -sign, 0.0], (len(points), 1))
        where, rays, triangles = solid.ray.intersects_location(origins, directions, multiple_hits=False)
        found = np.full((len(points), 2), np.nan)
        if len(rays) == 0:
            sides.append(found)
            continue
        found[rays, 0] = where[:, 1]
        found[rays, 1] = np.degrees(np.arccos(np.clip(np.abs(solid.face_normals[triangles][:, 1]), 0.0, 1.0)))
        sides.append(found)
    return sides[0], sides[1]


def pad_face_problem(part: PartMesh, center: Tuple[float, float], radius: float) -> Optional[str]:
    """Why a pad's disc at `center` (x, z mm in O), `radius` mm, does not rest on the slab the
    model takes (two parallel planar faces normal to the gripping axis, `part.thickness` apart,
    each within `part.tolerance` over the disc): what it found, or None when it rests there. A
    face tilted by a over the disc departs r tan(a) at its rim, so a tilt counts when that exceeds
    the tolerance."""
    half, tol = part.thickness / 2, part.tolerance
    most_tilt = float(np.degrees(np.arctan2(tol, radius)))
    below, above = pad_faces(part, center, radius)
    missing = int(np.isnan(below[:, 0]).sum() + np.isnan(above[:, 0]).sum())
    if missing:
        return f"hangs over the part's edge ({missing} of its {2 * len(below)} sample rays meet no face)"
    found: List[str] = []
    shapes: Dict[str, List[Tuple[str, float, float]]] = {}
    shifted = False
    for name, face, expected in (("-y", below, -half), ("+y", above, half)):
        lo, hi = float(face[:, 1].min()), float(face[:, 1].max())
        if hi > most_tilt:
            shapes.setdefault("curved" if hi - lo > most_tilt else "tilted", []).append((name, lo, hi))
        shifted = shifted or float(np.abs(face[:, 0] - expected).max()) > tol
    for shape, sides in shapes.items():
        lo, hi = min(s[1] for s in sides), max(s[2] for s in sides)
        faces = f"{shape} faces on both sides" if len(sides) == 2 else f"a {shape} {sides[0][0]} face"
        turn = f"{lo:.2g} to {hi:.2g}" if hi - lo > 0.05 else f"{hi:.2g}"
        found.append(f"{faces} (normals {turn} deg off the gripping axis)")
    gap = above[:, 0] - below[:, 0]
    if float(np.abs(gap - part.thickness).max()) > tol:
        span = f"{gap.min():.3g} to {gap.max():.3g}" if gap.max() - gap.min() > tol else f"{gap[0]:.3g}"
        found.append(f"{'' if found else 'faces '}{span} mm apart")
    elif shifted and not shapes:
        found.append(f"faces at y = {float(below[0, 0]):.3g} and {float(above[0, 0]):.3g} mm, the slab's at "
                     f"{-half:.3g} and {half:.3g}")
    return ("rests on " + ", ".join(found)) if found else None


def slab_text(part: PartMesh) -> str:
    """What the model takes a mesh part's grasp to be, for a refusal's end."""
    return f"the model takes a slab {part.thickness:.3g} mm thick, the pads on its two parallel planar faces"


def first_pad_off_faces(part: PartMesh, pads: Sequence[Tuple[Tuple[float, float], float]],
                        poses: Sequence[Sequence[float]]) -> Optional[Tuple[int, int, Tuple[float, float], str]]:
    """The first place along a path of grasp poses (x, z mm, theta deg) where a pad ((centre x, z
    mm in G), radius mm) does not rest on the part's slab faces (pad_face_problem): (the index
    of the pose before it, the pad's index, its centre in O, what it found), or None. Between two
    poses the pads are sampled at most half a radius apart, so a path cannot step over a groove."""
    seen = {}
    for k, q in enumerate(poses):
        following = poses[k + 1] if k + 1 < len(poses) else q
        for i, (center, radius) in enumerate(pads):
            a, b = point_in_object(q, center), point_in_object(following, center)
            steps = max(1, math.ceil(math.dist(a, b) / (radius / 2)))
            for j in range(steps if k + 1 < len(poses) else 1):
                t = j / steps
                qt = [u + t * (v - u) for u, v in zip(q, following)]
                p = point_in_object(qt, center)
                key = (round(p[0], 3), round(p[1], 3), radius)
                if key not in seen:
                    seen[key] = pad_face_problem(part, p, radius)
                problem = seen[key]
                if problem is not None:
                    return k, i, p, problem
    return None


@lru_cache(maxsize=8)
def _solid_in_o(file: str, scale: float, center_y: float, digest: str):
    import trimesh

    mesh, now = _read_solid(trimesh, Path(file), "object")
    if digest and now != digest:
        raise TaskError("object.file", f"{file} changed since the task was read: load the task again")
    mesh.apply_scale(scale)
    mesh.apply_translation([0.0, -center_y, 0.0])
    return mesh


@dataclass(frozen=True)
class MeshObject:
    """What the task takes from a mesh (mm, g, kg m^2)."""

    vertices: Tuple[Tuple[float, float], ...]  # the simplified section, counterclockwise (x right, z up)
    thickness: float  # mm: the solid's extent along y
    mass: float  # g
    com: Tuple[float, float]  # mm: the solid's centre of mass (x, z)
    inertia: float  # kg m^2: the solid's moment about y through its centre of mass
    section_vertices: int  # before simplification
    part: PartMesh
    notes: Tuple[str, ...] = ()  # legal but probably not meant (each names its field)


@dataclass(frozen=True)
class MeshSection:
    """How the task's section is taken from a mesh file: its units times `scale` into mm, cut by
    the plane y = `plane_y` [mm, after scaling; None: the centre of mass's y], the outline
    simplified within `tolerance` [mm] of the true one (the task file's object.scale, .plane_y and
    .tolerance, which load_mesh_object checks against the mesh)."""

    scale: float = 1.0
    plane_y: Optional[float] = None
    tolerance: float = 0.1


def load_mesh_object(path: Path, field: str, section: Optional[MeshSection] = None, *, mass: Optional[float] = None,
                     density: Optional[float] = None, max_vertices: int = 1000,
                     thickness_range: Tuple[float, float] = (1e-2, 1e4)) -> MeshObject:
    """The object of a mesh file, its section taken as `section` says (None: MeshSection()).
    `mass` [g] or `density` [g/cm^3] (exactly one); `thickness_range` [mm] bounds the solid's
    extent along y. One body, cut into one outline without holes. TaskError naming `field` on any
    problem."""
    section = MeshSection() if section is None else section
    scale, plane_y, tolerance = section.scale, section.plane_y, section.tolerance
    try:
        import trimesh
        from shapely.geometry import Polygon
        from shapely.geometry.polygon import orient
    except ImportError as exc:  # pragma: no cover - both are dependencies
        raise TaskError(field, f"mesh objects need trimesh and shapely ({exc})") from None
    mesh, digest = _read_solid(trimesh, path, field)
    mesh.apply_scale(scale)
    thickness = float(mesh.extents[1])
    if not thickness_range[0] <= thickness <= thickness_range[1]:
        raise TaskError(f"{field}.file", f"{path} is {thickness:g} mm thick along y (the gripping axis), outside "
                                         f"{thickness_range[0]:g} to {thickness_range[1]:g} mm: its units? "
                                         f"({field}.scale multiplies them into mm)")
    volume = float(mesh.volume)  # mm^3
    if not volume > 0:
        raise TaskError(f"{field}.file", f"{path} encloses no volume (inside out?)")
    if (mass is None) == (density is None):
        raise TaskError(field, "give exactly one of mass (g) and density (g/cm^3)")
    if mass is not None:
        grams = mass
    else:
        assert density is not None, "exactly one of mass and density is given (checked above)"
        grams = density * G_PER_CM3 * volume
    com = mesh.center_mass
    y = float(com[1]) if plane_y is None else plane_y
    low, high = mesh.bounds[:, 1]
    if not low < y < high:
        raise TaskError(f"{field}.plane_y", f"{y:g} mm is outside the mesh, which spans y {low:g} to {high:g} mm")
    outline = _section_outline(mesh, y, f"{field}.plane_y")
    raw = len(outline.exterior.coords) - 1
    simple = orient(Polygon(outline.exterior).simplify(tolerance, preserve_topology=True), 1.0)
    vertices = tuple((float(x), float(z)) for x, z in list(simple.exterior.coords)[:-1])
    if len(vertices) > max_vertices:
        raise TaskError(f"{field}.tolerance", f"the section keeps {len(vertices)} vertices at {tolerance:g} mm; "
                                              f"at most {max_vertices} (a larger tolerance)")
    mesh.density = grams / volume  # g/mm^3, so moment_inertia is in g mm^2
    inertia = float(mesh.moment_inertia[1, 1]) * 1e-9  # g mm^2 -> kg m^2
    notes = []
    thinnest = _thinnest_across(mesh, simple, low, high)
    if thinnest is not None and thinnest[0] < (1 - THICKNESS_VARIATION) * thickness:
        t, (x, z) = thinnest
        notes.append(f"{field}.file: the solid is {t:.3g} mm thick across the grasp at (x, z) = ({x:.3g}, {z:.3g}) "
                     f"mm but {thickness:.3g} mm overall; the model takes a slab of {thickness:.3g} mm (the pads "
                     f"press on its two faces)")
    part = PartMesh(file=str(Path(path).resolve()), scale=float(scale), center_y=float((low + high) / 2),
                    thickness=thickness, tolerance=float(tolerance), digest=digest)
    return MeshObject(vertices=vertices, thickness=thickness, mass=float(grams), com=(float(com[0]), float(com[2])),
                      inertia=inertia, section_vertices=raw, part=part, notes=tuple(notes))


def _read_solid(trimesh, path: Path, field: str):
    """The mesh in `path` (its own units) once it is one closed body, and the SHA-256 of the bytes
    it was read from; TaskError naming `field`.file."""
    file_type = path.suffix.lstrip(".").lower()
    if file_type not in MESH_FORMATS:
        raise TaskError(f"{field}.file", f"{path.name}: a mesh file is one of {', '.join(MESH_FORMATS)} "
                                         f"(by its extension)")
    try:
        data = read_capped(path, MAX_MESH_BYTES)
        protect_input(path, "a mesh file")
    except (OSError, ValueError) as exc:
        raise TaskError(f"{field}.file", f"cannot read {path}: {exc}") from None
    try:
        mesh = trimesh.load_mesh(io.BytesIO(data), file_type=file_type, force="mesh")
    except Exception as exc:  # noqa: BLE001 - trimesh raises many kinds on a bad file
        raise TaskError(f"{field}.file", f"cannot read {path} as a mesh ({type(exc).__name__}: "
                                         f"{' '.join(str(exc).split())[:120]})") from None
    if len(mesh.faces) == 0:
        raise TaskError(f"{field}.file", f"{path} holds no triangles")
    if not mesh.is_watertight:
        raise TaskError(f"{field}.file", f"{path} is not a closed surface (watertight), so it has no volume")
    bodies = mesh.body_count
    if bodies > 1:
        raise TaskError(f"{field}.file", f"{path} holds {bodies} separate bodies; the grasp holds one "
                                         f"(one body per file)")
    return mesh, hashlib.sha256(data).hexdigest()


def _section_outline(mesh, y: float, field: str):
    """The mesh's section at the plane y = `y` (mm) in the grasp plane's x, z, as one shapely outline
    without holes; TaskError naming `field` (the plane) otherwise."""
    section = mesh.section(plane_origin=[0.0, y, 0.0], plane_normal=[0.0, 1.0, 0.0])
    if section is None:
        raise TaskError(field, f"the plane y = {y:g} mm does not cut the mesh")
    to_xz = np.array([[1.0, 0, 0, 0], [0, 0, 1.0, 0], [0, -1.0, 0, y], [0, 0, 0, 1.0]])  # (x, y, z) -> (x, z, y0 - y)
    planar, _ = section.to_2D(to_2D=to_xz)
    polygons = list(planar.polygons_full)
    if not polygons:
        raise TaskError(field, f"the section at y = {y:g} mm is not a closed outline")
    # The model's object is one outline without holes: a pad over a hole, or between two pieces of
    # the section, would press on nothing.
    if len(polygons) > 1:
        raise TaskError(field, f"the section at y = {y:g} mm falls into {len(polygons)} separate pieces; the model "
                               f"takes one outline (another plane_y?)")
    outline = polygons[0]
    if outline.interiors:
        raise TaskError(field, f"the section at y = {y:g} mm has {len(outline.interiors)} hole(s); the model takes "
                               f"an outline without holes, and a pad over a hole would hold nothing (another plane_y?)")
    return outline


def _thinnest_across(mesh, section, low: float, high: float, grid: int = 9):
    """The least extent along y (mm) of the solid over a grid of points inside the section, and
    where: rays along +y through the solid (trimesh, with rtree)."""
    from shapely.geometry import Point

    x0, z0, x1, z1 = section.bounds
    points = [(x, z) for x in np.linspace(x0, x1, grid + 2)[1:-1] for z in np.linspace(z0, z1, grid + 2)[1:-1]
              if section.contains(Point(x, z))]
    if not points:
        return None
    origins = np.array([(x, low - 1.0, z) for x, z in points])
    hits, rays, _ = mesh.ray.intersects_location(origins, np.tile([0.0, 1.0, 0.0], (len(points), 1)))
    best = None
    for k, (x, z) in enumerate(points):
        ys = hits[rays == k][:, 1]
        if len(ys) >= 2:
            extent = float(ys.max() - ys.min())
            if best is None or extent < best[0]:
                best = (extent, (x, z))
    return best
