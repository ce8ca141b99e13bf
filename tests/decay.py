"""Free-decay measurement shared by the dynamics tests (single cables and harnesses)."""

from __future__ import annotations

import math

import numpy as np


def free_decay(time, y, after: float) -> tuple[float, float]:
    """Damping ratio (logarithmic decrement over the peaks of ``y`` after ``after`` s) and the
    mean period of a free decay."""
    peaks = [i for i in range(1, y.size - 1)
             if y[i] > y[i - 1] and y[i] >= y[i + 1] and time[i] > after]  # fmt: skip
    amps = y[peaks]
    n = len(amps) - 1
    assert n >= 3, "need several periods"
    delta = math.log(amps[0] / amps[n]) / n
    return delta / math.sqrt(4 * math.pi**2 + delta**2), float(np.diff(time[peaks]).mean())
