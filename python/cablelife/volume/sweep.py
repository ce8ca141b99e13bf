"""The capsules a cable sweeps: one per edge and saved step, radius = the section's outer
radius. The motion volume is their union over the saved steps (positions between two saved
steps are not interpolated: save steps densely enough for the motion)."""

from __future__ import annotations

import numpy as np

from cablelife.results import CableResult, Result
from cablelife.volume.field import Capsules


def select_steps(n_steps: int, steps) -> np.ndarray:
    """Indices of the saved steps to use: all (None), a slice, or an index array."""
    if steps is None:
        return np.arange(n_steps)
    if isinstance(steps, slice):
        return np.arange(n_steps)[steps]
    idx = np.asarray(steps, dtype=np.int64).ravel()
    if idx.size and (idx.min() < -n_steps or idx.max() >= n_steps):
        raise ValueError(f"steps = {steps!r}: indices must lie in [{-n_steps}, {n_steps - 1}]")
    return idx


def tube_capsules(positions, radius: float, steps=None) -> Capsules:
    """Capsules of a polyline over time: positions (T, N+1, 3) in m, tube radius in m."""
    x = np.asarray(positions, dtype=np.float64)
    if x.ndim == 2:
        x = x[None]
    if x.ndim != 3 or x.shape[2] != 3 or x.shape[1] < 2:
        raise ValueError(f"positions has shape {x.shape}: must be (T, N+1, 3) with N >= 1")
    radius = float(radius)
    if not (np.isfinite(radius) and radius > 0):
        raise ValueError(f"radius = {radius}: must be > 0 (m)")
    x = x[select_steps(len(x), steps)]
    if len(x) == 0:
        raise ValueError(f"steps = {steps!r} selects no saved step")
    starts = x[:, :-1].reshape(-1, 3)
    ends = x[:, 1:].reshape(-1, 3)
    return Capsules(starts, ends, np.full(len(starts), radius))


def cable_capsules(cable: CableResult, steps=None, radius: float | None = None) -> Capsules:
    """Capsules of one cable of a result (radius: the section's ``outer_radius``)."""
    if radius is None:
        if "outer_radius" not in cable.section:
            raise ValueError(
                f"cable {cable.name!r} has no section outer_radius: pass radius explicitly"
            )
        radius = float(cable.section["outer_radius"])
    return tube_capsules(cable.positions, radius, steps)


def result_capsules(source, steps=None, radius: float | None = None) -> Capsules:
    """Capsules of a :class:`Result` (every cable), a :class:`CableResult`, or an array of
    positions (T, N+1, 3) with ``radius``."""
    if isinstance(source, Result):
        caps = [cable_capsules(c, steps, radius) for c in source.cables.values()]
        if not caps:
            raise ValueError("result has no cables")
        out = caps[0]
        for c in caps[1:]:
            out = out.concat(c)
        return out
    if isinstance(source, CableResult):
        return cable_capsules(source, steps, radius)
    if radius is None:
        raise ValueError("radius is required when positions are given as an array")
    return tube_capsules(source, radius, steps)
