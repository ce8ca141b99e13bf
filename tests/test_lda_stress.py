"""Saint-Venant unit-load stress fields of the circle and the tube (cablelife.lda.stress)."""

import math

import numpy as np
import pytest
from cablelife.lda import CircularSection, surface_angles

SECTIONS = [
    CircularSection(0.004, 0.0, 0.3),
    CircularSection(0.004, 0.0, 0.45),
    CircularSection(0.005, 0.003, 0.3),
    CircularSection(0.005, 0.0045, 0.2),
]


def polar_grid(sec, n_r=24, n_t=64):
    """Gauss–Legendre in r on [b, a] × uniform θ (exact for trigonometric polynomials of
    degree < n_t; the fields are smooth in r on [b, a], so 24 nodes reach round-off)."""
    x, w = np.polynomial.legendre.leggauss(n_r)
    a, b = sec.outer_radius, sec.inner_radius
    r = 0.5 * (a - b) * x + 0.5 * (a + b)
    wr = 0.5 * (a - b) * w * r  # dA = r dr dθ
    t = 2 * np.pi * np.arange(n_t) / n_t
    rr, tt = np.meshgrid(r, t, indexing="ij")
    wa = wr[:, None] * np.full(n_t, 2 * np.pi / n_t)[None, :]
    return rr * np.cos(tt), rr * np.sin(tt), wa


@pytest.mark.parametrize("sec", SECTIONS)
def test_fields_integrate_back_to_the_unit_loads(sec):
    """Resultants of the six unit-load fields (F1, F2, F3, M1, M2, M3) = identity:
    V_y = ∫τ_xy, V_z = ∫τ_xz, N = ∫σ, M_y = ∫zσ, M_z = −∫yσ, T = ∫(yτ_xz − zτ_xy)."""
    y, z, w = polar_grid(sec)
    s = sec.interior_stress(y, z)  # (..., 6, 3)
    sig, txy, txz = s[..., 0], s[..., 1], s[..., 2]
    ws = w[..., None]
    res = np.stack(
        [
            (txy * ws).sum(axis=(0, 1)),
            (txz * ws).sum(axis=(0, 1)),
            (sig * ws).sum(axis=(0, 1)),
            (z[..., None] * sig * ws).sum(axis=(0, 1)),
            (-y[..., None] * sig * ws).sum(axis=(0, 1)),
            ((y[..., None] * txz - z[..., None] * txy) * ws).sum(axis=(0, 1)),
        ]
    )
    np.testing.assert_allclose(res, np.eye(6), atol=1e-11)


@pytest.mark.parametrize("sec", SECTIONS)
def test_shear_fields_are_the_saint_venant_flexure_solution(sec):
    """The transverse-shear fields satisfy equilibrium with the bending stress gradient
    (div τ = −V y/I), the compatibility condition of Saint-Venant flexure
    (∂τ_xy/∂z − ∂τ_xz/∂y = ν/(1+ν) V z/I, no twist) and are traction-free on r = a and r = b
    (checked by central differences, h = 1e-5 a: truncation ~1e-10 relative)."""
    a, b, nu, inertia = sec.outer_radius, sec.inner_radius, sec.poisson_ratio, sec.inertia
    rng = np.random.default_rng(0)
    r = rng.uniform(b + 0.05 * (a - b), a, 50)
    t = rng.uniform(0, 2 * np.pi, 50)
    y, z = r * np.cos(t), r * np.sin(t)
    h = 1e-5 * a

    def f(yy, zz):
        return sec.interior_stress(yy, zz)

    d_dy = (f(y + h, z) - f(y - h, z)) / (2 * h)
    d_dz = (f(y, z + h) - f(y, z - h)) / (2 * h)
    scale = a / inertia
    # load 0: V_y = 1; load 1: V_z = 1
    div_y = d_dy[:, 0, 1] + d_dz[:, 0, 2]
    div_z = d_dy[:, 1, 1] + d_dz[:, 1, 2]
    np.testing.assert_allclose(div_y, -y / inertia, atol=1e-7 * scale)
    np.testing.assert_allclose(div_z, -z / inertia, atol=1e-7 * scale)
    curl_y = d_dz[:, 0, 1] - d_dy[:, 0, 2]
    curl_z = d_dz[:, 1, 1] - d_dy[:, 1, 2]
    np.testing.assert_allclose(curl_y, nu / (1 + nu) * z / inertia, atol=1e-7 * scale)
    np.testing.assert_allclose(curl_z, -nu / (1 + nu) * y / inertia, atol=1e-7 * scale)
    for radius in (a, b) if b > 0 else (a,):
        s = sec.interior_stress(radius * np.cos(t), radius * np.sin(t))
        traction = s[..., 1] * np.cos(t)[:, None] + s[..., 2] * np.sin(t)[:, None]
        np.testing.assert_allclose(traction, 0.0, atol=1e-9 / sec.area)


