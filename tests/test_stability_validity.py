"""Mechanics you can trust: stable equilibria (buckled column against the elastica),
snap-through reporting, pre-tensioned mountings (EA·ε) and the strain validity range."""

from __future__ import annotations

import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest
from cablelife.scene import scene_from_dict
from cablelife.simulate import SimulationError, simulate
from cablelife.summary import cable_summary
from cablelife.validity import PrestrainWarning, StabilityWarning, StrainLimitWarning
from scipy.optimize import brentq
from scipy.special import ellipe, ellipk

EI = 0.02
STIFFNESS = {"EA": 1e5, "GA": 4e4, "EI": EI, "GJ": 0.015, "mass_per_length": 0.1, "radius": 0.005}
EULER = np.pi**2 * EI / 4  # clamped–free, L = 1 m


def column(load: float, imperfection: float, segments: int = 40, motion=None, mode="static"):
    """A 1 m clamped–free column along +x under the dead tip load (−P, 0, imperfection·P)."""
    return {
        "simulation": {"mode": mode, "gravity": [0, 0, 0], "duration": 1.0, "time_step": 0.01},
        "bodies": [{"name": "base", "origin": [0, 0, 0], "motion": motion or []}],
        "cables": [
            {
                "name": "column",
                "length": 1.0,
                "segments": segments,
                "stiffness": STIFFNESS,
                "clips": [
                    {
                        "name": "root",
                        "s": 0.0,
                        "body": "base",
                        "position": [0, 0, 0],
                        "direction": [1, 0, 0],
                        "normal": [0, 0, 1],
                    }
                ],
                "loads": [{"s": 1.0, "force": [-load, 0, imperfection * load]}],
            }
        ],
    }


def elastica_tip(load: float) -> tuple[float, float]:
    """Tip of the post-buckled clamped–free elastica (L = 1): K(k) = √(P/EI), the tip at
    2E/K − 1 along the load line and 2k/K across it."""
    m = brentq(lambda m: ellipk(m) - np.sqrt(load / EI), 0.0, 1.0 - 1e-15)
    return 2 * ellipe(m) / ellipk(m) - 1, 2 * np.sqrt(m) / ellipk(m)


def test_a_column_above_its_euler_load_is_solved_to_the_stable_buckled_elastica():
    load = 2 * EULER
    x_ref, y_ref = elastica_tip(load)
    errors = []
    for n in (20, 40):
        with warnings.catch_warnings():
            warnings.simplefilter("error")  # no unstable state is returned
            res = simulate(scene_from_dict(column(load, 1e-4, n))).cables["column"]
        assert res.solver["unstable"].tolist() == [0]
        x, y, z = res.positions[0, -1]
        assert z > 0, "buckles to the side of the imperfection"
        errors.append(np.hypot(x - x_ref, z - y_ref))
    # Second order in the edge length (the 1e-4 imperfection moves the tip by ~1e-4 m).
    assert 3.0 < errors[0] / errors[1] < 5.0, errors
    assert errors[1] < 3e-3, errors


def test_below_its_euler_load_the_column_stays_straight_and_stable():
    res = simulate(scene_from_dict(column(0.9 * EULER, 1e-4))).cables["column"]
    assert res.solver["unstable"].tolist() == [0]
    assert abs(res.positions[0, -1, 2]) < 1e-3


def test_a_snap_through_is_reported_with_time_and_place(tmp_path):
    # The buckled round column leans to +z; its clamp turns towards −z (ry) until the lean
    # flips (for a round section at once: the buckling plane is free to swing round).
    motion = [{"channel": "ry", "signal": {"type": "sine", "amplitude": 1.0, "frequency": 0.25}}]
    data = column(2 * EULER, 1e-3, 20, motion, mode="quasistatic")
    with pytest.warns(StabilityWarning, match=r"snap-through at t = .* s.* at s = 1\.000 m"):
        res = simulate(scene_from_dict(data)).cables["column"]
    assert (res.solver["unstable"] == 0).all()
    assert res.solver["snap_time"].size >= 1
    assert res.solver["snap_jump"][0] > 1.0  # the tip crosses over: ~2 × 0.8 m
    assert res.positions[0, -1, 2] > 0.5 and res.positions[-1, -1, 2] < -0.5
    snaps = cable_summary(res)["snap_throughs"]
    assert snaps and snaps[0]["s"] == 1.0


