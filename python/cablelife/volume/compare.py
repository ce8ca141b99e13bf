"""Comparing two motion volumes on a common grid: each volume, their union, intersection and
differences, and the largest distance by which one sticks out of the other."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from cablelife.volume.field import VoxelField, union_field
from cablelife.volume.mesh import TriangleMesh, level_set_mesh
from cablelife.volume.motion import MotionVolume


@dataclass
class Excess:
    """How far one volume sticks out of another: the largest distance (m) from a point of it
    to the other volume, and where (m); 0 and None when it lies inside the other."""

    distance: float
    point: np.ndarray | None


@dataclass
class VolumeComparison:
    """Volumes in m³ and meshes of A, B, A ∪ B, A ∩ B, A ∖ B and B ∖ A on one grid."""

    voxel: float
    meshes: dict[str, TriangleMesh]
    a_beyond_b: Excess
    b_beyond_a: Excess

    @property
    def volumes(self) -> dict[str, float]:
        """Volume of each of ``a``, ``b``, ``union``, ``intersection``, ``a_minus_b``,
        ``b_minus_a`` in m³."""
        return {k: m.volume for k, m in self.meshes.items()}

    @property
    def hausdorff(self) -> float:
        """The Hausdorff distance between the two volumes (as sets), m."""
        return max(self.a_beyond_b.distance, self.b_beyond_a.distance)


def _excess(inside: np.ndarray, outside_other: np.ndarray, grid: VoxelField, other) -> Excess:
    """Largest exact distance to ``other`` (Capsules) over the voxels of one volume that lie
    outside the other."""
    index = np.argwhere(inside & outside_other)
    if len(index) == 0:
        return Excess(0.0, None)
    points = grid.points(index)
    d = other.distance(points)
    k = int(np.argmax(d))
    return Excess(float(d[k]), points[k])


def compare_volumes(
    a: MotionVolume, b: MotionVolume, voxel: float | None = None
) -> VolumeComparison:
    """Compares two motion volumes at ``voxel`` (default: the finer of the two).

    The union, intersection and differences are meshed from min/max combinations of the two
    exact distance fields. The excess distances are exact distances to the other union of
    capsules, taken at the voxels of one volume outside the other: they under-estimate the
    true maxima by at most half a voxel diagonal (√3/2 · voxel)."""
    voxel = min(a.voxel, b.voxel) if voxel is None else float(voxel)
    ba, bb = a.capsules.bounding_box, b.capsules.bounding_box
    box = np.stack([np.minimum(ba[0], bb[0]), np.maximum(ba[1], bb[1])])
    fa = union_field(a.capsules, voxel, box)  # both on the grid of the common box
    fb = union_field(b.capsules, voxel, box)
    va, vb = fa.values, fb.values
    combos = {
        "a": va,
        "b": vb,
        "union": np.minimum(va, vb),
        "intersection": np.maximum(va, vb),
        "a_minus_b": np.maximum(va, -vb),
        "b_minus_a": np.maximum(vb, -va),
    }
    meshes = {k: level_set_mesh(fa, v) for k, v in combos.items()}
    return VolumeComparison(
        voxel=voxel,
        meshes=meshes,
        a_beyond_b=_excess(va <= 0, vb > 0, fa, b.capsules),
        b_beyond_a=_excess(vb <= 0, va > 0, fa, a.capsules),
    )
