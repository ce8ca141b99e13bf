"""The time grid and the kinematics (value and its time derivatives) of one channel."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from cablelife.signals.errors import SignalError

#: Allowed deviation of any time step from the mean step of a "uniform" grid (relative).
UNIFORM_TOLERANCE = 1e-6


@dataclass
class Kinematics:
    """One channel over a time grid, SI units (m or rad, per s, per s²)."""

    value: np.ndarray  # (T,) displacement (m) or angle (rad)
    velocity: np.ndarray  # (T,) first time derivative
    acceleration: np.ndarray  # (T,) second time derivative

    def __add__(self, other: Kinematics) -> Kinematics:
        return Kinematics(
            self.value + other.value,
            self.velocity + other.velocity,
            self.acceleration + other.acceleration,
        )

    def faded_in(self, time: np.ndarray, fade_in: float) -> Kinematics:
        """This motion multiplied by the quintic ramp w over ``fade_in`` s from t = 0 (product
        rule for the derivatives): it starts at rest, with continuous velocity and
        acceleration. ``fade_in = 0`` returns it unchanged."""
        if fade_in <= 0:
            return self
        from cablelife.signals.ramp import smoothstep

        w, dw, ddw = smoothstep(np.asarray(time, dtype=float), 0.0, fade_in)
        return Kinematics(
            w * self.value,
            dw * self.value + w * self.velocity,
            ddw * self.value + 2 * dw * self.velocity + w * self.acceleration,
        )

    @classmethod
    def zeros(cls, n: int) -> Kinematics:
        return cls(np.zeros(n), np.zeros(n), np.zeros(n))


# Samples of one time grid: each channel keeps value, velocity and acceleration (3 × 8 bytes
# per sample), so this bounds a channel at 1.2 GB.
MAX_SAMPLES = 50_000_000


def time_grid(duration: float, time_step: float, start: float = 0.0) -> np.ndarray:
    """Uniform grid ``start, start + dt, ...`` up to ``start + duration`` (inclusive, rounded)."""
    if not (np.isfinite(duration) and duration > 0):
        raise SignalError(f"duration: must be a finite number > 0 s, got {duration!r}")
    if not (np.isfinite(time_step) and time_step > 0):
        raise SignalError(f"time_step: must be a finite number > 0 s, got {time_step!r}")
    if time_step > duration:
        raise SignalError(
            f"time_step: {time_step:g} s is longer than the duration {duration:g} s; "
            "allowed: time_step <= duration"
        )
    steps = float(np.floor(duration / time_step + 1e-9))  # float: inf for absurd input
    if steps + 1 > MAX_SAMPLES:
        raise SignalError(
            f"time_step: {time_step:g} s over {duration:g} s is {steps + 1:.4g} samples; "
            f"allowed: at most {MAX_SAMPLES:.0e} per channel (memory); use a larger time_step "
            "or a shorter duration"
        )
    return start + time_step * np.arange(int(steps) + 1)


def time_step_of(time: np.ndarray) -> float:
    """The step of a uniform, increasing time grid; a clear error for anything else."""
    t = np.asarray(time, dtype=float)
    if t.ndim != 1 or t.size < 2:
        raise SignalError(f"time: must be a 1-D array of at least 2 samples, got shape {t.shape}")
    if not np.all(np.isfinite(t)):
        bad = int(np.flatnonzero(~np.isfinite(t))[0])
        raise SignalError(f"time: sample {bad} is {t[bad]}; allowed: finite numbers")
    steps = np.diff(t)
    dt = (t[-1] - t[0]) / (t.size - 1)
    if dt <= 0 or np.any(steps <= 0):
        bad = int(np.flatnonzero(steps <= 0)[0]) if np.any(steps <= 0) else 0
        raise SignalError(f"time: must increase; step {bad} -> {bad + 1} is {steps[bad]} s")
    deviation = np.abs(steps - dt) / dt
    if deviation.max() > UNIFORM_TOLERANCE:
        bad = int(np.argmax(deviation))
        raise SignalError(
            f"time: must be uniformly spaced; step {bad} is {steps[bad]} s, mean step {dt} s "
            f"(allowed relative deviation {UNIFORM_TOLERANCE:g})"
        )
    return float(dt)


def grid_derivatives(value: np.ndarray, dt: float) -> Kinematics:
    """Velocity and acceleration by second-order central finite differences on the grid."""
    velocity = np.gradient(value, dt, edge_order=2) if value.size > 2 else np.gradient(value, dt)
    acceleration = (
        np.gradient(velocity, dt, edge_order=2) if value.size > 2 else np.zeros_like(value)
    )
    return Kinematics(value, velocity, acceleration)
