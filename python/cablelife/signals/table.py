"""Inline tables t/value interpolated onto the time grid."""

from __future__ import annotations

import numpy as np

from cablelife.signals.kinematics import Kinematics, grid_derivatives, time_step_of
from cablelife.signals.spec import TableSignal


def table(spec: TableSignal, time: np.ndarray) -> Kinematics:
    """Displacement (m or rad) with derivatives; end values held outside the table.

    ``pchip`` and ``cubic`` give the interpolant's analytic derivatives (zero outside the table);
    ``linear`` gives piecewise constant velocity and the acceleration by finite differences on
    the grid (spikes at the kinks: use pchip or cubic for dynamic runs).
    """
    t = np.asarray(time, dtype=float)
    factor = spec.amplitude_unit.factor if spec.amplitude_unit else 1.0
    knots = np.asarray(spec.t, dtype=float)
    values = factor * np.asarray(spec.value, dtype=float)
    inside = (t >= knots[0]) & (t <= knots[-1])
    clipped = np.clip(t, knots[0], knots[-1])
    if spec.interpolation == "linear":
        value = np.interp(t, knots, values)
        dt = time_step_of(t)
        slopes = np.diff(values) / np.diff(knots)
        seg = np.clip(np.searchsorted(knots, t, side="right") - 1, 0, len(slopes) - 1)
        velocity = np.where(inside, slopes[seg], 0.0)
        acceleration = grid_derivatives(velocity, dt).velocity
        return Kinematics(value, velocity, acceleration)
    from scipy.interpolate import CubicSpline, PchipInterpolator

    curve = (
        PchipInterpolator(knots, values)
        if spec.interpolation == "pchip"
        else CubicSpline(knots, values, bc_type="natural")
    )
    value = curve(clipped)
    velocity = np.where(inside, curve(clipped, 1), 0.0)
    acceleration = np.where(inside, curve(clipped, 2), 0.0)
    return Kinematics(value, velocity, acceleration)
