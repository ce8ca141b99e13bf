"""Modal analysis through the scene API: the banded Rust solver against the former dense one,
modes at the clip poses of t = 0, the mode types (the solver itself is tested against
analytical frequencies in crates/rod/tests/modal.rs)."""

from __future__ import annotations

import copy
from pathlib import Path

import numpy as np
import pytest
from cablelife.modal import cable_modes, cable_modes_dense
from cablelife.scene import load_scene, scene_from_dict

EXAMPLE = Path(__file__).parent.parent / "examples" / "hose-three-clips.toml"


def test_banded_solver_agrees_with_the_dense_one():
    # Three clips, gravity, a swivel (massless twist) and a held length: every kind of unknown.
    scene = load_scene(EXAMPLE)
    cable = scene.cables[0].model_copy(update={"segments": 30})
    banded = cable_modes(scene, cable, 8)
    dense = cable_modes_dense(scene, cable, 8)
    np.testing.assert_allclose(banded.omega, dense.omega, rtol=1e-7)
    np.testing.assert_allclose(banded.equilibrium, dense.equilibrium)
    # mass-normalised shapes agree up to sign where the frequency is simple
    gaps = np.diff(banded.omega)
    for i in range(8):
        near = [gaps[i - 1] if i > 0 else np.inf, gaps[i] if i < 7 else np.inf]
        if min(near) < 1e-3 * banded.omega[i]:
            continue
        a, b = banded.shapes[i].ravel(), dense.shapes[i].ravel()
        sign = np.sign(a @ b)
        np.testing.assert_allclose(a, sign * b, atol=1e-6 * np.abs(a).max())
    assert banded.shares.shape == (8, 4)
    np.testing.assert_allclose(banded.shares.sum(axis=1), 1.0)
    assert banded.rotations.shape == (8, 30, 3)


def test_modes_are_taken_at_the_clip_poses_of_t0(scene_dict):
    # The engine clip starts 5 cm away from its reference position (a sine with phase 90°):
    # the modes are those of the cable mounted there, not at the reference.
    moved = copy.deepcopy(scene_dict)
    scene_dict["bodies"] = [
        {
            "name": "engine",
            "origin": [0.8, 0.2, 0.0],
            "motion": [
                {
                    "channel": "x",
                    "signal": {
                        "type": "sine",
                        "amplitude": 0.05,
                        "frequency": 1.0,
                        "phase": np.pi / 2,
                    },
                }
            ],
        }
    ]
    scene_dict["cables"][0]["clips"][1]["body"] = "engine"
    moved["cables"][0]["clips"][1]["position"] = [0.85, 0.2, 0.0]
    reference = copy.deepcopy(scene_dict)
    reference["bodies"][0]["motion"] = []
    scene, moved, reference = map(scene_from_dict, (scene_dict, moved, reference))
    m = cable_modes(scene, scene.cables[0], 4)
    np.testing.assert_allclose(m.omega, cable_modes(moved, moved.cables[0], 4).omega, rtol=1e-9)
    np.testing.assert_allclose(m.equilibrium[-1], [0.85, 0.2, 0.0], atol=1e-12)
    ref = cable_modes(reference, reference.cables[0], 4)
    assert np.all(np.abs(m.omega / ref.omega - 1) > 1e-3)


def test_mode_types_of_a_straight_clamped_cable(scene_dict):
    # Straight between two clamps, no gravity: bending pairs (d1, d2) first; each mode is
    # almost all one type.
    scene_dict["simulation"]["gravity"] = [0.0, 0.0, 0.0]
    scene_dict["cables"][0]["clips"][1]["position"] = [1.0, 0.0, 0.0]
    scene = scene_from_dict(scene_dict)
    m = cable_modes(scene, scene.cables[0], 4)
    assert sorted(m.kind[:2]) == ["bending d1", "bending d2"]
    assert sorted(m.kind[2:4]) == ["bending d1", "bending d2"]
    assert np.all(m.shares.max(axis=1) > 0.99)


