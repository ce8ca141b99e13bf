"""Rotation matrices and quaternions in numpy (what ``simulate`` needs of
``scipy.spatial.transform``, whose import alone costs a small run ~0.3–0.8 s; the test checks
both against scipy)."""

from __future__ import annotations

import numpy as np


def euler_matrix(angles) -> np.ndarray:
    """R = Rz(rz) Ry(ry) Rx(rx) (rotations about the global axes, x first)."""
    a, b, c = (float(x) for x in angles)
    ca, sa, cb, sb, cc, sc = np.cos(a), np.sin(a), np.cos(b), np.sin(b), np.cos(c), np.sin(c)
    rx = np.array([[1.0, 0.0, 0.0], [0.0, ca, -sa], [0.0, sa, ca]])
    ry = np.array([[cb, 0.0, sb], [0.0, 1.0, 0.0], [-sb, 0.0, cb]])
    rz = np.array([[cc, -sc, 0.0], [sc, cc, 0.0], [0.0, 0.0, 1.0]])
    return rz @ ry @ rx


def matrix_quaternions(matrices: np.ndarray) -> np.ndarray:
    """Unit quaternions (n, 4), scalar first, of rotation matrices (n, 3, 3); Shepperd's method
    (the largest of trace and diagonal picks the stable formula; the same choice as scipy)."""
    r = np.asarray(matrices, dtype=float).reshape(-1, 3, 3)
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
