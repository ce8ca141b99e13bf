"""Triangle meshes of level sets: marching cubes, enclosed volume, watertightness."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from cablelife.volume.field import VoxelField


@dataclass(frozen=True)
class TriangleMesh:
    """Vertices (V, 3) in m and faces (F, 3) vertex indices, oriented outward."""

    vertices: np.ndarray
    faces: np.ndarray

    @classmethod
    def empty(cls) -> TriangleMesh:
        return cls(np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int64))

    @property
    def volume(self) -> float:
        """Enclosed volume (divergence theorem), m³."""
        if len(self.faces) == 0:
            return 0.0
        t = self.vertices[self.faces]
        return float(np.einsum("ij,ij->i", t[:, 0], np.cross(t[:, 1], t[:, 2])).sum() / 6.0)

    @property
    def area(self) -> float:
        """Surface area, m²."""
        if len(self.faces) == 0:
            return 0.0
        t = self.vertices[self.faces]
        return (
            float(np.linalg.norm(np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0]), axis=1).sum()) / 2
        )

    @property
    def bounding_box(self) -> np.ndarray:
        """(2, 3): rows min and max of the vertices, m."""
        return np.stack([self.vertices.min(axis=0), self.vertices.max(axis=0)])

    def is_watertight(self) -> bool:
        """True when every edge is shared by exactly two faces, traversed in opposite
        directions (a closed, consistently oriented 2-manifold)."""
        if len(self.faces) == 0:
            return False
        f = self.faces
        directed = np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]])
        n = len(self.vertices)
        key = directed[:, 0] * n + directed[:, 1]
        rkey = directed[:, 1] * n + directed[:, 0]
        if len(np.unique(key)) != len(key):
            return False  # an edge used twice in the same direction
        return bool(np.isin(rkey, key).all())


def level_set_mesh(field: VoxelField, values: np.ndarray | None = None) -> TriangleMesh:
    """The zero level set of ``values`` (default ``field.values``; negative inside) by marching
    cubes (scikit-image, Lewiner), outward-oriented; empty when nothing is inside."""
    from skimage.measure import marching_cubes

    v = field.values if values is None else values
    if not (v.min() < 0.0 < v.max()):
        return TriangleMesh.empty()
    h = field.spacing
    verts, faces, _, _ = marching_cubes(v, level=0.0, spacing=(h, h, h), allow_degenerate=False)
    mesh = TriangleMesh(verts + field.origin, faces.astype(np.int64))
    if mesh.volume < 0:
        mesh = TriangleMesh(mesh.vertices, mesh.faces[:, ::-1].copy())
    return mesh
