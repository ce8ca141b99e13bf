"""Dynamics and modal analysis through the scene API (the integrator itself is tested in
crates/rod/tests/dynamics.rs against Euler–Bernoulli, energy, order and decrement)."""

from __future__ import annotations

import copy
import math
import warnings

import numpy as np
import pytest
from cablelife.modal import cable_modes, retardation_times
from cablelife.scene import SceneError, scene_from_dict
from cablelife.simulate import simulate
from decay import free_decay

BETA_L = [1.875104, 4.694091, 7.854757]


def cantilever(scene_dict, segments=50):
    cable = scene_dict["cables"][0]
    cable["segments"] = segments
    cable["clips"] = cable["clips"][:1]
    scene_dict["simulation"]["gravity"] = [0.0, 0.0, 0.0]
    return scene_dict


def test_cantilever_bending_frequencies_match_euler_bernoulli(scene_dict):
    # Slender (L/r = 200): shear and rotary inertia change the first three modes by < 0.1 %;
    # the discretisation error at N = 50 is O((β_n/N)²) < 1 %.
    scene = scene_from_dict(cantilever(scene_dict))
    modes = cable_modes(scene, scene.cables[0], count=6)
    p = scene.cables[0].properties()
    ei, mass = p.EI1, p.mass_per_length
    exact = np.array([b**2 * math.sqrt(ei / mass) for b in BETA_L])  # L = 1
    # A round cable bends alike in both planes: each frequency appears twice.
    found = modes.omega[[0, 2, 4]]
    np.testing.assert_allclose(modes.omega[[1, 3, 5]], found, rtol=1e-6)
    np.testing.assert_allclose(found, exact, rtol=0.01)
    # Mode shapes: mass-normalised displacements, zero at the clamp.
    assert np.allclose(modes.shapes[:, 0], 0.0)


def test_default_damping_is_critical_on_the_first_mode(scene_dict):
    scene = scene_from_dict(cantilever(scene_dict, segments=20))
    shear, bend, info = retardation_times(scene, scene.cables[0])
    assert info["source"] == "ratio" and info["ratio"] == 1.0
    # an unstressed cantilever's mode 1 is pure bending: ζ = τω₁/2 (shear energy < 1e-3)
    assert bend[0] == pytest.approx(2.0 / info["omega1"], rel=1e-3)
    modes = cable_modes(scene, scene.cables[0], 1, damping=True)
    assert modes.damping_ratio[0] == pytest.approx(1.0, rel=1e-6)
    scene_dict["cables"][0]["damping"] = {"retardation_time": 0.01, "torsion": 0.02}
    shear, bend, info = retardation_times(
        scene_from_dict(scene_dict),
        scene.cables[0].model_copy(
            update={"damping": scene_from_dict(scene_dict).cables[0].damping}
        ),
    )
    assert shear == [0.01, 0.01, 0.01] and bend == [0.01, 0.01, 0.02]


def test_set_damping_ratio_gives_the_logarithmic_decrement(scene_dict):
    # A short cantilever released by a tip-load removal is not expressible in a scene; instead
    # the clamp gives a short smooth kick and the free decay of mode 1 is measured at the tip.
    d = cantilever(scene_dict, segments=20)
    cable = d["cables"][0]
    cable["length"] = 0.3
    cable["damping"] = {"ratio": 0.05}
    d["bodies"] = [
        {
            "name": "shaker",
            "motion": [
                {
                    "channel": "z",
                    "signal": {
                        "type": "table",
                        "t": [0.0, 0.01, 0.02, 5.0],
                        "value": [0.0, 0.002, 0.0, 0.0],
                        "interpolation": "pchip",
                    },
                }
            ],
        }
    ]
    cable["clips"][0]["body"] = "shaker"
    d["simulation"].update(mode="dynamic", duration=1.2, time_step=0.001)
    scene = scene_from_dict(d)
    res = simulate(scene).cable
    zeta, period = free_decay(res.time, res.positions[:, -1, 2], after=0.05)
    assert zeta == pytest.approx(0.05, rel=0.1)
    assert 2 * math.pi / res.solver["omega1"] == pytest.approx(period, rel=0.03)


