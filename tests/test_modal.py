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
                    "signal": {"type": "sine", "amplitude": 0.05, "frequency": 1.0,
                               "phase": np.pi / 2},
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
