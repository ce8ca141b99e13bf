"""Rainflow counting (Rust kernel through cablelife.lda): ASTM E1049-85 and the PyPI package."""

import numpy as np
import pytest
import rainflow
from cablelife.lda import rainflow_cycles, range_mean_matrix, turning_points
from cablelife.lda.rainflow import from_to_matrix

ASTM = [-2.0, 1.0, -3.0, 5.0, -1.0, 3.0, -4.0, 4.0, -2.0]


def histogram(cycles):
    h = {}
    for r, n in zip(cycles.range.tolist(), cycles.count.tolist(), strict=True):
        h[r] = h.get(r, 0.0) + n
    return sorted(h.items())


def test_astm_e1049_example_table():
    """ASTM E1049-85 §5.4.4: ranges (count) 3 (0.5), 4 (1.5), 6 (0.5), 8 (1.0), 9 (0.5)."""
    c = rainflow_cycles(ASTM)
    assert histogram(c) == [(3.0, 0.5), (4.0, 1.5), (6.0, 0.5), (8.0, 1.0), (9.0, 0.5)]
    assert c.total == 4.0


def test_astm_example_equals_rainflow_package_with_indices():
    ours = sorted(rainflow_cycles(ASTM).as_tuples(), key=lambda t: (t[3], t[4]))
    ref = sorted(rainflow.extract_cycles(ASTM), key=lambda t: (t[3], t[4]))
    assert ours == ref


@pytest.mark.parametrize("seed", range(20))
def test_random_series_cycle_list_equals_rainflow_package(seed):
    """Same residue convention (half cycles): identical ranges, means, counts and indices."""
    rng = np.random.default_rng(seed)
    n = int(rng.integers(2, 3000))
    x = np.cumsum(rng.normal(size=n)) if seed % 2 else rng.normal(size=n)
    ours = sorted(rainflow_cycles(x).as_tuples(), key=lambda t: (t[3], t[4]))
    ref = sorted(rainflow.extract_cycles(x.tolist()), key=lambda t: (t[3], t[4]))
    assert len(ours) == len(ref)
    for a, b in zip(ours, ref, strict=True):
        assert a[2:] == b[2:]
        assert a[0] == pytest.approx(b[0], rel=1e-15, abs=0)
        assert a[1] == pytest.approx(b[1], rel=1e-15, abs=1e-300)


def test_integer_series_with_plateaus_equal_rainflow_package():
    """Ties and plateaus: counted identically (plateau reversals sit at their last sample;
    equal ranges close a cycle, X >= Y, as in ASTM)."""
    rng = np.random.default_rng(7)
    x = rng.integers(-3, 4, size=2000).astype(float)
    ours = sorted(rainflow_cycles(x).as_tuples(), key=lambda t: (t[3], t[4]))
    ref = sorted(rainflow.extract_cycles(x.tolist()), key=lambda t: (t[3], t[4]))
    assert ours == ref


def test_turning_points_equal_rainflow_reversals():
    x = np.random.default_rng(3).normal(size=500)
    i, v = turning_points(x)
    ref = list(rainflow.reversals(x.tolist()))
    assert i.tolist() == [r[0] for r in ref]
    assert v.tolist() == [r[1] for r in ref]


def test_residue_treatments_on_astm_example():
    assert histogram(rainflow_cycles(ASTM, residue="discard")) == [(4.0, 1.0)]
    assert histogram(rainflow_cycles(ASTM, residue="full")) == [
        (3.0, 1.0),
        (4.0, 2.0),
        (6.0, 1.0),
        (8.0, 2.0),
        (9.0, 1.0),
    ]
    # the history repeated: 5 -1 3 -4 4 -2 1 -3 (5) closes 4, 3, 7, 9 per repetition
    assert histogram(rainflow_cycles(ASTM, residue="repeated")) == [
        (3.0, 1.0),
        (4.0, 1.0),
        (7.0, 1.0),
        (9.0, 1.0),
    ]


def test_repeated_residue_equals_counting_a_repeated_history():
    """For a history ending where it starts, 'repeated' counts one period of the periodic
    history: the extra cycles of counting it three times, per added repetition."""
    rng = np.random.default_rng(11)
    x = rng.normal(size=400)
    x[-1] = x[0]
    k = 4
    d_rep = np.sum(rainflow_cycles(x, residue="repeated").range ** k)

    def d_half(y):
        c = rainflow_cycles(y)
        return np.sum(c.count * c.range**k)

    per_period = d_half(np.concatenate([x, x[1:], x[1:]])) - d_half(np.concatenate([x, x[1:]]))
    assert d_rep == pytest.approx(per_period, rel=1e-12)


@pytest.mark.parametrize("period", [4, 7, 40, 41])
@pytest.mark.parametrize("periods", [1, 3, 5])
@pytest.mark.parametrize("phase", [0.0, 0.3, 1.1, 2.9])
def test_repeated_residue_counts_the_periods_of_a_sine(period, periods, phase):
    """k periods of a sampled sine are k cycles (the residue once repeated, not the whole ASTM
    stack doubled; the old count depended on round-off)."""
    t = np.arange(period * periods + 1)
    x = np.sin(2 * np.pi * t / period + phase)
    c = rainflow_cycles(x, residue="repeated", hysteresis=1e-9)
    assert c.count.sum() == periods
    assert c.range.min() > 1.4 * np.abs(x).max()


def test_repeated_residue_reported_cases():
    x = np.sin(2 * np.pi * np.arange(201) / 40)
    assert rainflow_cycles(x, residue="repeated").count.sum() == 5
    c = rainflow_cycles(np.array([0.0, 1, -1, 1, -1, 1, -1, 0]), residue="repeated")
    assert histogram(c) == [(2.0, 3.0)]


def test_hysteresis_gate_drops_small_cycles():
    x = np.array([0.0, 10.0, 9.5, 10.5, 0.2, 0.6, -1.0, 8.0])
    c = rainflow_cycles(x, hysteresis=1.0)
    assert c.range.min() > 1.0
    i, v = turning_points(x, hysteresis=1.0)
    assert v.tolist() == [0.0, 10.5, -1.0, 8.0]
    assert rainflow_cycles(x).range.min() < 1.0


def test_matrices_sum_to_the_cycle_count():
    x = np.random.default_rng(1).normal(size=3000)
    c = rainflow_cycles(x)
    h, re, me = range_mean_matrix(c, bins=16)
    assert h.sum() == pytest.approx(c.total)
    ft, e = from_to_matrix(x, c, bins=16)
    assert ft.sum() == pytest.approx(c.total)


@pytest.mark.parametrize(
    ("series", "kwargs", "message"),
    [
        ([0.0, np.nan, 1.0], {}, "non-finite sample nan at index 1"),
        ([], {}, "empty"),
        ([[0.0, 1.0]], {}, "one-dimensional"),
        ([0.0, 1.0], {"residue": "halves"}, "residue = 'halves'"),
        ([0.0, 1.0], {"hysteresis": -1.0}, "hysteresis = -1"),
    ],
)
def test_bad_input_errors_name_the_problem(series, kwargs, message):
    with pytest.raises(ValueError, match=message):
        rainflow_cycles(series, **kwargs)
