"""Hinged clips through the scene API: the pinned–supported beam, the hinge's reaction and
bad hinge input. (crates/rod/tests/hinge.rs covers convergence order, Jacobian and dynamics.)"""

from __future__ import annotations

import copy

import numpy as np
import pytest
from cablelife.scene import SceneError, scene_from_dict
from cablelife.simulate import simulate


def overhang(scene_dict, segments=80, normal=(0.0, 0.0, 1.0), axis=(0.0, 1.0, 0.0)):
    """A beam along x: a hinge at 0, a ball at a = 0.6, a tip load F = 1e-3 N down at 1 m."""
    scene_dict = copy.deepcopy(scene_dict)
    cable = scene_dict["cables"][0]
    del cable["section"], cable["material"]
    # Moderate EA: both supports hold positions, so the membrane tension of the deflected span
    # stays ~1e-5 N (1e-6 of the bending stiffness). GA = 1e5: the shear deflection is 1e-4
    # of the bending one (in the reference below) and the round-off of the shear forces
    # (GA · 1e-16 / h) stays ~1e-9 N.
    cable["stiffness"] = {
        "EA": 1e4,
        "GA": 1e5,
        "EI": 1.0,
        "GJ": 1.0,
        "mass_per_length": 0.1,
        "radius": 0.005,
    }
    cable["segments"] = segments
    cable["clips"] = [
        {
            "name": "hinge",
            "s": 0.0,
            "position": [0.0, 0.0, 0.0],
            "direction": [1.0, 0.0, 0.0],
            "normal": list(normal),
            "type": "hinge",
            "axis": list(axis),
        },
        {
            "name": "support",
            "s": 0.6,
            "position": [0.6, 0.0, 0.0],
            "direction": [1.0, 0.0, 0.0],
            "type": "ball",
        },
    ]
    cable["loads"] = [{"s": 1.0, "force": [0.0, 0.0, -1e-3]}]
    scene_dict["simulation"]["gravity"] = [0.0, 0.0, 0.0]
    return scene_dict


@pytest.mark.parametrize(
    "normal, axis",
    [((0.0, 0.0, 1.0), (0.0, 1.0, 0.0)), ((0.0, 1.0, 0.0), (-1.0, 0.0, 0.0))],
    ids=["axis-d2", "axis-d1"],
)
def test_hinged_overhang_matches_the_pinned_beam(scene_dict, normal, axis):
    # Both clip frames put the hinge axis along global ±y: the same pinned beam.
    # Tip deflection F b² L / (3EI) = 5.33e-5 m plus shear F b L / (a GA) (Castigliano);
    # N = 80: discretisation error 2e-4 (measured convergence in crates/rod/tests/hinge.rs).
    res = simulate(scene_from_dict(overhang(scene_dict, normal=normal, axis=axis))).cable
    f, a, b, length = 1e-3, 0.6, 0.4, 1.0
    exact = f * b * b * length / 3.0 + f * b * length / (a * 1e5)
    assert -res.positions[0, -1, 2] == pytest.approx(exact, rel=5e-4)
    # The hinge moment about the axis (global y) is zero; all reactions balance the load.
    hinge = res.clips["hinge"]
    assert abs(hinge.moment[0][1]) < 1e-12
    total = hinge.force[0] + res.clips["support"].force[0]
    # To the Newton tolerance: residual 1e-10 × the force scale EI/L² = 1 N.
    np.testing.assert_allclose(total, [0.0, 0.0, f], rtol=0, atol=1e-10)
    assert hinge.force[0][2] == pytest.approx(-f * b / a, rel=1e-6)


def test_hinge_takes_the_moment_across_its_axis(scene_dict):
    # A hinge about the global z axis under a vertical tip load: it holds the bending moment
    # about y (a clamp in that plane, with the ball a propped cantilever); the moments of the
    # reactions and the load about the hinge sum to zero.
    d = overhang(scene_dict, axis=(1.0, 0.0, 0.0))  # d1 = global z
    res = simulate(scene_from_dict(d)).cable
    hinge, support = res.clips["hinge"], res.clips["support"]
    assert abs(hinge.moment[0][2]) < 1e-12  # none about the axis
    assert abs(hinge.moment[0][1]) > 1e-5  # the constraint moment across it
    total = hinge.moment[0] + np.cross([0.6, 0.0, 0.0], support.force[0])
    total += np.cross(res.positions[0, -1], [0.0, 0.0, -1e-3])
    np.testing.assert_allclose(total, 0.0, atol=1e-10)  # Newton tolerance (N · 1 m)


def error_of(data) -> str:
    with pytest.raises(SceneError) as info:
        simulate(scene_from_dict(data))
    return str(info.value)


def test_hinge_without_an_axis(scene_dict):
    d = overhang(scene_dict)
    del d["cables"][0]["clips"][0]["axis"]
    msg = error_of(d)
    assert "clips[0]" in msg and "needs its axis" in msg


