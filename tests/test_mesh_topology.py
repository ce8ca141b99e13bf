"""The edge topology of a mesh (``_core.mesh_topology``: closed, boundary edges, shells)
against a numpy and scipy reference (sorted edge keys, the face graph of shared edges and its
connected components), and bad input named."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh
from cablelife import _core
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components


def reference(faces: np.ndarray, n_vertices: int):
    a = faces.reshape(-1)
    b = faces[:, [1, 2, 0]].reshape(-1)
    keys = np.minimum(a, b) * np.int64(n_vertices) + np.maximum(a, b)
    order = np.argsort(keys, kind="stable")
    k = keys[order]
    starts = np.flatnonzero(np.r_[True, k[1:] != k[:-1]])
    counts = np.diff(np.r_[starts, len(k)])
    same = np.flatnonzero(k[1:] == k[:-1])  # consecutive sides on one edge
    f = order // 3
    n = len(faces)
    graph = coo_matrix((np.ones(len(same)), (f[same], f[same + 1])), shape=(n, n))
    n_shells, labels = connected_components(graph, directed=False)
    return bool(np.all(counts == 2)), int(np.count_nonzero(counts == 1)), labels, n_shells


def soup(seed: int, closed_only: bool = False) -> tuple[np.ndarray, int]:
    """Closed spheres and a box, then (unless ``closed_only``) an open strip and a fin, faces
    shuffled."""
    rng = np.random.default_rng(seed)
    parts = [
        trimesh.creation.icosphere(subdivisions=2),
        trimesh.creation.box(),
        trimesh.creation.icosphere(subdivisions=1),
    ]
    faces, n = [], 0
    for m in parts:
        faces.append(m.faces + n)
        n += len(m.vertices)
    if not closed_only:
        strip = np.array([[0, 1, 2], [2, 1, 3], [2, 3, 4]]) + n  # open: 5 vertices
        n += 5
        faces.append(strip)
        faces.append(np.array([[0, 1, n]]))  # a fin on an edge of the first sphere
        n += 1
    f = np.concatenate(faces)
    return f[rng.permutation(len(f))], n


@pytest.mark.parametrize("seed", range(4))
def test_topology_equals_the_numpy_reference(seed):
    closed, n_closed = soup(seed, closed_only=True)
    assert _core.mesh_topology(closed, n_closed)[::3] == (True, 3)
    faces, n = soup(seed)
    for sub in (closed, faces, faces[:-4]):  # closed; with the strip and the fin; holes
        watertight, boundary, labels, n_shells = _core.mesh_topology(sub, n)
        ref = reference(sub, n)
        assert (watertight, boundary, n_shells) == (ref[0], ref[1], ref[3])
        # the same partition, numbered by first face (scipy numbers the same way)
        assert np.array_equal(labels, ref[2])


def test_bad_faces_are_named():
    with pytest.raises(ValueError, match=r"face 1 \[0, 1, 7\].*0\.\.5"):
        _core.mesh_topology(np.array([[0, 1, 2], [0, 1, 7]]), 5)
    with pytest.raises(ValueError, match="must be"):
        _core.mesh_topology(np.zeros((2, 2), np.int64), 5)
