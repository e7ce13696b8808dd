"""Make the shipped example mesh, data/meshes/l-bracket.stl: an L-shaped bracket, 60 x 50 mm in the
grasp plane (legs 20 mm wide), 25 mm thick along y (the gripping axis), in mm, in the axes a mesh
task uses (x, z in the grasp plane; y pad to pad; docs/model.md section 4).

    pip install mapbox-earcut      # trimesh's polygon triangulation, needed by this script only
    python3 scripts/make_example_mesh.py
"""
from pathlib import Path

import numpy as np
import trimesh
from shapely.geometry import Polygon

OUTLINE = [(-30, -25), (30, -25), (30, -5), (-10, -5), (-10, 25), (-30, 25)]  # (x, z) mm, counterclockwise
THICKNESS = 25.0  # mm along y


def main() -> None:
    solid = trimesh.creation.extrude_polygon(Polygon(OUTLINE), THICKNESS)  # the outline in xy, extruded along +z
    # (x, y, z) -> (x, -(z - t/2), y): the outline into xz, the extrusion along y, centred on y = 0.
    solid.apply_transform(np.array([[1.0, 0, 0, 0], [0, 0, -1.0, THICKNESS / 2], [0, 1.0, 0, 0], [0, 0, 0, 1.0]]))
    assert solid.is_watertight and solid.volume > 0
    out = Path(__file__).resolve().parent.parent / "data" / "meshes" / "l-bracket.stl"
    solid.export(out)
    print(f"{out}: {len(solid.faces)} triangles, {solid.volume:.0f} mm^3, bounds {solid.bounds.tolist()}")


if __name__ == "__main__":
    main()