def two_clips(distance: float, gravity=(0.0, 0.0, 0.0), strain_limit="warn") -> dict:
    """A 1 m cable held straight along x by two fixed clips ``distance`` apart."""
    clip = {"direction": [1, 0, 0], "normal": [0, 0, 1]}
    return {
        "simulation": {"mode": "static", "gravity": list(gravity), "strain_limit": strain_limit},
        "cables": [
            {
                "name": "hose",
                "length": 1.0,
                "segments": 20,
                "stiffness": STIFFNESS,
                "clips": [
                    {"name": "a", "s": 0.0, "position": [0, 0, 0], **clip},
                    {"name": "b", "s": 1.0, "position": [distance, 0, 0], **clip},
                ],
            }
        ],
    }


def test_clips_farther_apart_than_the_cable_mount_it_stretched_with_tension_ea_eps():
    with pytest.warns(PrestrainWarning, match="'a' and 'b' is mounted stretched by 2 %"):
        res = simulate(scene_from_dict(two_clips(1.02))).cables["hose"]
    tension = res.forces[0, :, 2]
    assert np.allclose(tension, STIFFNESS["EA"] * 0.02, rtol=1e-9, atol=0)
    assert np.abs(res.forces[0, :, :2]).max() < 1e-9
    assert res.solver["prestrain"] == pytest.approx(0.02, rel=1e-12)
    assert cable_summary(res)["prestrain"] == pytest.approx(0.02, rel=1e-12)
    # Below the documented 1 %: no warning.
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        res = simulate(scene_from_dict(two_clips(1.005))).cables["hose"]
    assert np.allclose(res.forces[0, :, 2], STIFFNESS["EA"] * 0.005, rtol=1e-9, atol=0)


def test_over_stretch_warns_with_where_and_when_or_fails_when_asked():
    with pytest.warns(StrainLimitWarning, match=r"axial strain 36 % at s = .* m, t = 0 s"):
        res = simulate(scene_from_dict(two_clips(1.36, gravity=(0, 0, -9.81))))
    s = cable_summary(res.cables["hose"])
    assert s["max_axial_strain"]["value"] == pytest.approx(0.36, rel=1e-3)
    with pytest.raises(SimulationError, match="axial strain 36 %") as info:
        simulate(scene_from_dict(two_clips(1.36, strain_limit="error")))
    assert info.value.result.cables["hose"].n_steps == 1  # the computed result is kept
    # Inside the validity range: silent.
    with warnings.catch_warnings():
        warnings.simplefilter("error", StrainLimitWarning)
        simulate(scene_from_dict(two_clips(1.004)))


def test_the_cli_summary_shows_strains_and_pre_strain(tmp_path):
    import tomli_w

    path = tmp_path / "taut.toml"
    path.write_text(tomli_w.dumps(two_clips(1.36)))
    root = Path(__file__).resolve().parents[1]
    proc = subprocess.run(
        [sys.executable, "-m", "cablelife", "run", str(path), "-q"],
        capture_output=True,
        text=True,
        cwd=root,
    )
    assert proc.returncode == 0, proc.stderr
    assert "max axial strain Γ3" in proc.stdout and "36 %" in proc.stdout
    assert "span pre-strain" in proc.stdout
    assert "exceeds the model's validity range" in proc.stderr
    data = two_clips(1.36, strain_limit="error")
    path.write_text(tomli_w.dumps(data))
    proc = subprocess.run(
        [sys.executable, "-m", "cablelife", "run", str(path), "-q"],
        capture_output=True,
        text=True,
        cwd=root,
    )
    assert proc.returncode == 1 and "axial strain 36 %" in proc.stderr


