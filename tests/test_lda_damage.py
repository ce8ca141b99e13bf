"""Palmgren–Miner damage with a Wöhler curve in ranges (Rust batch kernel)."""

import numpy as np
import pytest
import rainflow
from cablelife.lda import (
    WohlerCurve,
    damage,
    damage_combined,
    equivalent_range,
    pseudo_damage_curve,
)
from cablelife.lda.damage import equivalent_range_from_damage


def constant_amplitude(n_cycles, mean, rng_):
    x = np.empty(2 * n_cycles + 1)
    x[0::2] = mean - rng_ / 2
    x[1::2] = mean + rng_ / 2
    return x


def test_constant_amplitude_miner_is_n_over_n_exactly():
    curve = WohlerCurve(k=5.0, alpha=2e12)
    x = constant_amplitude(1000, 3.0, 40.0)  # 1000 cycles of range 40
    n_fail = curve.cycles_to_failure(40.0)
    assert n_fail == pytest.approx(2e12 / 40.0**5)
    assert damage(x, curve) == pytest.approx(1000 / n_fail, rel=1e-14)


def test_pseudo_damage_default_curve():
    """k = 5 through (1 MPa, 1e6 cycles): 1e6 cycles of a 1 MPa range give D = 1."""
    c = pseudo_damage_curve()
    assert (c.k, c.pseudo) == (5.0, True)
    assert c.cycles_to_failure(1e6) == pytest.approx(1e6)
    x = constant_amplitude(1000, 0.0, 2e6)
    assert damage(x) == pytest.approx(1000 * 2.0**5 / 1e6, rel=1e-13)


@pytest.mark.parametrize("c", [0.3, 2.0, 7.5])
def test_scaling_the_load_by_c_scales_damage_by_c_pow_k(c):
    x = np.random.default_rng(1).normal(size=20000) * 1e6
    for k in (3.0, 5.0, 6.5):
        curve = WohlerCurve(k=k, alpha=1e30)
        assert damage(c * x, curve) / damage(x, curve) == pytest.approx(c**k, rel=1e-12)


def test_damage_equals_miner_sum_of_the_rainflow_package_cycles():
    x = np.random.default_rng(5).normal(size=5000)
    curve = WohlerCurve(k=5.0, alpha=1.0)
    ref = sum(n * r**5 for r, _, n, _, _ in rainflow.extract_cycles(x.tolist()))
    assert damage(x, curve) == pytest.approx(ref, rel=1e-12)


def test_knee_haibach_and_cutoff():
    c_h = WohlerCurve.from_point(5.0, 50e6, 2e6, knee=True, knee_kind="haibach")
    c_c = WohlerCurve.from_point(5.0, 50e6, 2e6, knee=True, knee_kind="cutoff")
    assert c_h.knee_cycles == pytest.approx(2e6)
    below = constant_amplitude(100, 0.0, 25e6)
    above = constant_amplitude(100, 0.0, 100e6)
    assert damage(below, c_c) == 0.0
    assert damage(below, c_h) == pytest.approx(100 / (2e6 * 2.0**9), rel=1e-12)
    assert damage(above, c_h) == pytest.approx(100 / (2e6 / 32), rel=1e-12)
    assert c_h.cycles_to_failure(25e6) == pytest.approx(2e6 * 2.0**9)
    assert np.isinf(c_c.cycles_to_failure(25e6))


def test_equivalent_range():
    x = np.concatenate([constant_amplitude(100, 0, 10.0), constant_amplitude(10, 0, 30.0)])
    k = 4.0
    # rainflow: 100 + 10 cycles plus the junction; compute the reference from the cycles
    ref_sum = sum(n * r**k for r, _, n, _, _ in rainflow.extract_cycles(x.tolist()))
    assert equivalent_range(x, k, n_ref=1e3) == pytest.approx((ref_sum / 1e3) ** (1 / k))
    curve = WohlerCurve(k=k, alpha=1e9)
    d = damage(x, curve)
    assert equivalent_range_from_damage(d, curve, 1e3) == pytest.approx((ref_sum / 1e3) ** (1 / k))
    with pytest.raises(ValueError, match="without knee"):
        equivalent_range_from_damage(d, WohlerCurve(k=k, alpha=1e9, knee_range=5.0), 1e3)


def test_batch_threads_and_combined_kernel_agree():
    rng = np.random.default_rng(9)
    loads = rng.normal(size=(4, 3000, 6))
    weights = rng.normal(size=(7, 6))
    curve = WohlerCurve(k=5.0, alpha=1.0)
    d = damage_combined(loads, weights, curve)
    series = np.einsum("gtc,jc->gjt", loads, weights).reshape(28, 3000)
    d1 = damage(series, curve, threads=1)
    d2 = damage(series, curve, threads=2)
    np.testing.assert_array_equal(d1, d2)
    np.testing.assert_allclose(d.reshape(-1), d1, rtol=1e-9)
    assert damage(series[3], curve) == d1[3]


@pytest.mark.parametrize(
    ("call", "message"),
    [
        (lambda: WohlerCurve(k=0.0, alpha=1.0), "k = 0.0"),
        (lambda: WohlerCurve(k=-2.0, alpha=1.0), "k = -2.0"),
        (lambda: WohlerCurve(k=5.0, alpha=-1.0), "alpha = -1.0"),
        (lambda: WohlerCurve(k=5.0, alpha=1.0, knee_range=0.0), "knee_range = 0.0"),
        (lambda: WohlerCurve(k=5.0, alpha=1.0, knee_kind="elbow"), "knee_kind = 'elbow'"),
        (lambda: damage([1.0, np.nan, 2.0]), "non-finite sample nan at index 1"),
        (lambda: damage(np.array([[1.0, 2.0], [3.0, np.inf]])), "series 1 .*index 1"),
        (lambda: damage([]), "empty"),
        (lambda: damage(np.zeros((3, 0))), "at least one sample"),
        (lambda: damage([1.0, 2.0], threads=0), "threads = 0"),
        (lambda: damage([1.0, 2.0], residue="all"), "residue = 'all'"),
        (lambda: damage_combined(np.zeros((2, 5, 6)), np.zeros((3, 5))), "weights has shape"),
        (lambda: equivalent_range([1.0, 2.0], 5.0, n_ref=0.0), "n_ref = 0.0"),
    ],
)
def test_bad_input_errors(call, message):
    with pytest.raises(ValueError, match=message):
        call()


def test_kernel_reads_fortran_ordered_arrays_in_logical_order():
    # The binding borrows C-contiguous memory only: a Fortran-ordered array (contiguous too,
    # but column-major) gives the damage of the same logical rows.
    from cablelife import _core

    rng = np.random.default_rng(0)
    x = rng.normal(size=(8, 400))
    np.testing.assert_array_equal(
        _core.fatigue_damage_many(np.asfortranarray(x), 5.0, 1.0),
        _core.fatigue_damage_many(x, 5.0, 1.0),
    )
    s, w = rng.normal(size=(3, 200, 6)), rng.normal(size=(4, 6))
    np.testing.assert_array_equal(
        _core.fatigue_damage_combined(np.asfortranarray(s), np.asfortranarray(w), 5.0, 1.0),
        _core.fatigue_damage_combined(s, w, 5.0, 1.0),
    )
