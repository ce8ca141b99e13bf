"""Smooth ramps for fading signals in and out."""

from __future__ import annotations

import numpy as np


def smoothstep(t: np.ndarray, start: float, length: float) -> tuple[np.ndarray, ...]:
    """Quintic ramp w from 0 (t ≤ start) to 1 (t ≥ start + length), with w′ and w″.

    w(s) = 10s³ − 15s⁴ + 6s⁵: w′ and w″ vanish at both ends, so a faded signal keeps continuous
    velocity and acceleration. ``length = 0`` gives a unit step at ``start``.
    """
    if length <= 0:
        one = (t >= start).astype(float)
        return one, np.zeros_like(one), np.zeros_like(one)
    s = np.clip((t - start) / length, 0.0, 1.0)
    w = s**3 * (10 - 15 * s + 6 * s**2)
    dw = 30 * s**2 * (1 - s) ** 2 / length
    ddw = 60 * s * (1 - s) * (1 - 2 * s) / length**2
    return w, dw, ddw
