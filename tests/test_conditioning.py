"""Ill-conditioned tangent stiffness: a warning that names the cause and the estimated
condition (issue 13; docs/solver.md "Singular and ill-conditioned systems")."""

from __future__ import annotations

import copy
import warnings

import numpy as np
import pytest
from cablelife.scene import scene_from_dict
from cablelife.simulate import SimulationError, build_cable, simulate
from cablelife.validity import CONDITION_WARNING, ConditioningWarning

HOSE = {
    "simulation": {"mode": "static", "gravity": [0.0, 0.0, -9.81]},
    "cables": [
        {
            "name": "hose",
            "length": 1.0,
            "segments": 40,
            "stiffness": {
                "EA": 3927.0,
                "GA": 1300.0,
                "EI": 0.0245,
                "GJ": 0.017,
                "mass_per_length": 0.118,
                "radius": 0.005,
            },
            "clips": [
                {"name": "a", "s": 0.0, "position": [0, 0, 0], "direction": [1, 0, 0]},
                {"name": "b", "s": 1.0, "position": [0.8, 0.2, 0], "direction": [1, 0, 0]},
            ],
        }
    ],
}


def hose(segments: int = 40, **stiffness) -> dict:
    d = copy.deepcopy(HOSE)
    d["cables"][0]["segments"] = segments
    d["cables"][0]["stiffness"].update(stiffness)
    return d


def conditioning(d: dict) -> tuple[float, list[str]]:
    sc = scene_from_dict(d)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        core = build_cable(sc, sc.cables[0])
    msgs = [str(w.message) for w in caught if issubclass(w.category, ConditioningWarning)]
    return core.condition()[0], msgs


def test_shear_stiffness_far_above_the_axial_one_is_named_with_the_condition():
    cond, msgs = conditioning(hose(GA=1e4 * 3927.0))
    assert cond > CONDITION_WARNING
    assert len(msgs) == 1
    assert "cable 'hose'" in msgs[0] and "GA1 = 1e+04·EA" in msgs[0]
    assert f"{cond:.2g}" in msgs[0]
    # the same ratio on a coarser scale stays below the limit: no warning
    cond, msgs = conditioning(hose(GA=1000 * 3927.0))
    assert cond < CONDITION_WARNING and msgs == []


def test_below_the_limit_the_answer_is_the_shear_rigid_one_and_above_it_the_cause_is_named():
    # GA = 1000·EA (condition 3.5e10) against GA = 10·EA: both shear-rigid for this hose
    # (EI/(GA L²) < 1e-5), so the static shapes agree far below 1e-5 m.
    shapes = []
    for ga in (1000 * 3927.0, 10 * 3927.0):
        with warnings.catch_warnings():
            warnings.simplefilter("error", ConditioningWarning)
            res = simulate(scene_from_dict(hose(GA=ga))).cable
        assert res.solver["unstable"][0] == 0
        shapes.append(res.positions[0])
    assert np.abs(shapes[0] - shapes[1]).max() < 1e-5
    # GA = 1e4·EA (3.5e11): the solver's pivots reach round-off ("singular"); the warning
    # before the error names the cause
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        with pytest.raises(SimulationError, match="singular"):
            simulate(scene_from_dict(hose(GA=1e4 * 3927.0)))
    named = [str(w.message) for w in caught if issubclass(w.category, ConditioningWarning)]
    assert len(named) == 1 and "GA1 = 1e+04·EA" in named[0]


@pytest.mark.parametrize(
    "label, scene",
    [
        ("normal hose", hose()),
        ("fine hose", hose(segments=400)),
        # rotary inertia enters the mass matrix, not the tangent: the banded modal solver is
        # exact for it (crates/rod/tests/modal.rs), statics never see it
        ("rotary inertia 1e-12 kg m", hose(rotary_inertia=1e-12)),
        # bending stiffness 1e-9 of the hose's: the scaled tangent's spread is unchanged
        ("EI = GJ = 1e-9 N m²", hose(EI=1e-9, GJ=1e-9)),
    ],
)
def test_legal_models_are_not_warned(label, scene):
    cond, msgs = conditioning(scene)
    assert msgs == [], label
    assert cond < 1e-2 * CONDITION_WARNING, label


def test_a_segment_ratio_of_1e5_is_scaled_away():
    # a load 1e-6 m from the clip gives a segment 25 000 times shorter than the others: the
    # Jacobi scaling of the estimate (and the pivoting of the solver) removes it
    d = hose()
    d["cables"][0]["loads"] = [{"s": 1e-6, "force": [0, 0, -0.01]}]
    sc = scene_from_dict(d)
    with warnings.catch_warnings():
        warnings.simplefilter("error", ConditioningWarning)
        core = build_cable(sc, sc.cables[0])
    ds = np.diff(core.arc_length)
    assert ds.max() / ds.min() > 1e4
    assert core.condition()[0] < 1e-2 * CONDITION_WARNING


def test_a_singular_tangent_is_left_to_the_solve_error():
    # one ball clip leaves the cable free to turn: singular, which the solve names (a rigid-body
    # motion), not an ill-conditioning warning
    d = hose()
    d["cables"][0]["clips"] = [{**d["cables"][0]["clips"][0], "type": "ball"}]
    cond, msgs = conditioning(d)
    assert not np.isfinite(cond)
    assert msgs == []
