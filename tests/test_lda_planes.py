"""Critical planes: normal stress on planes of the surface tangent plane."""

import numpy as np
import pytest
from cablelife.lda import (
    CircularSection,
    plane_angles,
    plane_weights,
    section_series,
    surface_angles,
)
from cablelife.lda.planes import normal_stress


def test_max_over_a_fine_plane_set_is_the_larger_principal_stress():
    """max_φ σ_n(φ) = σ/2 + √(σ²/4 + τ²). With a 0.5° step the grid misses the maximum by at
    most 1 − cos(0.5°) = 3.8e-5 of the Mohr radius."""
    rng = np.random.default_rng(0)
    sigma = rng.normal(size=500) * 50e6
    tau = rng.normal(size=500) * 30e6
    phi = plane_angles(0.5)
    sn = normal_stress(sigma[:, None], tau[:, None], phi[None, :])
    radius = np.sqrt(sigma**2 / 4 + tau**2)
    principal = sigma / 2 + radius
    assert np.all(sn.max(axis=1) <= principal + 1e-9 * radius)
    np.testing.assert_array_less(principal - sn.max(axis=1), 3.9e-5 * radius)


def test_default_step_loss_in_pure_shear_is_one_minus_cos_step():
    """Pure shear: maximum at 45°; the 10° grid (40°, 50°) gives sin 80° = 1 − 1.5 %."""
    phi = plane_angles()
    assert np.rad2deg(phi[1]) == pytest.approx(10.0) and phi.size == 18
    assert normal_stress(0.0, 1.0, phi).max() == pytest.approx(np.cos(np.deg2rad(10)))


def test_weights_reproduce_the_plane_stresses_of_each_point():
    sec = CircularSection(0.004, 0.001, 0.3)
    g, phi = surface_angles(12), plane_angles(15)
    w = plane_weights(sec, g, phi)
    assert w.shape == (12 * 12, 6)
    loads = np.random.default_rng(2).normal(size=(300, 6)) * [5, 5, 50, 0.2, 0.2, 0.1]
    series = section_series(loads, w)  # (n_series, T), one matrix product
    assert series.shape == (144, 300) and series.flags.c_contiguous
    sigma, tau = sec.surface_unit_stress(g)
    s, t = loads @ sigma.T, loads @ tau.T  # (T, n_pts)
    ref = normal_stress(s[:, :, None], t[:, :, None], phi[None, None, :])  # (T, pts, planes)
    np.testing.assert_allclose(series, ref.reshape(300, -1).T, rtol=1e-12, atol=1e-6)


@pytest.mark.parametrize("step", [0.0, -5.0, 7.0, 100.0, float("nan")])
def test_bad_plane_step(step):
    with pytest.raises(ValueError, match="plane step"):
        plane_angles(step)


def test_section_series_checks_shape():
    with pytest.raises(ValueError, match="must be \\(T, 6\\)"):
        section_series(np.zeros((10, 5)), np.zeros((4, 6)))
