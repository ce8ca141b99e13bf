"""Rotation matrices and quaternions in numpy (what ``simulate`` needs of
``scipy.spatial.transform``, whose import alone costs a small run ~0.3–0.8 s; the test checks
both against scipy)."""

from __future__ import annotations

import math

import numpy as np


def euler_matrix(angles) -> np.ndarray:
    """R = Rz(rz) Ry(ry) Rx(rx) (rotations about the global axes, x first)."""
    a, b, c = (float(x) for x in angles)
    ca, sa, cb, sb, cc, sc = np.cos(a), np.sin(a), np.cos(b), np.sin(b), np.cos(c), np.sin(c)
    rx = np.array([[1.0, 0.0, 0.0], [0.0, ca, -sa], [0.0, sa, ca]])
    ry = np.array([[cb, 0.0, sb], [0.0, 1.0, 0.0], [-sb, 0.0, cb]])
    rz = np.array([[cc, -sc, 0.0], [sc, cc, 0.0], [0.0, 0.0, 1.0]])
    return rz @ ry @ rx


#: Up to this many matrices are converted one by one (numpy's per-call cost, ~50 µs, is
#: then most of the time: a harness run converts its clips' frames at rest 17 times).
SMALL = 4


def matrix_quaternions(matrices: np.ndarray) -> np.ndarray:
    """Unit quaternions (n, 4), scalar first, of rotation matrices (n, 3, 3); Shepperd's method
    (the largest of trace and diagonal picks the stable formula; the same choice as scipy)."""
    r = np.asarray(matrices, dtype=float).reshape(-1, 3, 3)
    if r.shape[0] <= SMALL and np.isfinite(r).all():
        # a few matrices (a cable's clips at rest): Python floats, the same operations
        return np.array([_shepperd(m) for m in r.tolist()]).reshape(-1, 4)
    return _matrix_quaternions_arrays(r)


def _shepperd(r: list) -> list[float]:
    """`matrix_quaternions` of one matrix (nested lists), as the array code computes it: the
    same choice (the first largest of the diagonal and the trace), the same sums in the same
    order, the norm summed from x to w."""
    d = (r[0][0], r[1][1], r[2][2])
    trace = d[0] + d[1] + d[2]
    options = (*d, trace)
    choice = max(range(4), key=lambda c: (options[c], -c))
    if choice == 3:  # x, y, z, w
        q = [r[2][1] - r[1][2], r[0][2] - r[2][0], r[1][0] - r[0][1], 1.0 + trace]
    else:
        i = choice
        j, k = (i + 1) % 3, (i + 2) % 3
        q = [0.0] * 4
        q[i] = 1.0 - trace + 2.0 * r[i][i]
        q[j] = r[j][i] + r[i][j]
        q[k] = r[k][i] + r[i][k]
        q[3] = r[k][j] - r[j][k]
    norm = math.sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3])
    return [q[3] / norm, q[0] / norm, q[1] / norm, q[2] / norm]


def _matrix_quaternions_arrays(r: np.ndarray) -> np.ndarray:
    """`matrix_quaternions` of (n, 3, 3) in array operations."""
    n = r.shape[0]
    diag = np.stack([r[:, 0, 0], r[:, 1, 1], r[:, 2, 2]], axis=1)
    trace = diag.sum(axis=1)
    choice = np.argmax(np.column_stack([diag, trace]), axis=1)
    q = np.empty((n, 4))  # x, y, z, w
    t = choice == 3
    q[t, 0] = r[t, 2, 1] - r[t, 1, 2]
    q[t, 1] = r[t, 0, 2] - r[t, 2, 0]
    q[t, 2] = r[t, 1, 0] - r[t, 0, 1]
    q[t, 3] = 1.0 + trace[t]
    for i in range(3):
        m = choice == i
        j, k = (i + 1) % 3, (i + 2) % 3
        q[m, i] = 1.0 - trace[m] + 2.0 * r[m, i, i]
        q[m, j] = r[m, j, i] + r[m, i, j]
        q[m, k] = r[m, k, i] + r[m, i, k]
        q[m, 3] = r[m, k, j] - r[m, j, k]
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    return q[:, [3, 0, 1, 2]]
