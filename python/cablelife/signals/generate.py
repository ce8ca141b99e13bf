"""One entry point for every signal type: the channel value and its time derivatives."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from cablelife.signals.kinematics import Kinematics, time_step_of
from cablelife.signals.measured import measured
from cablelife.signals.psd import synthesise
from cablelife.signals.sine import sine
from cablelife.signals.spec import (
    MeasuredSignal,
    PsdSignal,
    Signal,
    SineSignal,
    SweepSignal,
    TableSignal,
)
from cablelife.signals.sweep import sweep
from cablelife.signals.table import table


def kinematics(spec: Signal, time: np.ndarray, base_dir: Path | None = None) -> Kinematics:
    """Value (m or rad), velocity and acceleration of one channel on a uniform time grid.

    Derivatives: analytic for sine and sweep; exact spectral derivatives for PSD signals; the
    spline's derivatives for measured signals and pchip/cubic tables; for linear tables the slope
    and its finite differences. ``base_dir`` resolves relative file names of measured signals.
    """
    t = np.asarray(time, dtype=float)
    dt = time_step_of(t)
    if isinstance(spec, SineSignal):
        return sine(spec, t)
    if isinstance(spec, SweepSignal):
        return sweep(spec, t)
    if isinstance(spec, PsdSignal):
        f_low, f_high = spec.band
        kin = synthesise(spec.psd(), t.size, dt, spec.seed, f_low, f_high)
        return kin.faded_in(t, spec.fade_in)
    if isinstance(spec, MeasuredSignal):
        return measured(spec, t, base_dir)
    if isinstance(spec, TableSignal):
        return table(spec, t)
    raise TypeError(f"not a signal spec: {type(spec).__name__}")


def generate(spec: Signal, time: np.ndarray, base_dir: Path | None = None) -> np.ndarray:
    """The channel's value (T,) in SI units (m or rad) on the uniform grid ``time``."""
    return kinematics(spec, time, base_dir).value


def quantity_series(kin: Kinematics, quantity: str) -> np.ndarray:
    """The displacement, velocity or acceleration series of ``kin``."""
    return {
        "displacement": kin.value,
        "velocity": kin.velocity,
        "acceleration": kin.acceleration,
    }[quantity]
