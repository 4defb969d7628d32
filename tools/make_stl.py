"""Write the ASCII STL walls of cases/silo-heat: a vertical open tube and a bottom disc.

Usage: python tools/make_stl.py [OUTDIR]   (default cases/silo-heat/meshes)

Units are metres, the axis is z, the tube's foot at z = 0. Normals point into the silo
(LIGGGHTS' mesh walls act on both sides, but ParaView shades by them). The tube is cut
into rings so that no triangle is much longer than wide: LIGGGHTS warns about, and
handles badly, slivers.
"""
from __future__ import annotations

import sys
from pathlib import Path

import meshio
import numpy as np

RADIUS = 0.0125       # m, inner radius of the tube (25 mm bore)
HEIGHT = 0.050        # m
SEGMENTS = 40         # around the circumference
RINGS = 5             # along the height (10 mm: triangles about 2 x 10 mm)
DISC_Z = 0.002        # m, height of the bottom plate (it is vibrated about this level)
DISC_RADIUS = RADIUS  # m, flush with the tube wall


def tube(radius: float, height: float, segments: int, rings: int) -> meshio.Mesh:
    phi = np.linspace(0.0, 2 * np.pi, segments, endpoint=False)
    z = np.linspace(0.0, height, rings + 1)
    points = np.array([[radius * np.cos(p), radius * np.sin(p), h] for h in z for p in phi])
    cells = []
    for k in range(rings):
        for i in range(segments):
            a, b = k * segments + i, k * segments + (i + 1) % segments
            c, d = a + segments, b + segments
            # Counter-clockwise seen from the axis: the normal points inwards.
            cells += [[a, c, b], [b, c, d]]
    return meshio.Mesh(points, [("triangle", np.array(cells))])


def disc(radius: float, z: float, segments: int) -> meshio.Mesh:
    phi = np.linspace(0.0, 2 * np.pi, segments, endpoint=False)
    points = np.vstack([[0.0, 0.0, z], np.column_stack(
        [radius * np.cos(phi), radius * np.sin(phi), np.full(segments, z)])])
    # Counter-clockwise seen from above: the normal points up, into the silo.
    cells = [[0, 1 + i, 1 + (i + 1) % segments] for i in range(segments)]
    return meshio.Mesh(points, [("triangle", np.array(cells))])


def main(outdir: Path) -> None:
    outdir.mkdir(parents=True, exist_ok=True)
    for name, mesh in (("tube.stl", tube(RADIUS, HEIGHT, SEGMENTS, RINGS)),
                       ("bottom.stl", disc(DISC_RADIUS, DISC_Z, SEGMENTS))):
        meshio.write(outdir / name, mesh, file_format="stl", binary=False)
        print(f"{outdir / name}: {len(mesh.cells[0].data)} triangles")


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else
         Path(__file__).resolve().parents[1] / "cases" / "silo-heat" / "meshes")
