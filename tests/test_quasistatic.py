"""Quasistatic sequences: warm-started equilibria following the body motions."""

from __future__ import annotations

import numpy as np
import pytest
from cablelife.scene import scene_from_dict
from cablelife.simulate import SimulationError, simulate


def moving(scene_dict, motion, duration=1.0, step=0.05):
    scene_dict["simulation"].update(mode="quasistatic", duration=duration, time_step=step)
    scene_dict["bodies"] = [{"name": "engine", "origin": [0.8, 0.2, 0.0], "motion": motion}]
    scene_dict["cables"][0]["clips"][1]["body"] = "engine"
    return scene_from_dict(scene_dict)


def test_each_step_equals_a_static_solve_at_that_pose(scene_dict):
    motion = [
        {"channel": "z", "signal": {"type": "sine", "amplitude": 0.05, "frequency": 1.0}},
        {"channel": "ry", "signal": {"type": "sine", "amplitude": 0.3, "frequency": 0.5}},
    ]
    scene = moving(scene_dict, motion)
    res = simulate(scene).cable
    assert res.n_steps == 21
    k = 7
    t = res.time[k]
    pos = np.array(scene_dict["cables"][0]["clips"][1]["position"])
    z = 0.05 * np.sin(2 * np.pi * t)
    ry = 0.3 * np.sin(np.pi * t)
    c, s = np.cos(ry), np.sin(ry)
    rot = np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])
    origin = np.array([0.8, 0.2, 0.0])
    clip = scene_dict["cables"][0]["clips"][1]
    static = dict(scene_dict)
    static["simulation"] = {"mode": "static", "gravity": [0.0, 0.0, -9.81]}
    static["bodies"] = []
    clip.update(
        body="world",
        position=(origin + [0, 0, z] + rot @ (pos - origin)).tolist(),
        direction=(rot @ np.array(clip["direction"])).tolist(),
        normal=(rot @ np.array(clip["normal"])).tolist(),
    )
    ref = simulate(scene_from_dict(static)).cable
    np.testing.assert_allclose(res.positions[k], ref.positions[0], atol=1e-9)
    np.testing.assert_allclose(res.moments[k], ref.moments[0], atol=1e-8)
    np.testing.assert_allclose(res.positions[k, -1], origin + [0, 0, z], atol=1e-12)


def test_rigid_translation_of_everything_changes_no_load(scene_dict):
    # Both clips on one body translating: the cable moves rigidly, loads stay constant.
    scene_dict["simulation"].update(mode="quasistatic", duration=1.0, time_step=0.1)
    scene_dict["bodies"] = [
        {
            "name": "frame",
            "motion": [
                {"channel": "y", "signal": {"type": "sine", "amplitude": 0.2, "frequency": 0.7}}
            ],
        }
    ]
    for clip in scene_dict["cables"][0]["clips"]:
        clip["body"] = "frame"
    res = simulate(scene_from_dict(scene_dict)).cable
    shift = res.positions - res.positions[:1]
    assert np.abs(shift[..., [0, 2]]).max() < 1e-9
    np.testing.assert_allclose(
        shift[..., 1], shift[:, :1, 1] * np.ones_like(shift[..., 1]), atol=1e-9
    )
    np.testing.assert_allclose(
        res.forces, np.broadcast_to(res.forces[:1], res.forces.shape), atol=1e-7
    )


def test_interrupted_run_keeps_the_steps_computed(scene_dict, tmp_path):
    sine = {"type": "sine", "amplitude": 0.02, "frequency": 1.0}
    scene = moving(scene_dict, [{"channel": "z", "signal": sine}], duration=1.0, step=0.01)
    calls = []

    def progress(cable, done, total):
        calls.append(done)
        if done >= 30:
            raise KeyboardInterrupt

    with pytest.raises(SimulationError) as info:
        simulate(scene, progress=progress)
    partial = info.value.result
    assert (
        not partial.complete and "interrupted" in partial.message or "callback" in partial.message
    )
    n = partial.cable.n_steps
    assert 30 <= n < 101
    assert partial.cable.positions.shape == (n, 41, 3)
    path = partial.save(tmp_path / "partial.h5")
    from cablelife import load_result
    from cablelife.resultcheck import PartialResultWarning

    with pytest.warns(PartialResultWarning, match="partial result"):
        back = load_result(path)
    assert not back.complete and back.cable.n_steps == n


def test_motion_table_csv(scene_dict, tmp_path):
    # A body pose table t, x, y, z, rx, ry, rz drives the clip; the clip follows it exactly.
    t = np.linspace(0.0, 1.0, 11)
    table = np.column_stack([t, 0 * t, 0.05 * t, -0.02 * t, 0.1 * t, 0 * t, 0 * t])
    csv = tmp_path / "engine.csv"
    np.savetxt(csv, table, delimiter=",", header="t,x,y,z,rx,ry,rz", comments="")
    scene_dict["simulation"].update(mode="quasistatic", duration=1.0, time_step=0.25)
    scene_dict["bodies"] = [{"name": "engine", "origin": [0.8, 0.2, 0.0], "motion_file": str(csv)}]
    scene_dict["cables"][0]["clips"][1]["body"] = "engine"
    res = simulate(scene_from_dict(scene_dict)).cable
    np.testing.assert_allclose(
        res.positions[:, -1], [[0.8, 0.2 + 0.05 * ti, -0.02 * ti] for ti in res.time], atol=1e-12
    )


def test_newton_failure_names_the_residual_and_keeps_steps(scene_dict):
    # Far too few iterations for a slack four-clip cable: a clear failure, not a hang or NaN.
    cable = scene_dict["cables"][0]
    cable["length"] = 1.2
    cable["clips"].insert(
        1,
        {
            "name": "m",
            "s": 0.6,
            "position": [0.3, 0.3, -0.1],
            "direction": [0.0, 1.0, 0.0],
            "type": "swivel",
        },
    )
    cable["clips"][-1]["s"] = 1.2
    scene_dict["simulation"]["max_iterations"] = 1
    with pytest.raises(SimulationError) as info:
        simulate(scene_from_dict(scene_dict))
    msg = str(info.value)
    assert "did not converge" in msg and "last residual" in msg and " N" in msg
    assert info.value.result.cable.n_steps == 0