def test_the_modes_of_a_taut_mounting_are_those_of_the_tensioned_string():
    from cablelife.modal import cable_modes

    sc = scene_from_dict(two_clips(1.02))
    modes = cable_modes(sc, sc.cables[0], 4)
    # The lowest transverse mode (a torsional one, at (1/2L)√(GJ/ρI_p) = 55 Hz, moves no node).
    transverse = np.abs(modes.shapes[..., 1:]).max(axis=(1, 2)) > 1e-3 * np.abs(modes.shapes).max()
    f1 = modes.frequencies[np.flatnonzero(transverse)[0]]
    tension, rho_a, eps = STIFFNESS["EA"] * 0.02, STIFFNESS["mass_per_length"], 0.02
    # String of the stretched length L(1+ε) with its mass ρA L: f = √(T(1+ε)/ρA) / (2L(1+ε)).
    # Bending stiffness at clamped ends raises it by at most 2/λ, λ = L√(T/EI) (0.6 %); the
    # lumped-mass discretisation (N = 20) lowers it by π²/(24N²) (0.1 %).
    string = np.sqrt(tension * (1 + eps) / rho_a) / (2 * (1 + eps))
    lam = np.sqrt(tension / EI)
    assert string * (1 - np.pi**2 / (24 * 20**2)) <= f1 <= string * (1 + 2 / lam), (f1, string)


def test_a_dynamic_run_starts_from_the_stable_buckled_state():
    data = column(2 * EULER, 1e-3, 20, mode="dynamic")
    data["simulation"].update(duration=0.01, time_step=1e-3)
    res = simulate(scene_from_dict(data)).cables["column"]
    assert res.solver["unstable"][0] == 0 and (res.solver["unstable"][1:] == -1).all()
    x_ref, y_ref = elastica_tip(2 * EULER)
    assert res.positions[0, -1, 2] == pytest.approx(y_ref, abs=0.02)
    # At rest in a stable equilibrium with the clips at rest: it stays there.
    assert np.abs(res.positions[-1] - res.positions[0]).max() < 1e-6


def test_strain_extremes_scan_equals_the_rotation_matrix_formula():
    """The one-pass scan of the strains (the Rust kernel, no rotation matrices formed, no
    strain arrays) finds the same extremes, values and places as Γ = Rᵀ(x_{n+1} − x_n)/Δs − e₃
    with R from the normalised quaternion and numpy's argmax, also late in the run and with
    quaternions that are not unit; a NaN is reported where argmax finds it."""
    from types import SimpleNamespace

    from cablelife.export.frames import rotation_matrices
    from cablelife.validity import strain_extremes

    rng = np.random.default_rng(3)
    t, n = 150, 30
    q = rng.normal(size=(t, n, 4)) * rng.uniform(0.5, 2.0, size=(t, n, 1))
    x = np.cumsum(rng.normal(size=(t, n + 1, 3)) * 0.01, axis=1)
    x[140, 20:] += [0.0, 0.0, 0.5]  # the largest stretch in the last block, at edge 19
    arc = np.cumsum(rng.uniform(0.5, 1.5, n + 1)) * 0.01
    c = SimpleNamespace(quaternions=q, positions=x, arc_length=arc, time=np.arange(t) * 1e-3)
    tangent = np.diff(x, axis=1) / np.diff(arc)[None, :, None]
    gamma = np.einsum("...ji,...j->...i", rotation_matrices(q), tangent)
    axial, shear = gamma[..., 2] - 1.0, np.hypot(gamma[..., 0], gamma[..., 1])
    ext = strain_extremes(c)
    cases = (("axial", axial, 1), ("compression", -axial, -1), ("shear", shear, 1))
    for key, values, sign in cases:
        k, e = np.unravel_index(int(np.argmax(values)), values.shape)
        assert ext[key]["value"] == pytest.approx(sign * values[k, e], rel=1e-12)
        assert ext[key]["t"] == c.time[k]
        assert ext[key]["s"] == pytest.approx(0.5 * (arc[e] + arc[e + 1]))
    # the set-up puts an extreme late in the run
    assert 140 in {int(np.argmax(v)) // n for v in (axial, shear)}
    # a NaN node (steps 90 and 120): every extreme is NaN, at the first NaN edge, as argmax
    x[[120, 90], 7] = np.nan
    ext = strain_extremes(c)
    for key in ("axial", "compression", "shear"):
        assert np.isnan(ext[key]["value"])
        assert ext[key]["t"] == c.time[90]
        assert ext[key]["s"] == pytest.approx(0.5 * (arc[6] + arc[7]))