def test_slow_excitation_gives_the_quasistatic_result(scene_dict):
    # A clip moved at 0.1 Hz, far below the first mode: inertia and damping forces are
    # negligible, so dynamic and quasistatic loads agree within 1 % of their range.
    d = scene_dict
    d["bodies"] = [
        {
            "name": "engine",
            "origin": [0.8, 0.2, 0.0],
            "motion": [
                {
                    "channel": "z",
                    "signal": {"type": "sine", "amplitude": 0.05, "frequency": 0.1, "fade_in": 2.0},
                }
            ],
        }
    ]
    d["cables"][0]["clips"][1]["body"] = "engine"
    d["cables"][0]["segments"] = 20
    d["cables"][0]["damping"] = {"ratio": 0.1}
    d["simulation"].update(duration=5.0, time_step=0.002, output_step=0.1)
    scene = scene_from_dict(d)
    dyn = simulate(scene, mode="dynamic").cable
    qs = simulate(scene, mode="quasistatic").cable
    assert dyn.time.shape == qs.time.shape
    span = np.ptp(qs.moments[..., :2])
    assert np.abs(dyn.moments[..., :2] - qs.moments[..., :2]).max() < 0.01 * span
    np.testing.assert_allclose(dyn.positions, qs.positions, atol=0.01 * 0.05)
    assert "kinetic_energy" in dyn.energies and dyn.solver["real_time_factor"] > 0


def test_a_moving_start_warns_and_a_faded_one_does_not(scene_dict):
    from cablelife.simulate import StartUpWarning

    psd = {
        "type": "psd",
        "quantity": "displacement",
        "breakpoints": [[5, 1e-7], [50, 1e-7]],
        "seed": 3,
    }
    d = copy.deepcopy(scene_dict)
    d["simulation"].update(mode="dynamic", duration=0.3, time_step=1e-3)
    d["bodies"] = [{"name": "shaker", "motion": [{"channel": "z", "signal": psd}]}]
    d["cables"][0]["clips"][0]["body"] = "shaker"
    with pytest.warns(StartUpWarning, match="starts with .* m/s") as seen:
        simulate(scene_from_dict(d))
    # where the warning points: the caller of simulate(), not the thread pool's internals
    # (the cables run in threads; their warnings are given again by simulate itself)
    places = {w.filename for w in seen if issubclass(w.category, StartUpWarning)}
    assert places == {__file__}, places
    psd["fade_in"] = 0.1
    with warnings.catch_warnings():
        warnings.simplefilter("error", StartUpWarning)
        res = simulate(scene_from_dict(d))
    assert res.complete
    # a static run of the same scene takes the pose at t = 0 (no signal on a 2-sample grid)
    static = simulate(scene_from_dict(d), mode="static")
    assert static.cable.n_steps == 1


def test_newton_tolerance_is_settable_and_bounds_the_iteration_error(scene_dict):
    # A clip shaken at 60 Hz (1 mm): the default tolerance (the estimated remaining error
    # below 0.02 of the local time-error estimate) leaves moment histories within 0.1 % rms
    # of a run converged to 1e-8, at fewer iterations; the tolerance reaches the solver and
    # is validated.
    d = scene_dict
    d["bodies"] = [
        {
            "name": "engine",
            "origin": [0.8, 0.2, 0.0],
            "motion": [
                {
                    "channel": "z",
                    "signal": {
                        "type": "sine",
                        "amplitude": 1e-3,
                        "frequency": 60.0,
                        "fade_in": 0.05,
                    },
                }
            ],
        }
    ]
    d["cables"][0]["clips"][1]["body"] = "engine"
    d["cables"][0]["segments"] = 30
    d["cables"][0]["damping"] = {"ratio": 0.2}
    d["simulation"].update(mode="dynamic", duration=0.3, time_step=1e-3)
    default = simulate(scene_from_dict(d)).cable
    d["simulation"]["newton_tolerance"] = 1e-8
    tight = simulate(scene_from_dict(d)).cable
    from cablelife._core import DEFAULT_NEWTON_TOLERANCE

    assert default.solver["newton_tolerance"] == DEFAULT_NEWTON_TOLERANCE == 0.02
    assert tight.solver["newton_tolerance"] == 1e-8
    assert tight.solver["iterations"].sum() > 1.3 * default.solver["iterations"].sum()
    m, m_ref = default.moments, tight.moments
    assert np.sqrt(np.mean((m - m_ref) ** 2)) < 1e-3 * np.sqrt(np.mean(m_ref**2))
    assert np.abs(m - m_ref).max() > 0  # not the same run
    d["simulation"]["newton_tolerance"] = 0.0
    with pytest.raises(Exception, match="newton_tolerance"):
        scene_from_dict(d)


