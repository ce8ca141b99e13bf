"""The vertical axis of the 3D views has no tick at the corner shared with the y axis."""

import numpy as np
import pytest
from cablelife.report.scene3d import _ticks_off_corner


@pytest.mark.parametrize("lo,hi", [(-0.55, 0.55), (0.0, 1.0), (-0.013, 0.2), (-3.2, 7.9)])
def test_ticks_round_inside_and_off_the_lower_corner(lo, hi):
    ticks = np.array(_ticks_off_corner(lo, hi))
    span = hi - lo
    assert 3 <= len(ticks) <= 6
    assert ticks.min() >= lo + 0.08 * span and ticks.max() <= hi
    steps = np.diff(ticks)
    assert np.allclose(steps, steps[0])  # evenly spaced
    mant = steps[0] / 10 ** np.floor(np.log10(steps[0]))
    assert any(np.isclose(mant, m) for m in (1, 2, 2.5, 5))  # a round step


def test_demo_like_range_drops_the_corner_tick():
    # the merged view of the demo: range ±0.55; -0.5 (drawn over the y axis' -0.5) is gone
    assert _ticks_off_corner(-0.55, 0.55) == [-0.4, -0.2, 0.0, 0.2, 0.4]
