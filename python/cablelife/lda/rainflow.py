"""Rainflow counting (ASTM E1049-85) of single series, and range–mean / from–to matrices.

Counting runs in Rust (crate ``cablelife-fatigue``). Turning points: first sample, strict
extrema (last sample of a plateau), last extremum; an optional hysteresis gate h drops every
reversal whose excursion does not exceed h. Residue treatments (``residue=``):

- ``"half"`` (default, ASTM E1049-85): each unclosed range counts 0.5 cycles;
- ``"discard"``: unclosed ranges are ignored;
- ``"full"``: each unclosed range counts 1.0 cycle;
- ``"repeated"``: the history is taken as repeating: the residue followed by itself is
  counted again with the four-point rule and the cycles it closes count 1.0 each.

Cycles are ranges (peak to valley), not amplitudes.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from cablelife import _core

RESIDUES = ("half", "discard", "full", "repeated")


def as_series(series, name: str = "series") -> np.ndarray:
    """A finite, non-empty 1-D float64 array, or a ValueError naming the problem."""
    x = np.ascontiguousarray(series, dtype=float)
    if x.ndim != 1:
        raise ValueError(f"{name} has shape {x.shape}: must be one-dimensional")
    if x.size == 0:
        raise ValueError(f"{name} is empty: needs at least one sample")
    bad = np.flatnonzero(~np.isfinite(x))
    if bad.size:
        raise ValueError(
            f"{name} has a non-finite sample {x[bad[0]]} at index {bad[0]} "
            f"({bad.size} in all): all samples must be finite"
        )
    return x


def check_residue(residue: str) -> str:
    if residue not in RESIDUES:
        raise ValueError(f"residue = {residue!r}: must be one of {RESIDUES}")
    return residue


@dataclass(frozen=True)
class Cycles:
    """Rainflow cycles of one series: ranges, means, counts (0.5 or 1.0) and the sample
    indices of their two turning points (``from_index`` before ``to_index``)."""

    range: np.ndarray
    mean: np.ndarray
    count: np.ndarray
    from_index: np.ndarray
    to_index: np.ndarray

    def __len__(self) -> int:
        return int(self.range.size)

    @property
    def total(self) -> float:
        """Number of cycles (half cycles count 0.5)."""
        return float(self.count.sum())

    def as_tuples(self) -> list[tuple[float, float, float, int, int]]:
        """(range, mean, count, from, to) tuples, like ``rainflow.extract_cycles``."""
        return list(
            zip(
                self.range.tolist(),
                self.mean.tolist(),
                self.count.tolist(),
                self.from_index.tolist(),
                self.to_index.tolist(),
                strict=True,
            )
        )


def turning_points(series, hysteresis: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """Turning points of ``series``: (sample indices, values)."""
    return _core.fatigue_turning_points(as_series(series), float(hysteresis))


def rainflow_cycles(series, residue: str = "half", hysteresis: float = 0.0) -> Cycles:
    """All rainflow cycles of ``series`` (closed cycles first, then the residue)."""
    r = _core.fatigue_cycles(as_series(series), check_residue(residue), float(hysteresis))
    return Cycles(*r)


def range_mean_matrix(
    cycles: Cycles, bins: int | tuple = 32, range_limits=None, mean_limits=None
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Cycle counts binned by (range, mean): (counts (n_range, n_mean), range_edges,
    mean_edges), for plotting."""
    rl = range_limits or (0.0, float(cycles.range.max(initial=0.0)) or 1.0)
    ml = mean_limits or (float(cycles.mean.min(initial=0.0)), float(cycles.mean.max(initial=0.0)))
    if ml[0] == ml[1]:
        ml = (ml[0] - 0.5, ml[1] + 0.5)
    h, re, me = np.histogram2d(
        cycles.range, cycles.mean, bins=bins, range=[rl, ml], weights=cycles.count
    )
    return h, re, me


@dataclass
class RainflowMatrix:
    """Cycle counts (R, M) in bins of range (edges (R+1,)) and mean (edges (M+1,)), in
    ``unit``. The LDA stores the one of its most damaged series (``section_index`` node,
    surface angle ``angle`` and plane ``plane`` in degrees)."""

    range_edges: np.ndarray
    mean_edges: np.ndarray
    counts: np.ndarray
    unit: str = "Pa"
    label: str = ""
    section_index: int | None = None
    arc_length: float | None = None  # m
    angle: float | None = None  # deg, surface angle γ from d1 towards d2
    plane: float | None = None  # deg, critical plane φ from the cable axis

    def __post_init__(self):
        self.range_edges = np.asarray(self.range_edges, dtype=float)
        self.mean_edges = np.asarray(self.mean_edges, dtype=float)
        self.counts = np.asarray(self.counts, dtype=float)
        want = (self.range_edges.size - 1, self.mean_edges.size - 1)
        if self.counts.shape != want:
            raise ValueError(
                f"counts has shape {self.counts.shape}: must be {want} "
                "(len(range_edges) - 1, len(mean_edges) - 1)"
            )

    @property
    def total(self) -> float:
        """Number of cycles (half cycles count 0.5)."""
        return float(self.counts.sum())

    @classmethod
    def of_cycles(cls, cycles: Cycles, bins: int = 32, **kw) -> RainflowMatrix:
        """The range–mean matrix of ``cycles`` (see :func:`range_mean_matrix`)."""
        counts, re, me = range_mean_matrix(cycles, bins)
        return cls(re, me, counts, **kw)


def from_to_matrix(
    series, cycles: Cycles, bins: int = 32, limits=None
) -> tuple[np.ndarray, np.ndarray]:
    """Cycle counts binned by (from value, to value) — the from–to (Markov) matrix of the
    counted cycles: (counts (bins, bins), edges)."""
    x = as_series(series)
    lim = limits or (float(x.min()), float(x.max()))
    if lim[0] == lim[1]:
        lim = (lim[0] - 0.5, lim[1] + 0.5)
    h, e, _ = np.histogram2d(
        x[cycles.from_index],
        x[cycles.to_index],
        bins=bins,
        range=[lim, lim],
        weights=cycles.count,
    )
    return h, e