@pytest.mark.parametrize("sec", SECTIONS)
def test_surface_formulas_equal_the_interior_fields_at_the_surface(sec):
    g = surface_angles(16)
    a = sec.outer_radius
    s = sec.interior_stress(a * np.cos(g), a * np.sin(g))
    sigma, tau = sec.surface_unit_stress(g)
    tau_xt = -s[..., 1] * np.sin(g)[:, None] + s[..., 2] * np.cos(g)[:, None]
    np.testing.assert_allclose(sigma, s[..., 0], rtol=1e-12, atol=1e-12 * np.abs(sigma).max())
    np.testing.assert_allclose(tau, tau_xt, rtol=1e-12, atol=1e-12 * np.abs(tau).max())


def test_shear_factor_limits():
    """κ = (1+2ν)/(1+ν) for the circle: 1.231 at ν = 0.3, the elementary 4/3 at ν = 0.5;
    a thin tube tends to 2 (thin-walled shear flow V/(πRt) = 2V/A)."""
    assert CircularSection(1.0, 0.0, 0.3).shear_factor == pytest.approx(1.6 / 1.3)
    assert CircularSection(1.0, 0.0, 0.5).shear_factor == pytest.approx(4 / 3)
    assert CircularSection(1.0, 0.999, 0.3).shear_factor == pytest.approx(2.0, rel=1e-3)


@pytest.mark.parametrize("sec", [SECTIONS[0], SECTIONS[2]])
def test_textbook_surface_stresses(sec):
    """Pure tension N/A; bending M a/I with the maximum on the tension side; torsion T a/J."""
    a, b = sec.outer_radius, sec.inner_radius
    area = math.pi * (a**2 - b**2)
    inertia = math.pi * (a**4 - b**4) / 4
    g = surface_angles(16)
    sigma, tau = sec.surface_unit_stress(g)
    n, m, t = 100.0, 0.5, 0.2  # N, N m, N m

    def stresses(loads):
        return sigma @ loads, tau @ loads

    s, ta = stresses(np.array([0, 0, n, 0, 0, 0.0]))
    np.testing.assert_allclose(s, n / area)
    np.testing.assert_allclose(ta, 0.0)
    # M1 = M_y about d1: tension at z = +a (γ = 90°), compression at γ = 270°
    s, ta = stresses(np.array([0, 0, 0, m, 0, 0.0]))
    assert s.max() == pytest.approx(m * a / inertia) and g[s.argmax()] == pytest.approx(np.pi / 2)
    assert s.min() == pytest.approx(-m * a / inertia)
    # M2 = M_z about d2: tension at y = −a (γ = 180°)
    s, _ = stresses(np.array([0, 0, 0, 0, m, 0.0]))
    assert g[s.argmax()] == pytest.approx(np.pi)
    if b == 0:
        assert s.max() == pytest.approx(4 * m / (math.pi * a**3))
    s, ta = stresses(np.array([0, 0, 0, 0, 0, t]))
    np.testing.assert_allclose(s, 0.0)
    np.testing.assert_allclose(ta, t * a / (math.pi * (a**4 - b**4) / 2))
    if b == 0:
        np.testing.assert_allclose(ta, 2 * t / (math.pi * a**3))


def test_section_from_result_attributes_and_errors():
    sec = CircularSection.from_attrs(
        {"shape": "tube", "outer_radius": 0.005, "inner_radius": 0.003, "poisson_ratio": 0.35}
    )
    assert (sec.inner_radius, sec.poisson_ratio) == (0.003, 0.35)
    meas = CircularSection.from_attrs(
        {"shape": "circle", "outer_radius": 0.004, "poisson_ratio": 0.4, "from_measured": True}
    )
    assert meas.from_measured and meas.inner_radius == 0.0
    with pytest.raises(ValueError, match="inner_radius = 0.006"):
        CircularSection(0.005, 0.006)
    with pytest.raises(ValueError, match="outer_radius = -1"):
        CircularSection(-1.0)
    with pytest.raises(ValueError, match="poisson_ratio = 0.7"):
        CircularSection(1.0, 0.0, 0.7)
    with pytest.raises(ValueError, match="n_points = 0"):
        surface_angles(0)
