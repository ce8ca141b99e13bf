"""Damping of harnesses (docs/harness.md, "Damping"): modal damping ratios of the whole tree
and the default bending damping calibrated on the harness's first mode, checked against the
single cable and against the free decay of a dynamic run."""

from __future__ import annotations

import warnings
from pathlib import Path

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
    # The example harness: its mode 1 is 143 % bending (compressed branches lower ω₁ below the
    # bending stiffness alone), so the former rule τ = 2ζ/ω₁ damped it at 1.43 ζ; calibrated,
    # it gets ζ from bending exactly, the extension, torsion and shear damping (loss factor 0.1
    # on their own modes) a small part on top.
    from cablelife.modal import retardation_times
    from cablelife.scene import load_scene

    scene = load_scene(Path(__file__).parents[1] / "examples" / "harness" / "scene.toml")
    core, cables, _, _ = harness_equilibrium(scene)
    omega1, per_tau = mode1_bending_damping(core, len(cables))
    assert per_tau * 2 / omega1 == pytest.approx(1.43, abs=0.01)  # the former rule's ζ₁ / ζ
    modes = harness_modes(scene, 3, damping=True)
    zeta = modes["trunk"].damping_ratio
    assert 0.2 <= zeta[0] < 0.2 * 1.03, zeta
    assert np.all(zeta[1:] > zeta[0])  # stiffness-proportional: higher modes more
    for m in modes.values():
        np.testing.assert_array_equal(m.damping_ratio, zeta)  # one ratio per harness mode
    for c in cables:
        assert retardation_times(scene, c, (omega1, per_tau))[1][0] == 0.2 / per_tau


def test_default_damping_of_a_mode_hardly_bending_is_held():
    # The Y hanging under gravity: its mode 1 stretches the cables (9 % of its stiffness is
    # bending). The τ that would damp it at ζ (11× the beam rule) would over-damp every bending
    # mode above it; τ is held at 2ζ/(ω₁ · MIN_BENDING_SHARE) and the mode gets
    # ζ · share / MIN_BENDING_SHARE from bending.
    from cablelife.modal import CALIBRATION_TOLERANCE, MIN_BENDING_SHARE, retardation_times

    scene = scene_from_dict(with_damping(y_scene(), {"ratio": 0.05}))
    core, cables, _, _ = harness_equilibrium(scene)
    omega1, per_tau = mode1_bending_damping(core, len(cables))
    share = per_tau * 2 / omega1
    assert share < 0.1
    _, bend, info = retardation_times(scene, cables[0], (omega1, per_tau))
    assert bend[0] == pytest.approx(2 * 0.05 / (omega1 * MIN_BENDING_SHARE), rel=1e-12)
    assert info["bending_share"] == pytest.approx(share, rel=1e-12)
    # the calibration's mode (its tolerance: the same vector), its ratio linear in τ
    bending_only = core.modes(
        1,
        shear_tau=[[0.0] * 3] * 3,
        bend_tau=[[bend[0]] * 2 + [0.0]] * 3,
        tolerance=CALIBRATION_TOLERANCE,
    )
    zeta1 = bending_only["damping_ratio"][0]
    assert zeta1 == pytest.approx(0.05 * share / MIN_BENDING_SHARE, rel=1e-9)


def test_harness_free_decay_shows_the_modal_damping_ratio():
    # A short vertical kick of the trunk's bracket; the hanging Y rings down in its first mode
    # (the higher ones are damped 3.5× more). The logarithmic decrement of a trunk node along
    # mode 1's shape gives mode 1's damping ratio of the harness modal analysis (ζ = 0.5 set:
    # the mode is 9 % bending and gets 0.05 from bending, held, plus its extension damping),
    # the period 2π/ω₁.
    d = with_damping(y_scene(), {"ratio": 0.5})
    kick = {"type": "table", "t": [0.0, 0.05, 0.1, 10.0], "value": [0.0, 0.005, 0.0, 0.0],
            "interpolation": "pchip"}  # fmt: skip
    d["bodies"] = [{"name": "bracket", "motion": [{"channel": "z", "signal": kick}]}]
    mode1 = harness_modes(scene_from_dict(d), 1, damping=True)["trunk"]
    expected = mode1.damping_ratio[0]
    assert 0.04 < expected < 0.08
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
    assert zeta == pytest.approx(expected, rel=0.1)
    assert period == pytest.approx(2 * np.pi / mode1.omega[0], rel=0.03)
    # The run says that this mode is hardly bending and what damping it gets.
    hints = [h for h in run_hints(scene, result) if "bending" in h]
    assert len(hints) == 3 and "only 9 % bending" in hints[0], hints


class Recording:
    """A solver object that records the tolerance its ``modes`` is asked for."""

    def __init__(self, solver):
        self.solver, self.asked = solver, []

    def modes(self, *args, **kwargs):
        self.asked.append(kwargs.get("tolerance"))
        return self.solver.modes(*args, **kwargs)


def test_calibration_tolerance_loosens_only_the_last_digits():
    """The damping's calibration stops the modal iteration at a change of 1e-9 instead of
    1e-11: ω₁ and ζ₁ as the full accuracy's to 1e-7, on a harness and on a single cable; a
    tolerance outside (0, 1) is an error naming it."""
    from cablelife.modal import CALIBRATION_TOLERANCE, _equilibrium
    from cablelife.scene import load_scene

    scene = load_scene(Path(__file__).parents[1] / "examples" / "harness" / "scene.toml")
    core, cables, _, _ = harness_equilibrium(scene)
    single, _ = _equilibrium(scene, scene.cables[0])
    for solver, n in ((core, len(cables)), (single, None)):
        taus = dict(shear_tau=[0.0] * 3, bend_tau=[1.0, 1.0, 0.0])
        if n is not None:
            taus = {k: [v] * n for k, v in taus.items()}
        full = solver.modes(1, **taus)
        quick = solver.modes(1, **taus, tolerance=CALIBRATION_TOLERANCE)
        for key in ("omega", "damping_ratio"):
            np.testing.assert_allclose(quick[key], full[key], rtol=1e-7, atol=0)
        recording = Recording(solver)  # the calibration asks the solver for its tolerance
        assert mode1_bending_damping(recording, n) == (
            float(quick["omega"][0]),
            float(quick["damping_ratio"][0]),
        )
        assert recording.asked == [CALIBRATION_TOLERANCE]
        for bad in (0.0, 1.0, float("nan"), -1e-9):
            with pytest.raises(ValueError, match=r"tolerance = .*allowed 0 < tolerance < 1"):
                solver.modes(1, tolerance=bad)
