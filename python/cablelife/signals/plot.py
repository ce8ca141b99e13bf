"""PNG of generated signals: time history and Welch PSD over the target profile (Agg)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.figure import Figure
from scipy.signal import welch

from cablelife.atomic import atomic_path
from cablelife.signals.generate import quantity_series
from cablelife.signals.spec import PsdSignal, SineSignal, SweepSignal
from cablelife.signals.specfile import ChannelSeries, target_quantity
from cablelife.signals.units import psd_unit, si_psd_name


def lowest_frequency(series: ChannelSeries, duration: float) -> float:
    """Lowest frequency of interest, sets the Welch segment length."""
    signal = series.motion.signal
    if isinstance(signal, PsdSignal):
        return signal.band[0]
    if isinstance(signal, SineSignal):
        return signal.frequency
    if isinstance(signal, SweepSignal):
        return min(signal.f0, signal.f1)
    return 8.0 / duration


def welch_psd(values: np.ndarray, time_step: float, f_min: float) -> tuple[np.ndarray, ...]:
    """One-sided Welch PSD (Hann, 50 % overlap), resolution about f_min/16 (record permitting)."""
    n = values.size
    nperseg = int(min(n, 2 ** np.ceil(np.log2(max(16.0 / (f_min * time_step), 16)))))
    return welch(values, fs=1.0 / time_step, nperseg=nperseg)


def plot_signals(path: Path, time: np.ndarray, series: list[ChannelSeries]) -> None:
    """One row per channel: displacement/angle over time, and the PSD of the specified quantity."""
    dt = float(time[1] - time[0])
    fig = Figure(figsize=(12, 3.2 * len(series)))  # Agg canvas, no pyplot state
    axes = fig.subplots(len(series), 2, squeeze=False)
    for row, s in zip(axes, series, strict=True):
        _time_history(row[0], time, s)
        _spectrum(row[1], s, dt, lowest_frequency(s, time[-1] - time[0]))
    fig.tight_layout()

    def write(tmp: Path) -> None:
        fig.savefig(tmp, dpi=110, format="png")

    with atomic_path(path) as tmp:
        write(tmp)


def _time_history(ax, time: np.ndarray, s: ChannelSeries) -> None:
    rotation = s.motion.unit == "rad"
    factor, unit = (180 / np.pi, "deg") if rotation else (1e3, "mm")
    ax.plot(time, factor * s.kinematics.value, lw=0.6)
    ax.set_xlabel("time [s]")
    ax.set_ylabel(f"{s.name} [{unit}]")
    rms = np.std(s.kinematics.value) * factor
    ax.set_title(f"{s.name}: {s.motion.signal.type}, {s.motion.frame} frame, RMS {rms:.4g} {unit}")
    ax.grid(alpha=0.3)


def _spectrum(ax, s: ChannelSeries, dt: float, f_min: float) -> None:
    quantity = target_quantity(s.motion)
    dim = "angle" if s.motion.unit == "rad" else "length"
    signal = s.motion.signal
    unit_name, factor = si_psd_name(quantity, dim), 1.0
    if isinstance(signal, PsdSignal) and signal.psd_unit is not None:
        unit_name, factor = signal.psd_unit.name, psd_unit(signal.psd_unit.name).factor
    f, p = welch_psd(quantity_series(s.kinematics, quantity), dt, f_min)
    ax.loglog(f[1:], p[1:] / factor, lw=0.8, label="generated (Welch)")
    if isinstance(signal, PsdSignal):
        target = signal.psd()
        lo, hi = signal.band
        ft = np.geomspace(lo, min(hi, 0.5 / dt), 400)
        gt = target(ft) / factor
        ax.loglog(ft, gt, "k--", lw=1.2, label="target")
        ax.set_ylim(gt.min() / 30, gt.max() * 10)
        ax.set_xlim(lo / 2, min(target.frequency[-1] * 1.5, 0.5 / dt))
        ax.axvspan(f[1], lo, color="0.9", zorder=0)
    else:
        top = p[1:].max() / factor
        ax.set_ylim(top * 1e-8, top * 10)
    ax.set_xlabel("frequency [Hz]")
    ax.set_ylabel(f"{quantity} PSD [{unit_name}]")
    ax.grid(alpha=0.3, which="both")
    ax.legend(loc="best", fontsize=8)