def test_modes_table_has_a_type_column(tmp_path):
    from cablelife.cli import app
    from typer.testing import CliRunner

    r = CliRunner().invoke(app, ["modes", str(EXAMPLE), "-n", "3"])
    assert r.exit_code == 0, r.output
    assert "type" in r.output and "bending" in r.output


@pytest.mark.parametrize("count", [0, -1])
def test_bad_count_is_an_error(count):
    from cablelife.scene import SceneError

    scene = load_scene(EXAMPLE)
    with pytest.raises(SceneError, match="count"):
        cable_modes(scene, scene.cables[0], count)


def _measured(scene_dict, **extra):
    cable = scene_dict["cables"][0]
    cable.pop("section")
    cable.pop("material")
    cable["stiffness"] = {
        "EA": 1e5,
        "GA": 1e5,
        "EI": 50.0,
        "GJ": 0.01,
        "mass_per_length": 0.2,
        "radius": 0.005,
        **extra,
    }
    scene_dict["simulation"]["gravity"] = [0.0, 0.0, 0.0]
    cable["clips"][1]["position"] = [1.0, 0.0, 0.0]
    return scene_from_dict(scene_dict)


def test_polar_rotary_inertia_sets_the_torsion_frequency(scene_dict):
    # Stiff in bending, soft in torsion: the lowest mode is torsion, ω = π/L √(GJ/ρI₃).
    plain = _measured(copy.deepcopy(scene_dict), rotary_inertia=1e-6)
    assert plain.cables[0].properties().rotary_inertia == (1e-6, 1e-6, 2e-6)
    scene = _measured(copy.deepcopy(scene_dict), rotary_inertia=1e-6, polar_rotary_inertia=8e-6)
    assert scene.cables[0].properties().rotary_inertia == (1e-6, 1e-6, 8e-6)
    for sc, j3 in ((plain, 2e-6), (scene, 8e-6)):
        m = cable_modes(sc, sc.cables[0], 1)
        assert m.kind[0] == "torsion"
        exact = np.pi * np.sqrt(0.01 / j3)
        assert abs(m.omega[0] / exact - 1) < (np.pi / 40) ** 2  # 40 segments, O(h²)


@pytest.mark.parametrize("value", [0.0, -1e-6, "big"])
def test_bad_polar_rotary_inertia_is_named(scene_dict, value):
    from cablelife.scene import SceneError

    with pytest.raises(SceneError, match="polar_rotary_inertia"):
        _measured(scene_dict, polar_rotary_inertia=value)


def test_default_damping_is_critical_on_bending_and_material_like_elsewhere(scene_dict):
    from cablelife.modal import DEFAULT_LOSS_FACTOR, lowest_frequencies, retardation_times

    scene = scene_from_dict(scene_dict)
    cable = scene.cables[0]
    shear, bend, info = retardation_times(scene, cable)
    tau = bend[0]
    assert bend[1] == tau
    # critical on mode 1 by its Rayleigh quotient (the other parts add < 1e-6 here); the
    # sagging hose's mode 1 is stiffened by gravity, so 2/ω₁ would damp it at ζ ≈ 2.2
    assert cable_modes(scene, cable, 1, damping=True).damping_ratio[0] == pytest.approx(1, 1e-6)
    assert 2.0 / info["omega1"] > 2 * tau
    p = cable.properties()
    w_ax = np.pi / 1.0 * np.sqrt(p.shear_stiffness[2] / p.mass_per_length)  # span 1 m
    w = lowest_frequencies(cable)
    assert w["extension"] == pytest.approx(w_ax)
    assert shear[2] == pytest.approx(DEFAULT_LOSS_FACTOR / w_ax)
    assert shear[0] == pytest.approx(DEFAULT_LOSS_FACTOR / w["shear"])
    assert bend[2] == pytest.approx(DEFAULT_LOSS_FACTOR / w["torsion"])
    assert max(shear + [bend[2]]) < 0.01 * tau
    # a given retardation time still applies to every mode
    scene_dict["cables"][0]["damping"] = {"retardation_time": 0.01}
    scene = scene_from_dict(scene_dict)
    shear, bend, _ = retardation_times(scene, scene.cables[0])
    assert shear + bend == [0.01] * 6


