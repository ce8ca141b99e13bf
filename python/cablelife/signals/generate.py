"""One entry point for every signal type: the channel value and its time derivatives."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from cablelife.signals.errors import SignalError
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


def kinematics(
    spec: Signal, time: np.ndarray, base_dir: Path | None = None, allow_outside: bool = False
) -> Kinematics:
    """Value (m or rad), velocity and acceleration of one channel on a uniform time grid.

    Derivatives: analytic for sine and sweep; exact spectral derivatives for PSD signals; the
    spline's derivatives for measured signals and pchip/cubic tables; for linear tables the slope
    and its finite differences. ``base_dir`` resolves relative file names of measured signals;
    files outside it are read only with ``allow_outside`` (cablelife.paths).
    """
    t = np.asarray(time, dtype=float)
    dt = time_step_of(t)
    if isinstance(spec, SineSignal | SweepSignal):
        _check_nyquist(spec, dt)
        return sine(spec, t) if isinstance(spec, SineSignal) else sweep(spec, t)
    if isinstance(spec, PsdSignal):
        f_low, f_high = spec.band
        kin = synthesise(spec.psd(), t.size, dt, spec.seed, f_low, f_high)
        return kin.faded_in(t, spec.fade_in)
    if isinstance(spec, MeasuredSignal):
        return measured(spec, t, base_dir, allow_outside)
    if isinstance(spec, TableSignal):
        return table(spec, t)
    raise TypeError(f"not a signal spec: {type(spec).__name__}")


def _check_nyquist(spec: SineSignal | SweepSignal, dt: float) -> None:
    """A sine or sweep above the Nyquist frequency of the time step would be sampled as another
    (aliased) frequency: refused, naming the frequency and the largest allowed."""
    f = spec.frequency if isinstance(spec, SineSignal) else max(spec.f0, spec.f1)
    nyquist = 0.5 / dt
    if f >= nyquist:
        key = "frequency" if isinstance(spec, SineSignal) else "f0/f1"
        raise SignalError(
            f"{spec.type} signal: {key} = {f:g} Hz is at or above the Nyquist frequency "
            f"{nyquist:g} Hz of time_step = {dt:g} s (it would alias to another frequency); "
            f"allowed: below {nyquist:g} Hz, or a time_step below {0.5 / f:g} s"
        )


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