def test_axis_on_a_clip_that_is_no_hinge(scene_dict):
    d = overhang(scene_dict)
    d["cables"][0]["clips"][0]["type"] = "fixed"
    msg = error_of(d)
    assert "clips[0]" in msg and "axis = [0.0, 1.0, 0.0]" in msg and "only a hinge" in msg


def test_hinge_with_a_length_or_a_zero_axis(scene_dict):
    d = overhang(scene_dict)
    d["cables"][0]["clips"][0].update(length=0.02, s=0.01)
    assert "hinge clip holds a point" in error_of(d)
    d = overhang(scene_dict)
    d["cables"][0]["clips"][0]["axis"] = [0.0, 0.0, 0.0]
    msg = error_of(d)
    assert "clips[0]" in msg and "axis must not be the zero vector" in msg


def hanging(scene_dict, segments=50):
    """A soft cable (EA = 50 N, 0.1 kg/m) from a clamp 0.5 m up through a 0.1 m guide."""
    d = copy.deepcopy(scene_dict)
    cable = d["cables"][0]
    del cable["section"], cable["material"]
    cable["stiffness"] = {
        "EA": 50.0,
        "GA": 50.0,
        "EI": 1e-3,
        "GJ": 1e-3,
        "mass_per_length": 0.1,
        "radius": 0.005,
    }
    cable["segments"] = segments
    down = [0.0, 0.0, -1.0]
    cable["clips"] = [
        {
            "name": "top",
            "s": 0.0,
            "body": "lift",
            "position": [0.0, 0.0, 0.5],
            "direction": down,
            "normal": [1.0, 0.0, 0.0],
        },
        {
            "name": "guide",
            "s": 0.5,
            "position": [0.0, 0.0, 0.0],
            "direction": down,
            "type": "sliding",
            "length": 0.1,
        },
    ]
    d["bodies"] = [{"name": "lift", "origin": [0.0, 0.0, 0.5]}]
    return d


def sigma_exact(h, w=0.981, ea=50.0, length=1.0):
    """Material coordinate at the guide with the clamp h above it (stretch under own weight)."""
    c = w / ea
    a, b = 0.5 * c, -(1.0 + c * length)
    return (-b - np.sqrt(b * b - 4 * a * h)) / (2 * a)


def test_sliding_clip_slides_to_the_stretch_and_passes_the_tension(scene_dict, tmp_path):
    from cablelife.results import load_result

    result = simulate(scene_from_dict(hanging(scene_dict)))
    res = result.cable
    guide = res.clips["guide"]
    assert guide.slid_length[0] == pytest.approx(sigma_exact(0.5) - 0.5, abs=1e-6)
    assert res.clips["top"].slid_length is None
    np.testing.assert_allclose(guide.force[0], 0.0, atol=1e-9)  # frictionless, no side load
    path = tmp_path / "r.h5"
    result.save(path)
    back = load_result(path).cable.clips["guide"]
    np.testing.assert_allclose(back.slid_length, guide.slid_length)


def test_cable_pulled_out_of_a_sliding_clip_is_a_clear_error(scene_dict):
    from cablelife.simulate import SimulationError

    d = hanging(scene_dict)
    d["simulation"].update(mode="quasistatic", duration=1.0, time_step=0.1)
    d["bodies"][0]["motion"] = [
        {"channel": "z", "signal": {"type": "table", "t": [0.0, 1.0], "value": [0.0, 0.8]}}
    ]
    with pytest.raises(SimulationError) as info:
        simulate(scene_from_dict(d))
    msg = str(info.value)
    assert "'guide'" in msg and "'hose'" in msg and "ran out of sliding clip" in msg
    assert "step 6 (t = 0.6 s)" in msg  # lift 0.48 m: σ + 0.05 > L
    res = info.value.result.cable
    assert res.n_steps >= 5  # kept up to there; the slid length grows with the lift
    slid = res.clips["guide"].slid_length
    assert np.all(np.diff(slid) > 0)


def test_bad_sliding_clips(scene_dict):
    d = hanging(scene_dict)
    d["cables"][0]["clips"][1]["length"] = 0.0
    assert "give length > 0" in error_of(d)
    d = hanging(scene_dict)
    d["cables"][0]["clips"][0]["friction"] = 0.3
    msg = error_of(d)
    assert "clips[0]" in msg and "friction = 0.3" in msg and "only a sliding clip" in msg
    d = hanging(scene_dict)
    d["cables"][0]["clips"][1]["friction"] = -0.1
    assert "clips[1].friction" in error_of(d)
    d = hanging(scene_dict, segments=10)
    msg = error_of(d)
    assert "'guide'" in msg and "at least three nodes" in msg


