"""Cross sections (stations) of the LDA: the nodes of the cable, where M is known.

The result stores M on the N+1 nodes and F on the N edges. F is brought to a node as the mean
of its two adjacent edges (an end node takes its single edge). Both edge values are in their
own material frames, which differ from the node's by a rotation of O(curvature · Δs); the mean
is exact for a straight cable and first-order accurate otherwise. Any subset of nodes can be
analysed (every ``step``-th node, always including the last one, or explicit indices).
"""

from __future__ import annotations

import numpy as np

from cablelife.results import CableResult


def node_forces(forces: np.ndarray) -> np.ndarray:
    """Edge forces (T, N, 3) → node forces (T, N+1, 3): mean of adjacent edges, ends one edge."""
    f = np.asarray(forces, float)
    if f.ndim != 3 or f.shape[2] != 3 or f.shape[1] < 1:
        raise ValueError(f"forces has shape {f.shape}: must be (T, N, 3) with N >= 1")
    out = np.empty((f.shape[0], f.shape[1] + 1, 3))
    out[:, 0] = f[:, 0]
    out[:, -1] = f[:, -1]
    out[:, 1:-1] = 0.5 * (f[:, :-1] + f[:, 1:])
    return out


def station_indices(n_nodes: int, step: int = 1, indices=None) -> np.ndarray:
    """Node indices to analyse: ``indices`` if given, else every ``step``-th node plus the last."""
    if indices is not None:
        idx = np.unique(np.asarray(indices, dtype=int))
        if idx.size == 0 or idx[0] < 0 or idx[-1] >= n_nodes:
            raise ValueError(
                f"sections = {np.asarray(indices).tolist()}: node indices must lie in "
                f"[0, {n_nodes - 1}] and not be empty"
            )
        return idx
    if not (isinstance(step, int | np.integer) and step >= 1):
        raise ValueError(f"section_step = {step!r}: must be an integer >= 1")
    idx = np.arange(0, n_nodes, step)
    if idx[-1] != n_nodes - 1:
        idx = np.append(idx, n_nodes - 1)
    return idx


def section_loads(
    cable: CableResult, step: int = 1, indices=None
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(node indices, arc lengths, loads) with loads (n_sections, T, 6) contiguous in the order
    (F1, F2, F3, M1, M2, M3), material frame."""
    m = np.asarray(cable.moments, float)
    if m.ndim != 3 or m.shape[2] != 3:
        raise ValueError(f"moments of cable {cable.name!r} have shape {m.shape}: need (T, N+1, 3)")
    if cable.forces.shape[:2] != (m.shape[0], m.shape[1] - 1):
        raise ValueError(
            f"forces {cable.forces.shape} and moments {m.shape} of cable {cable.name!r} do not "
            "match: need (T, N, 3) and (T, N+1, 3)"
        )
    idx = station_indices(m.shape[1], step, indices)
    f = node_forces(cable.forces)
    loads = np.concatenate([f[:, idx], m[:, idx]], axis=2)  # (T, n, 6)
    return (
        idx,
        np.asarray(cable.arc_length, float)[idx],
        np.ascontiguousarray(loads.transpose(1, 0, 2)),
    )
