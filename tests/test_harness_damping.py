"""Damping of harnesses (docs/harness.md, "Damping"): modal damping ratios of the whole tree
and the default bending damping calibrated on the harness's first mode, checked against the
single cable and against the free decay of a dynamic run."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from cablelife.harness import harness_equilibrium
from cablelife.hints import run_hints
from cablelife.modal import cable_modes, harness_modes, mode1_bending_damping
from cablelife.scene import scene_from_dict
from cablelife.simulate import simulate
from decay import free_decay
from test_harness import pair_scene, y_scene


def with_damping(scene: dict, damping: dict) -> dict:
    for cable in scene["cables"]:
        cable["damping"] = dict(damping)
    return scene


def test_joined_pair_has_the_damping_ratios_of_the_single_cable():
    # Two cables joined by a massless junction are the single cable's discrete model: the same
    # frequencies and, with the same Kelvin–Voigt times, the same modal damping ratios (the
    # ends move with the junction in the mode: the cells next to it dissipate).
    times = {"retardation_time": 2e-3, "torsion": 5e-4, "extension": 1e-4}
    single = scene_from_dict(with_damping(pair_scene(joined=False), times))
    joined = scene_from_dict(with_damping(pair_scene(joined=True), times))
    ref = cable_modes(single, single.cables[0], 6, damping=True)
    got = harness_modes(joined, 6, damping=True)
    for name in ("c", "d"):
        np.testing.assert_allclose(got[name].omega, ref.omega, rtol=1e-6)
        np.testing.assert_allclose(got[name].damping_ratio, ref.damping_ratio, rtol=1e-6)
    # cable_modes of a harness cable is the harness's (with damping too).
    np.testing.assert_array_equal(
        cable_modes(joined, joined.cables[0], 6, damping=True).damping_ratio,
        got["c"].damping_ratio,
    )


def test_default_damping_gives_the_harness_first_mode_the_set_ratio():
    # The Y hanging under gravity: its mode 1 strains the cables mostly in extension (9 % of
    # its stiffness is bending), so the former rule τ = 2ζ/ω₁ damped it at 0.09 ζ. The
    # calibration τ = ζ / ζ₁(τ = 1 s) gives it ζ from bending exactly; the extension, torsion
    # and shear damping (loss factor 0.1 on their own modes) add their small part on top.
    scene = scene_from_dict(with_damping(y_scene(), {"ratio": 0.05}))
    core, cables, _, _ = harness_equilibrium(scene)
    omega1, per_tau = mode1_bending_damping(core, len(cables))
    assert per_tau * 2 / omega1 < 0.1  # the former rule's ζ₁ / ζ
    modes = harness_modes(scene, 3, damping=True)
    zeta = modes["trunk"].damping_ratio
    assert 0.05 <= zeta[0] < 0.05 * 1.03, zeta
    assert np.all(zeta[1:] > zeta[0])  # stiffness-proportional: higher modes more
    for m in modes.values():
        np.testing.assert_array_equal(m.damping_ratio, zeta)  # one ratio per harness mode


def test_harness_free_decay_shows_the_set_damping_ratio():
    # A short vertical kick of the trunk's bracket; the hanging Y rings down in its first mode
    # (the higher ones are damped 3.5× more). The logarithmic decrement of a trunk node along
    # mode 1's shape gives the set ζ (the former rule: 0.0044), the period 2π/ω₁.
    d = with_damping(y_scene(), {"ratio": 0.05})
    kick = {"type": "table", "t": [0.0, 0.05, 0.1, 10.0], "value": [0.0, 0.005, 0.0, 0.0],
            "interpolation": "pchip"}  # fmt: skip
    d["bodies"] = [{"name": "bracket", "motion": [{"channel": "z", "signal": kick}]}]
    mode1 = harness_modes(scene_from_dict(d), 1, damping=True)["trunk"]
    d["simulation"].update(mode="dynamic", duration=3.0, time_step=0.001)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the kick starts abruptly (a start-up warning)
        scene = scene_from_dict(d)
        result = simulate(scene)
    trunk = result.cables["trunk"]
    node = 12
    shape = mode1.shapes[0, node] / np.linalg.norm(mode1.shapes[0, node])
    y = (trunk.positions[:, node] - trunk.positions[-1, node]) @ shape
    zeta, period = free_decay(trunk.time, y, after=1.0)
    assert zeta == pytest.approx(0.05, rel=0.1)
    assert period == pytest.approx(2 * np.pi / mode1.omega[0], rel=0.03)
    # The run says that this mode is hardly bending and what its damping does to the others.
    hints = [h for h in run_hints(scene, result) if "bending" in h]
    assert len(hints) == 3 and "only 9 % bending" in hints[0], hints