def test_friction_in_a_sliding_clip_adds_mu_n_to_the_pull(scene_dict):
    # Lifting the clamp drags the cable up through the guide against a side pull at its end:
    # the clamp pulls the weight plus the Coulomb force μ Σ N of the guide (the guide's
    # friction on the cable, along its line, is the axial part of its reaction).
    d = hanging(scene_dict)
    d["cables"][0]["loads"] = [{"s": 1.0, "force": [0.3, 0.0, 0.0]}]
    d["simulation"].update(mode="quasistatic", duration=1.0, time_step=0.25)
    d["bodies"][0]["motion"] = [
        {"channel": "z", "signal": {"type": "table", "t": [0.0, 1.0], "value": [0.0, 0.1]}}
    ]
    pulls = {}
    for mu in (0.0, 0.3):
        d["cables"][0]["clips"][1]["friction"] = mu
        res = simulate(scene_from_dict(d)).cable
        pulls[mu] = res.clips["top"].force[1:, 2]
        friction = -res.clips["guide"].force[1:, 2]  # down (+t), against the lift
        assert np.all(friction >= 0)
        if mu == 0.0:
            np.testing.assert_allclose(friction, 0.0, atol=1e-8)
    weight = 0.1 * 9.81 * 1.0
    np.testing.assert_allclose(pulls[0.0], weight, rtol=1e-8)
    assert np.all(pulls[0.3] > weight + 0.05)


def guided_hose(scene_dict, mu: float, time_step: float) -> dict:
    """The two-clip hose through a frictional guide on its static shape at mid-length, its
    far clip on an engine shaken 10 mm at 5 Hz (faded in over 0.1 s), 0.3 s dynamic."""
    d = copy.deepcopy(scene_dict)
    d["simulation"].update(mode="dynamic", duration=0.3, time_step=time_step)
    sine = {"type": "sine", "amplitude": 0.01, "frequency": 5.0, "fade_in": 0.1}
    d["bodies"] = [
        {"name": "engine", "origin": [0.8, 0.2, 0.0], "motion": [{"channel": "z", "signal": sine}]}
    ]
    clips = d["cables"][0]["clips"]
    clips[1]["body"] = "engine"
    guide = {
        "name": "guide",
        "type": "sliding",
        "s": 0.5,
        "length": 0.08,
        "position": [0.4, 0.1, -0.24556242],
        "direction": [0.04497234, 0.02162714, 0.0],
        "friction": mu,
    }
    clips.insert(1, guide)
    return d


@pytest.mark.parametrize("mu", [0.2, 0.5])
def test_a_frictional_guide_holds_in_a_dynamic_run_at_any_time_step(scene_dict, mu):
    # The shaken span pulls the hose through the frictionless guide by ±3 mm; a guide with
    # friction holds it. The regularised friction is a stiff spring in its stick zone
    # (ε = 1 mm/s · h): before, Newton jumped across the zone and cycled (the runs stopped with
    # "Newton did not converge" at steps 1–42), and iterates accepted with the step's own
    # tolerance slipped by millimetres while the kinetic energy grew up to 3000-fold
    # (docs/scene.md "sliding"). Now the runs at 1 and 0.25 ms agree.
    free = simulate(scene_from_dict(guided_hose(scene_dict, 0.0, 1e-3))).cable
    slid_free = np.abs(free.clips["guide"].slid_length).max()
    assert slid_free > 2e-3
    runs = [
        simulate(scene_from_dict(guided_hose(scene_dict, mu, dt))).cable for dt in (1e-3, 2.5e-4)
    ]
    for res in runs:
        assert np.abs(res.clips["guide"].slid_length).max() < 0.02 * slid_free  # it holds
    coarse, fine = runs
    ke_c, ke_f = coarse.energies["kinetic_energy"], fine.energies["kinetic_energy"][::4]
    assert ke_c.max() == pytest.approx(ke_f.max(), rel=0.02)
    z_c, z_f = coarse.positions[:, 30, 2], fine.positions[::4, 30, 2]  # the shaken span
    np.testing.assert_allclose(z_c, z_f, atol=0.02 * np.ptp(z_f))


def test_a_frictional_guide_on_a_moving_body_carries_the_cable_along(scene_dict):
    # The guide rides on a body moving 5 mm at 5 Hz along its line: frictionless the hose
    # slides through it (±3.3 mm relative to it); with μ = 1 it moves with the guide (friction
    # acts on the velocity relative to the guide's material point, not the global one).
    slid = {}
    for mu in (0.0, 1.0):
        d = guided_hose(scene_dict, mu, 1e-3)
        sine = {"type": "sine", "amplitude": 0.005, "frequency": 5.0, "fade_in": 0.1}
        origin = d["cables"][0]["clips"][1]["position"]
        d["bodies"] = [
            {"name": "slider", "origin": origin, "motion": [{"channel": "x", "signal": sine}]}
        ]
        d["cables"][0]["clips"][1]["body"] = "slider"
        d["cables"][0]["clips"][2]["body"] = "world"
        result = simulate(scene_from_dict(d))
        assert result.complete
        slid[mu] = np.abs(result.cable.clips["guide"].slid_length).max()
    assert slid[0.0] > 2e-3
    assert slid[1.0] < 0.01 * slid[0.0]
