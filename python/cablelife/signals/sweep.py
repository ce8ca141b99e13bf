"""Sine sweeps: linear or logarithmic frequency law, constant amplitude of a chosen quantity.

Frequency and phase (t from the start of the sweep, D its duration):
- linear: f(t) = f0 + (f1 − f0) t/D,  Φ(t) = 2π (f0 t + (f1 − f0) t²/(2D))
- log:    f(t) = f0 2^(R t/60),       Φ(t) = 2π f0 60/(R ln 2) (2^(R t/60) − 1)
  R in octaves per minute (negative for a downward sweep), D = 60 log2(f1/f0)/R.
The displacement is x = w(t) X(t) sin(Φ + φ − kπ/2), X = A/(2πf)^k for a constant amplitude A of
displacement (k = 0), velocity (1) or acceleration (2); w fades in and out. Velocity and
acceleration are the exact derivatives of x (including the slowly varying X and w).
"""

from __future__ import annotations

import math

import numpy as np

from cablelife.signals.kinematics import Kinematics
from cablelife.signals.ramp import smoothstep
from cablelife.signals.spec import SweepSignal
from cablelife.signals.units import DERIVATIVE_ORDER


def sweep_frequency(spec: SweepSignal, time: np.ndarray) -> tuple[np.ndarray, ...]:
    """Instantaneous frequency f (Hz), its derivatives f′, f″ and the phase Φ (rad) at ``time``.

    Time is clipped to the sweep [0, D].
    """
    duration = spec.sweep_duration
    t = np.clip(np.asarray(time, dtype=float), 0.0, duration)
    if spec.law == "linear":
        k = (spec.f1 - spec.f0) / duration
        f = spec.f0 + k * t
        return f, np.full_like(t, k), np.zeros_like(t), 2 * np.pi * (spec.f0 * t + k * t**2 / 2)
    rate = 60.0 * math.log2(spec.f1 / spec.f0) / duration  # signed octaves per minute
    c = rate * math.log(2) / 60.0  # f′/f
    growth = np.exp(c * t)
    f = spec.f0 * growth
    return f, c * f, c * c * f, 2 * np.pi * spec.f0 * (growth - 1) / c


def sweep(spec: SweepSignal, time: np.ndarray) -> Kinematics:
    """Displacement (m or rad), velocity and acceleration of a sweep spec at ``time`` (s)."""
    t = np.asarray(time, dtype=float)
    duration = spec.sweep_duration
    unit = spec.amplitude_unit
    amplitude = spec.amplitude * (unit.factor if unit else 1.0)
    order = DERIVATIVE_ORDER[spec.quantity]

    f, df, ddf, phase = sweep_frequency(spec, t)
    theta = phase + spec.phase - order * np.pi / 2
    dtheta, ddtheta = 2 * np.pi * f, 2 * np.pi * df

    # displacement amplitude X = A (2πf)^-k and its time derivatives
    x_amp = amplitude / (2 * np.pi * f) ** order
    dx_amp = -order * x_amp * df / f
    ddx_amp = order * (order + 1) * x_amp * (df / f) ** 2 - order * x_amp * ddf / f

    # window: fade in at 0, fade out at D, zero outside [0, D]
    w_in, dw_in, ddw_in = smoothstep(t, 0.0, spec.fade)
    w_out, dw_out, ddw_out = smoothstep(-t, -duration, spec.fade)
    dw_out, ddw_out = -dw_out, ddw_out  # chain rule for the reflected argument
    w = w_in * w_out
    dw = dw_in * w_out + w_in * dw_out
    ddw = ddw_in * w_out + 2 * dw_in * dw_out + w_in * ddw_out

    g = w * x_amp
    dg = dw * x_amp + w * dx_amp
    ddg = ddw * x_amp + 2 * dw * dx_amp + w * ddx_amp
    s, c = np.sin(theta), np.cos(theta)
    value = g * s
    velocity = dg * s + g * dtheta * c
    acceleration = ddg * s + 2 * dg * dtheta * c + g * ddtheta * c - g * dtheta**2 * s
    return Kinematics(value, velocity, acceleration)
