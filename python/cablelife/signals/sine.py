"""Sine signals with an optional smooth fade-in; displacement and derivatives are analytic."""

from __future__ import annotations

import numpy as np

from cablelife.signals.kinematics import Kinematics
from cablelife.signals.ramp import smoothstep
from cablelife.signals.spec import SineSignal
from cablelife.signals.units import DERIVATIVE_ORDER


def sine(spec: SineSignal, time: np.ndarray) -> Kinematics:
    """Displacement (m or rad), velocity and acceleration of a sine spec at ``time`` (s).

    q(t) = A sin(ωt + φ) of the spec's quantity, integrated k times (k = 0, 1, 2):
    x(t) = w(t)·(A/ω^k)·sin(ωt + φ − kπ/2) + offset, w the fade-in ramp.
    """
    t = np.asarray(time, dtype=float)
    unit = spec.amplitude_unit
    amplitude = spec.amplitude * (unit.factor if unit else 1.0)
    order = DERIVATIVE_ORDER[spec.quantity]
    omega = 2 * np.pi * spec.frequency
    x_amp = amplitude / omega**order
    theta = omega * t + spec.phase - order * np.pi / 2
    s, c = np.sin(theta), np.cos(theta)
    w, dw, ddw = smoothstep(t, 0.0, spec.fade_in)
    if spec.fade_in <= 0:
        w, dw, ddw = np.ones_like(t), np.zeros_like(t), np.zeros_like(t)
    value = w * x_amp * s + spec.offset
    velocity = x_amp * (dw * s + w * omega * c)
    acceleration = x_amp * (ddw * s + 2 * dw * omega * c - w * omega**2 * s)
    return Kinematics(value, velocity, acceleration)
