"""Contact through the scene API: a sagging hose resting on a table (static, dynamic), the
contact outputs in the result and its HDF5 file, and bad contact settings.

The physics of the contact term is tested against analytical references in
crates/rod/tests/contact.rs; these check that the scene path carries it through.
"""

from __future__ import annotations

import numpy as np
import pytest
from cablelife.results import load_result
from cablelife.scene import SceneError, scene_from_dict
from cablelife.simulate import simulate

TABLE_Z = -0.05


def with_table(d, **contact):
    d["contact"] = {
        "enabled": True,
        "geometry": [{"type": "plane", "name": "table", "center": [0.0, 0.0, TABLE_Z]}],
        **contact,
    }
    return d


def weight(res) -> float:
    return float(res.section["mass_per_length"]) * 1.0 * 9.81


def test_static_hose_on_a_table_carries_its_weight(scene_dict):
    res = simulate(scene_from_dict(with_table(scene_dict))).cable
    f = res.contact_force
    assert f.shape == (1, 41, 3)
    clips = sum(c.force[0] for c in res.clips.values())
    total = f[0].sum(axis=0) + clips
    w = weight(res)
    # Contact and clips carry the weight (the solver's residual tolerance is far below 1e-6).
    assert total == pytest.approx([0.0, 0.0, w], abs=1e-6 * w)
    assert f[0, :, 2].sum() > 0.5 * w  # the table carries most of it
    # The cable surface does not go through the table (1 % of r), and lies on it where touching.
    r = 0.005
    z = res.positions[0, :, 2]
    assert z.min() - r - TABLE_Z > -0.01 * r
    touching = res.contact["contact_state"][0] > 0
    assert touching.any()
    assert np.all(np.abs(z[touching] - r - TABLE_Z) < 0.01 * r)
    # Per-body totals: the table is on 'world' (index 0).
    assert res.contact["body_contact_force"][0, 0] == pytest.approx(f[0].sum(axis=0))
    # Without contact the hose hangs through the table.
    d = with_table(scene_dict)
    d["contact"]["enabled"] = False
    free = simulate(scene_from_dict(d)).cable
    assert free.contact_force is None
    assert free.positions[0, :, 2].min() < TABLE_Z


def test_contact_outputs_are_saved_and_read_back(scene_dict, tmp_path):
    d = with_table(scene_dict, friction=0.3)
    d["simulation"].update(mode="dynamic", duration=0.05, time_step=1e-3)
    result = simulate(scene_from_dict(d))
    res = result.cable
    n = res.n_steps
    assert res.contact["contact_normal"].shape == (n, 41, 3)
    assert res.contact["contact_state"].shape == (n, 41)
    assert res.contact["body_contact_force"].shape == (n, 1, 3)
    assert np.all(res.contact["contact_gap"] > -0.01 * 0.005)
    path = result.save(tmp_path / "r.h5")
    back = load_result(path).cable
    for key, value in res.contact.items():
        np.testing.assert_array_equal(back.contact[key], value)
    np.testing.assert_array_equal(back.contact_force, res.contact_force)


@pytest.mark.parametrize(
    ("contact", "message"),
    [
        ({"enabled": True, "friction": -0.2, "geometry": [{"type": "plane"}]}, "friction"),
        ({"enabled": True}, "no geometry"),
        ({"enabled": True, "geometry": [{"type": "sphere"}]}, "radius"),
        ({"enabled": True, "geometry": [{"type": "cone"}]}, "cone"),
        (
            {"enabled": True, "geometry": [{"type": "plane", "friction": -1.0}]},
            "friction",
        ),
        ({"enabled": True, "geometry": [{"type": "plane", "body": "arm"}]}, "'arm'"),
        ({"enabled": True, "geometry": [{"type": "plane", "normal": [0, 0, 0]}]}, "normal"),
    ],
)
def test_bad_contact_settings_are_named(scene_dict, contact, message):
    scene_dict["contact"] = contact
    with pytest.raises(SceneError, match=message):
        scene_from_dict(scene_dict)


def test_quasistatic_hose_lifted_off_and_lowered_onto_a_moving_table(scene_dict):
    # The clip end moves up and down by 3 cm; the table rides on a body that also moves: the
    # hose leaves and regains the table, never goes through it, and the contact forces with
    # the clip reactions carry its weight at every step.
    d = with_table(scene_dict)
    d["simulation"].update(mode="quasistatic", duration=1.0, time_step=0.05)
    d["bodies"] = [
        {
            "name": "engine",
            "origin": [0.8, 0.2, 0.0],
            "motion": [
                {"channel": "z", "signal": {"type": "sine", "amplitude": 0.03, "frequency": 1.0}}
            ],
        },
        {
            "name": "shelf",
            "motion": [
                {"channel": "z", "signal": {"type": "sine", "amplitude": 0.005, "frequency": 2.0}}
            ],
        },
    ]
    d["cables"][0]["clips"][1]["body"] = "engine"
    d["contact"]["geometry"][0]["body"] = "shelf"
    res = simulate(scene_from_dict(d)).cable
    w = weight(res)
    f = res.contact_force
    clips = sum(c.force for c in res.clips.values())
    np.testing.assert_allclose(f.sum(axis=1)[:, 2] + clips[:, 2], w, atol=1e-6 * w)
    np.testing.assert_allclose(res.contact["body_contact_force"][:, 2], f.sum(axis=1))
    assert np.all(res.contact["contact_gap"] > -0.01 * 0.005)
    touching = (res.contact["contact_state"] > 0).sum(axis=1)
    assert touching.min() < touching.max()  # the contact changes with the motions
