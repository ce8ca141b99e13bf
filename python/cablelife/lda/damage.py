"""Palmgren–Miner damage of series by rainflow counting (Rust kernel, parallel, GIL released).

D = Σ n_i / N(ΔS_i) with the :class:`~cablelife.lda.wohler.WohlerCurve` in ranges. Life in
repeats of the analysed history: 1/D. Damage-equivalent stress range for N_ref cycles: the
constant range that gives the same damage on the single-slope line,
ΔS_eq = (Σ n_i ΔS_i^k / N_ref)^(1/k) (the knee is ignored by definition).
"""

from __future__ import annotations

import numpy as np

from cablelife import _core
from cablelife.lda.rainflow import as_series, check_residue
from cablelife.lda.wohler import WohlerCurve, pseudo_damage_curve


def _check_threads(threads):
    if threads is not None and not (isinstance(threads, int | np.integer) and threads >= 1):
        raise ValueError(f"threads = {threads!r}: must be an integer >= 1 or None (all cores)")
    return None if threads is None else int(threads)


def _as_batch(series) -> np.ndarray:
    x = np.asarray(series, dtype=float)
    if x.ndim == 1:
        x = x[None, :]
    if x.ndim != 2:
        raise ValueError(
            f"series has shape {x.shape}: must be (n_samples,) or (n_series, n_samples)"
        )
    if x.shape[1] == 0:
        raise ValueError(f"series has shape {x.shape}: every series needs at least one sample")
    return np.ascontiguousarray(x)


def damage(
    series,
    curve: WohlerCurve | None = None,
    *,
    residue: str = "half",
    hysteresis: float = 0.0,
    threads: int | None = None,
):
    """Miner damage of one series (float) or of every row of a 2-D array (array).

    ``curve`` defaults to :func:`pseudo_damage_curve`; ``threads=None`` uses all cores."""
    curve = curve or pseudo_damage_curve()
    one = np.ndim(series) == 1
    if one:
        as_series(series)
    x = _as_batch(series)
    d = _core.fatigue_damage_many(
        x,
        **curve.kernel_args(),
        residue=check_residue(residue),
        hysteresis=float(hysteresis),
        threads=_check_threads(threads),
    )
    return float(d[0]) if one else d


def equivalent_range(
    series,
    k: float,
    n_ref: float = 1e6,
    *,
    residue: str = "half",
    hysteresis: float = 0.0,
    threads: int | None = None,
):
    """Damage-equivalent stress range(s) for ``n_ref`` cycles at slope ``k``."""
    if not (np.isfinite(n_ref) and n_ref > 0):
        raise ValueError(f"n_ref = {n_ref!r}: must be a finite cycle count > 0")
    unit = WohlerCurve(k=k, alpha=1.0)
    s = damage(series, unit, residue=residue, hysteresis=hysteresis, threads=threads)
    return (np.asarray(s) / n_ref) ** (1.0 / k) if np.ndim(s) else (s / n_ref) ** (1.0 / k)


def equivalent_range_from_damage(d, curve: WohlerCurve, n_ref: float = 1e6):
    """ΔS_eq = (α D / N_ref)^(1/k) for damage computed with a curve WITHOUT knee."""
    if curve.knee_range is not None:
        raise ValueError(
            "equivalent range from damage needs a curve without knee (knee_range is "
            f"{curve.knee_range}); use equivalent_range(series, k, n_ref) instead"
        )
    return (curve.alpha * np.asarray(d, float) / n_ref) ** (1.0 / curve.k)


def damage_combined(
    signals: np.ndarray,
    weights: np.ndarray,
    curve: WohlerCurve | None = None,
    *,
    residue: str = "half",
    hysteresis: float = 0.0,
    threads: int | None = None,
) -> np.ndarray:
    """Damage of every series ``signals[g] @ weights[j]`` without storing the series.

    ``signals`` (n_groups, T, n_channels), ``weights`` (n_series, n_channels); returns
    (n_groups, n_series). For the LDA: groups = cross sections, channels = section loads."""
    curve = curve or pseudo_damage_curve()
    sig = np.ascontiguousarray(signals, dtype=float)
    w = np.ascontiguousarray(weights, dtype=float)
    if sig.ndim != 3:
        raise ValueError(f"signals has shape {sig.shape}: must be (n_groups, T, n_channels)")
    if w.ndim != 2 or w.shape[1] != sig.shape[2]:
        raise ValueError(
            f"weights has shape {w.shape}: must be (n_series, {sig.shape[2]}) for signals "
            f"of shape {sig.shape}"
        )
    if sig.shape[1] == 0:
        raise ValueError(f"signals has shape {sig.shape}: needs at least one time step")
    return _core.fatigue_damage_combined(
        sig,
        w,
        **curve.kernel_args(),
        residue=check_residue(residue),
        hysteresis=float(hysteresis),
        threads=_check_threads(threads),
    )