def _step_start(scene_dict, damping=None):
    scene_dict["simulation"].update(mode="dynamic", duration=0.1, time_step=0.001)
    scene_dict["bodies"] = [
        {
            "name": "engine",
            "origin": [0.8, 0.2, 0.0],
            "motion": [
                {"channel": "x", "signal": {"type": "sine", "amplitude": 0.024, "frequency": 2.0}}
            ],
        }
    ]
    cable = scene_dict["cables"][0]
    cable["segments"] = 20
    cable["clips"][1]["body"] = "engine"
    if damping:
        cable["damping"] = damping
    return scene_from_dict(scene_dict)


def test_summary_reports_and_warns_about_the_viscous_share(scene_dict, capsys):
    import warnings

    from cablelife.cli import print_summary
    from cablelife.simulate import simulate
    from cablelife.summary import VISCOUS_SHARE_WARNING, cable_summary

    # A clip starting at 0.3 m/s: τ = 2/ω₁ on every mode (the former default) makes the
    # viscous forces most of the start-up loads; the default keeps the tension an order lower.
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        new = simulate(_step_start(copy.deepcopy(scene_dict)))
        w1 = cable_modes(scene_from_dict(scene_dict), scene_from_dict(scene_dict).cables[0], 1)
        old = simulate(_step_start(scene_dict, {"retardation_time": 2 / w1.omega[0]}))
    s_new, s_old = cable_summary(new.cable), cable_summary(old.cable)
    assert s_old["viscous_share"].max() > VISCOUS_SHARE_WARNING
    assert s_new["max_tension"] < 0.1 * s_old["max_tension"]
    assert s_new["max_shear"] < 0.1 * s_old["max_shear"]
    print_summary(old)
    out = capsys.readouterr().out
    assert "viscous share" in out and "warning" in out and "damping" in out
    assert static_share_is_none(scene_dict)


def static_share_is_none(scene_dict) -> bool:
    from cablelife.simulate import simulate
    from cablelife.summary import cable_summary

    scene_dict["simulation"]["mode"] = "static"
    scene_dict.pop("bodies", None)
    scene_dict["cables"][0]["clips"][1].pop("body", None)
    return cable_summary(simulate(scene_from_dict(scene_dict)).cable)["viscous_share"] is None


def test_modal_damping_ratios_of_a_kelvin_voigt_cable(scene_dict):
    # Straight between two clamps, unstressed: each mode strains one kind only, so the damping
    # matrix is diagonal in the modes and mode k is damped by exactly ζ = τ ω_k / 2 with the τ
    # of its kind (the Rayleigh quotient φᵀCφ / (2ω φᵀMφ), crates/rod/src/modal.rs).
    scene_dict["simulation"]["gravity"] = [0.0, 0.0, 0.0]
    scene_dict["cables"][0]["clips"][1]["position"] = [1.0, 0.0, 0.0]
    tau = {"bending": 2e-3, "shear": 2e-3, "torsion": 5e-4, "extension": 1e-4}
    scene_dict["cables"][0]["damping"] = dict(tau)
    scene = scene_from_dict(scene_dict)
    m = cable_modes(scene, scene.cables[0], 24, damping=True)
    of_kind = {"bending d1": "bending", "bending d2": "bending", "axial": "extension"}
    kinds = {of_kind.get(k, k) for k in m.kind}
    assert kinds == {"bending", "torsion", "extension"}
    for w, kind, zeta in zip(m.omega, m.kind, m.damping_ratio, strict=True):
        t = tau[of_kind.get(kind, kind)]
        assert zeta == pytest.approx(0.5 * t * w, rel=1e-8), kind
    assert cable_modes(scene, scene.cables[0], 2).damping_ratio is None