def test_set_damping_ratio_holds_on_a_sagging_hose(scene_dict):
    # A slack hose sagging under gravity: its first mode (a swing) is stiffened by gravity, not
    # only by bending, so τ = 2ζ/ω₁ on bending would damp it at 2.2 ζ. The default is calibrated
    # on the mode's Rayleigh quotient; the free decay after a short sideways kick of one clip
    # shows the set ζ (logarithmic decrement over three periods, after the kick's transients).
    cable = scene_dict["cables"][0]
    cable["segments"] = 20
    cable["damping"] = {"ratio": 0.05}
    kick = {"type": "table", "t": [0.0, 0.05, 0.1, 10.0], "value": [0.0, 0.01, 0.0, 0.0],
            "interpolation": "pchip"}  # fmt: skip
    scene_dict["bodies"] = [{"name": "shaker", "motion": [{"channel": "y", "signal": kick}]}]
    cable["clips"][0]["body"] = "shaker"
    scene_dict["simulation"].update(mode="dynamic", duration=4.0, time_step=0.001)
    scene = scene_from_dict(scene_dict)
    _, bend, info = retardation_times(scene, scene.cables[0])
    assert bend[0] * info["omega1"] / 2 < 0.5 * 0.05  # the uncalibrated τ would be > 2× ζ
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the kick starts abruptly (a start-up warning)
        res = simulate(scene).cable
    chord = np.array([-0.2, 0.8, 0.0]) / np.hypot(0.2, 0.8)  # horizontal, across the chord
    y = (res.positions[:, 10] - res.positions[0, 10]) @ chord
    zeta, period = free_decay(res.time, y, after=1.0)
    assert zeta == pytest.approx(0.05, rel=0.1)
    assert 2 * math.pi / info["omega1"] == pytest.approx(period, rel=0.03)


def test_default_damping_is_held_for_a_first_mode_hardly_bending(scene_dict):
    # A hose hanging in a U from two clips pointing down and up 0.1 m apart: its first mode is a
    # swing that gravity stiffens (74 % of its stiffness is bending). The τ that damps it at ζ
    # would over-damp every bending mode above it; it is held at 2ζ/(ω₁ · MIN_BENDING_SHARE),
    # the mode gets ζ · share / MIN_BENDING_SHARE from bending, and the run says so.
    from cablelife.hints import run_hints
    from cablelife.modal import MIN_BENDING_SHARE, bending_damping_of_mode1

    cable = scene_dict["cables"][0]
    cable["damping"] = {"ratio": 0.2}
    a, b = cable["clips"]
    a.update(direction=[0.0, 0.0, -1.0], normal=[1.0, 0.0, 0.0])
    b.update(position=[0.1, 0.0, 0.0], direction=[0.0, 0.0, 1.0], normal=[1.0, 0.0, 0.0])
    scene = scene_from_dict(scene_dict)
    omega1, per_tau = bending_damping_of_mode1(scene, scene.cables[0])
    share = 2 * per_tau / omega1
    assert 0.5 < share < MIN_BENDING_SHARE
    _, bend, info = retardation_times(scene, scene.cables[0])
    assert bend[0] == pytest.approx(2 * 0.2 / (omega1 * MIN_BENDING_SHARE), rel=1e-12)
    assert bend[0] < 0.2 / per_tau  # the unheld calibration would damp more
    assert info["bending_share"] == pytest.approx(share, rel=1e-12)
    scene_dict["simulation"].update(mode="dynamic", duration=0.01, time_step=0.001)
    scene = scene_from_dict(scene_dict)
    hints = run_hints(scene, simulate(scene))
    assert any(f"only {100 * share:.0f} % bending" in h for h in hints), hints


def test_a_clip_turning_faster_than_the_step_can_follow_is_a_scene_error(scene_dict):
    # A rotation amplitude given in degrees where radians are meant (30 → 30 rad at 20 Hz:
    # 3.8 rad per 1 ms step) fails with the clip, the turn and the allowed bound instead of a
    # Newton failure at the first step; the same amplitude in radians runs.
    d = copy.deepcopy(scene_dict)
    d["simulation"].update(mode="dynamic", duration=0.02, time_step=1e-3)
    sine = {"type": "sine", "amplitude": 30.0, "frequency": 20.0, "fade_in": 0.01}
    d["bodies"] = [
        {"name": "arm", "origin": [0.8, 0.2, 0.0], "motion": [{"channel": "rz", "signal": sine}]}
    ]
    d["cables"][0]["clips"][1]["body"] = "arm"
    with pytest.raises(
        SceneError,
        match=r"clip 'b' \(body 'arm'\): the body motion turns the clip by \d\.\d+ rad within "
        r"one time step .*allowed: at most 1 rad per step",
    ):
        simulate(scene_from_dict(d))
    sine["amplitude"] = 30.0 * np.pi / 180.0
    assert simulate(scene_from_dict(d)).complete
    # a harness run checks its clips too
    from test_harness import y_scene

    y = y_scene()
    y["simulation"] = {"mode": "dynamic", "duration": 0.02, "time_step": 1e-3}
    y["bodies"] = y.get("bodies", []) + d["bodies"]
    sine["amplitude"] = 30.0
    y["cables"][1]["clips"][-1]["body"] = "arm"
    with pytest.raises(SceneError, match=r"the body motion turns the clip by"):
        simulate(scene_from_dict(y))
