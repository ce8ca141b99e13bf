"""Per-step quantities of a cable in the frames a viewer needs: rotations of the edges, global
force vectors, displacements, bend radii."""

from __future__ import annotations

import numpy as np


def rotation_matrices(quaternions: np.ndarray) -> np.ndarray:
    """R(p) (..., 3, 3) of unit quaternions (..., 4), scalar first: material → global."""
    q = np.asarray(quaternions, dtype=float)
    q = q / np.linalg.norm(q, axis=-1, keepdims=True)
    w, x, y, z = np.moveaxis(q, -1, 0)
    return np.stack(
        [
            np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], -1),
            np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], -1),
            np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], -1),
        ],
        -2,
    )


def to_global(quaternions: np.ndarray, vectors: np.ndarray) -> np.ndarray:
    """Material-frame vectors (..., 3) on edges turned into the global frame."""
    return np.einsum("...ij,...j->...i", rotation_matrices(quaternions), vectors)
