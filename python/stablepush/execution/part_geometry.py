"""The solid a simulator builds for a mesh part: convex pieces of the part itself (CoACD's convex
decomposition of a non-convex part, the hull of a convex one) and the solid's inertia, for the
scene (scene.py, made by world.py) that both engines build their worlds from.

Both engines collide convex solids only, so a non-convex part is simulated as the union of convex
pieces. Planning never needs any of this: the model plans with the section at the grasp plane.

Here, not in `stablepush.sim`: the executor's scene carries the pieces to a simulator
that may run in another process or on another machine, without the mesh file.
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path
from typing import Optional, Tuple

import numpy as np

from stablepush.execution.scene import MeshSolid
from stablepush.task.mesh import PartMesh
from stablepush.task.model import Task

# CoACD's concavity bound (its own normalized measure): at its default 0.05 a U-shaped part's
# pieces bridged 1.9% of its volume across the gap between its arms, at 0.02 under 0.1%.
DECOMPOSITION_THRESHOLD = 0.02
DECOMPOSITION_SEED = 1  # CoACD searches at random: fixed, so that a part has one decomposition
MAX_PIECES = 64  # CoACD merges pieces down to this many
MAX_DECOMPOSED_VERTICES = 256  # vertices of a piece CoACD makes (it decimates its hulls to this)
MAX_PIECE_VERTICES = 4096  # any piece, a convex part's own hull included (a scene's bound, protocol.py)
# A piece under this fraction of the solid's volume is a sliver of the decomposition: dropped, as
# no engine builds a solid of no volume.
SLIVER_VOLUME = 1e-6
MM3_G_TO_KG_M2 = 1e-9  # g mm^2 -> kg m^2


@dataclass(frozen=True)
class PartPieces:
    """A part's convex pieces: each an (n, 3) array of its hull's vertices in O, mm (y = 0 the
    slab's centre, as PartMesh.solid()), and how they were made, in words for a run's report."""

    pieces: Tuple[np.ndarray, ...]
    description: str


def part_pieces(part: PartMesh) -> PartPieces:
    """The convex pieces a simulator builds of `part` (cached per part: CoACD can take seconds).
    MissingExtra naming the extra to install when the part is not convex and CoACD is missing."""
    return _pieces(part)


@lru_cache(maxsize=8)
def _pieces(part: PartMesh) -> PartPieces:
    solid = part.solid()
    name = Path(part.file).name
    if solid.is_convex:
        hull = np.asarray(solid.convex_hull.vertices, float)
        return PartPieces(pieces=(_frozen(hull),), description=f"{name}: convex, its own hull")
    hulls = _decomposed(solid)
    # CoACD's hulls miss the solid's faces by some micrometres: a vertex within the part's tolerance
    # of one of the solid's is put on it, so that the faces a pad or a feature meets are the solid's.
    from scipy.spatial import cKDTree

    corners = np.asarray(solid.vertices, float)
    tree = cKDTree(corners)
    pieces = []
    for hull in hulls:
        distance, nearest = tree.query(hull)
        snapped = np.where((distance <= part.tolerance)[:, None], corners[nearest], hull)
        pieces.append(_frozen(np.unique(snapped, axis=0)))
    excess = sum(_hull_volume(p) for p in pieces) / float(solid.volume) - 1.0
    return PartPieces(pieces=tuple(pieces),
                      description=f"{name}: CoACD, {len(pieces)} convex pieces ({excess:+.1%} volume)")


def _decomposed(solid) -> list:
    """CoACD's convex pieces of a non-convex solid (mm): each its hull's vertices, slivers dropped."""
    from stablepush.extras import require

    coacd = require("coacd", "a mesh part in the simulator (its convex decomposition)")
    coacd.set_log_level("error")
    parts = coacd.run_coacd(coacd.Mesh(np.asarray(solid.vertices, float), np.asarray(solid.faces, int)),
                            threshold=DECOMPOSITION_THRESHOLD, seed=DECOMPOSITION_SEED, max_convex_hull=MAX_PIECES,
                            decimate=True, max_ch_vertex=MAX_DECOMPOSED_VERTICES)
    least = SLIVER_VOLUME * float(solid.volume)
    return [np.asarray(v, float) for v, _ in parts if _hull_volume(np.asarray(v, float)) > least]


def _hull_volume(points: np.ndarray) -> float:
    from scipy.spatial import ConvexHull, QhullError

    try:
        return float(ConvexHull(points).volume)
    except (QhullError, ValueError):  # flat or too few points
        return 0.0


def _frozen(array: np.ndarray) -> np.ndarray:
    array = np.ascontiguousarray(array, float)
    array.flags.writeable = False  # shared through the cache
    return array


def solid_inertia(part: PartMesh, mass_g: float) -> Tuple[np.ndarray, np.ndarray]:
    """The solid's inertia tensor [kg m^2] about its centre of mass, in O's axes, for a uniform
    part of `mass_g` grams, and that centre of mass (x, y, z) in O [mm]."""
    solid = part.solid()
    per_density = np.asarray(solid.moment_inertia, float) / solid.density  # mm^5: the shared solid is not altered
    return per_density * (mass_g / float(solid.volume)) * MM3_G_TO_KG_M2, np.asarray(solid.center_mass, float)


def scene_object_geometry(task: Task) -> Tuple[str, Optional[MeshSolid]]:
    """What a scene's object adds to the section for a simulator: what the simulated solid is, in
    words, and for a mesh part its convex pieces, the solid's inertia tensor and the y of its
    centre of mass (scene.MeshSolid, SI units)."""
    part = task.object
    if part.mesh is None:
        return f"prism of the section, {part.thickness:g} mm thick", None
    built = part_pieces(part.mesh)
    inertia, com = solid_inertia(part.mesh, part.mass)
    return built.description, MeshSolid(
        pieces=tuple(tuple((x, y, z) for x, y, z in (piece * 1e-3).tolist()) for piece in built.pieces),
        inertia=tuple((a, b, c) for a, b, c in inertia.tolist()), com_y=float(com[1]) * 1e-3)
