"""The cable as a tube surface: rings of vertices around the nodes in the material frame, so
that a vertex at surface angle γ sits at x + r (cos γ d1 + sin γ d2) like the stress recovery's
surface points."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from cablelife.export.frames import rotation_matrices


def node_frames(positions: np.ndarray, quaternions: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Directors d1, d2 (N+1, 3) at the nodes: the adjacent edges' d1 averaged and made
    orthogonal to the node tangent (the mean of the adjacent edge directions)."""
    r = rotation_matrices(quaternions)  # (N, 3, 3), columns d1, d2, d3
    d1e = r[:, :, 0]
    edge = np.diff(positions, axis=0)
    edge /= np.maximum(np.linalg.norm(edge, axis=1, keepdims=True), 1e-300)
    pad = lambda a: np.concatenate([a[:1], a, a[-1:]])  # noqa: E731
    e, d = pad(edge), pad(d1e)
    tangent = e[:-1] + e[1:]
    tangent /= np.maximum(np.linalg.norm(tangent, axis=1, keepdims=True), 1e-300)
    d1 = d[:-1] + d[1:]
    d1 -= np.einsum("ij,ij->i", d1, tangent)[:, None] * tangent
    d1 /= np.maximum(np.linalg.norm(d1, axis=1, keepdims=True), 1e-300)
    return d1, np.cross(tangent, d1)


@dataclass
class TubeMesh:
    """Vertices (N+1)·G of G-vertex rings and the triangles between consecutive rings."""

    vertices: np.ndarray  # (V, 3)
    faces: np.ndarray  # (F, 3)
    angles: np.ndarray  # (G,) rad


def ring_faces(n_nodes: int, n_angles: int) -> np.ndarray:
    """Triangles (2·N·G, 3) between consecutive rings of ``n_angles`` vertices."""
    n, g = np.meshgrid(np.arange(n_nodes - 1), np.arange(n_angles), indexing="ij")
    a = n * n_angles + g
    b = n * n_angles + (g + 1) % n_angles
    c, d = a + n_angles, b + n_angles
    return np.concatenate([np.stack([a, b, d], -1), np.stack([a, d, c], -1)]).reshape(-1, 3)


def tube_mesh(positions, quaternions, radius: float, n_angles: int = 16) -> TubeMesh:
    """The tube of ``radius`` (m) around one step's nodes (N+1, 3) and edges (N, 4)."""
    x = np.asarray(positions, dtype=float)
    if n_angles < 3:
        raise ValueError(f"n_angles = {n_angles}: must be >= 3")
    d1, d2 = node_frames(x, np.asarray(quaternions, dtype=float))
    angles = np.linspace(0, 2 * np.pi, n_angles, endpoint=False)
    ring = np.cos(angles)[None, :, None] * d1[:, None] + np.sin(angles)[None, :, None] * d2[:, None]
    vertices = (x[:, None] + radius * ring).reshape(-1, 3)
    return TubeMesh(vertices, ring_faces(len(x), n_angles), angles)
