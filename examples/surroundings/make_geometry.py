"""Generates the surroundings of the example scene as STL files (millimetres, as CAD exports):

- ``engine.stl``: a simplified engine block — a box with four cylinder bosses and a round
  pulley on its front, overlapping closed shells (no booleans: each shell is measured as its
  own solid, their union is the block);
- ``bracket.stl``: an L-shaped bracket of two plates.

    python examples/surroundings/make_geometry.py [output folder]
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np


def engine():
    import trimesh

    parts = [trimesh.creation.box(extents=[400, 300, 250])]  # block, centre at the origin
    for x in (-120, -40, 40, 120):  # bosses on top
        boss = trimesh.creation.cylinder(radius=35, height=60, sections=48)
        boss.apply_translation([x, 0, 125 + 20])
        parts.append(boss)
    pulley = trimesh.creation.cylinder(radius=80, height=40, sections=96)
    pulley.apply_transform(trimesh.transformations.rotation_matrix(np.pi / 2, [0, 1, 0]))
    pulley.apply_translation([200 + 15, 0, -20])
    parts.append(pulley)
    mesh = trimesh.util.concatenate(parts)
    mesh.apply_translation([700, 250, -300])  # engine bay position (mm)
    return mesh


def bracket():
    import trimesh

    base = trimesh.creation.box(extents=[80, 60, 6])
    wall = trimesh.creation.box(extents=[6, 60, 70])
    wall.apply_translation([-36, 0, -34])  # hangs below, overlapping the base (no shared vertices)
    mesh = trimesh.util.concatenate([base, wall])
    mesh.apply_translation([370, 75, -88])
    return mesh


def main(folder: Path) -> None:
    folder.mkdir(parents=True, exist_ok=True)
    for name, mesh in (("engine", engine()), ("bracket", bracket())):
        path = folder / f"{name}.stl"
        mesh.export(path)
        print(f"{path}: {len(mesh.faces)} triangles")


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else Path(__file__).parent)
