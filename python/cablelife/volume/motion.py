"""The motion volume: the space a cable's tube occupies at any saved step, as a watertight
mesh with its enclosed volume and bounding box."""

from __future__ import annotations

import os
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from cablelife.volume.field import Capsules, VoxelField, union_field
from cablelife.volume.mesh import TriangleMesh, level_set_mesh
from cablelife.volume.sweep import result_capsules

LITRE = 1e-3  # m³


@dataclass
class MotionVolume:
    """A swept volume: its mesh, the distance field it came from and its capsules."""

    mesh: TriangleMesh
    field: VoxelField
    capsules: Capsules
    timings: dict = field(default_factory=dict)

    @property
    def voxel(self) -> float:
        return self.field.spacing

    @property
    def volume(self) -> float:
        """Enclosed volume of the mesh, m³."""
        return self.mesh.volume

    @property
    def litres(self) -> float:
        return self.volume / LITRE

    @property
    def bounding_box(self) -> np.ndarray:
        """Exact bounds of the swept capsules, (2, 3) rows min and max, m."""
        return self.capsules.bounding_box

    def save(self, path: str | os.PathLike, unit: str = "m") -> Path:
        """Writes the mesh as STL or PLY (by the file suffix)."""
        return save_mesh(self.mesh, path, unit=unit)


def save_mesh(mesh: TriangleMesh, path: str | os.PathLike, unit: str = "m", **kw) -> Path:
    """Writes ``mesh`` to ``path``: ``.stl`` (binary) or ``.ply`` (binary)."""
    from cablelife.export.mesh_files import write_ply, write_stl

    suffix = Path(path).suffix.lower()
    if suffix == ".stl":
        return write_stl(path, mesh.vertices, mesh.faces, unit=unit)
    if suffix == ".ply":
        return write_ply(path, mesh.vertices, mesh.faces, unit=unit, **kw)
    raise ValueError(f"output = {str(path)!r}: the suffix must be .stl or .ply")


def volume_of_capsules(
    capsules: Capsules, voxel: float = 0.002, bounds: np.ndarray | None = None, progress=None
) -> MotionVolume:
    """The union of ``capsules`` meshed at ``voxel`` (m) on a grid covering ``bounds``
    (default: the capsules' own bounds); ``progress(done, total)``: rows of the grid."""
    t0 = time.perf_counter()
    f = union_field(capsules, voxel, bounds, progress)
    t1 = time.perf_counter()
    mesh = level_set_mesh(f)
    t2 = time.perf_counter()
    timings = {"distance_s": t1 - t0, "mesh_s": t2 - t1, "voxels": int(f.values.size)}
    return MotionVolume(mesh=mesh, field=f, capsules=capsules, timings=timings)


def motion_volume(
    source,
    voxel: float = 0.002,
    *,
    steps=None,
    radius: float | None = None,
    bounds: np.ndarray | None = None,
    progress=None,
) -> MotionVolume:
    """The motion volume of a :class:`~cablelife.results.Result` (all its cables), a
    :class:`~cablelife.results.CableResult`, or positions (T, N+1, 3) with ``radius``.

    Definition: the union, over the saved steps (``steps``: all by default, or a slice or
    indices), of the tube of radius ``radius`` (default: the section's outer radius) around
    every edge — i.e. of capsules. Its signed distance is evaluated exactly at the voxels of a
    grid of spacing ``voxel`` (m) and meshed by marching cubes; the mesh is watertight and its
    volume converges like voxel² to the exact volume of the union.
    """
    return volume_of_capsules(result_capsules(source, steps, radius), voxel, bounds, progress)
