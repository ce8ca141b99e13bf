"""Sine signals with an optional smooth fade-in; displacement and derivatives are analytic."""

from __future__ import annotations

import numpy as np

from cablelife.signals.kinematics import Kinematics
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
    pure = Kinematics(x_amp * s, x_amp * omega * c, -x_amp * omega**2 * s)
    faded = pure.faded_in(t, spec.fade_in)
    return Kinematics(faded.value + spec.offset, faded.velocity, faded.acceleration)
