"""Cold static solves of the example harness with the powertrain turned land on the
equilibrium reached by continuation from the reference pose (issue 16: a former cold solve
after a 0.03 rad turn found another equilibrium 9–12 cm away)."""

from __future__ import annotations

import copy
import shutil
import warnings
from pathlib import Path

import numpy as np
import pytest
from cablelife.scene import load_scene, scene_from_dict
from cablelife.simulate import simulate

HARNESS = Path(__file__).parent.parent / "examples" / "harness" / "scene.toml"
SHIFT = (0.02, 0.02)  # m, along y and z
TURNS = (0.03, 0.02)  # rad, about y and z


def _run(motion: list, mode: str, duration: float):
    data = load_scene(HARNESS).model_dump(mode="json", exclude_none=True)
    data["bodies"][0]["motion"] = motion
    data["simulation"].update(mode=mode, duration=duration, time_step=0.1)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return simulate(scene_from_dict(copy.deepcopy(data), base_dir=HARNESS.parent), mode=mode)


@pytest.mark.parametrize("turn", [0.03, 0.1])
def test_a_cold_static_solve_of_a_turned_powertrain_equals_the_continued_one(turn):
    values = (("y", SHIFT[0]), ("z", SHIFT[1]), ("ry", turn), ("rz", TURNS[1]))
    table = lambda a, b: {"type": "table", "t": [0.0, 1.0], "value": [a, b]}  # noqa: E731
    ramp = [{"channel": c, "signal": table(0.0, v)} for c, v in values]
    held = [{"channel": c, "signal": table(v, v)} for c, v in values]
    continued = _run(ramp, "quasistatic", 1.0)
    cold = _run(held, "static", 0.1)
    for name, result in continued.cables.items():
        moved = np.abs(result.positions[-1] - result.positions[0]).max()
        assert moved > 1e-3, f"{name}: the turn moves it ({moved})"
        gap = np.abs(result.positions[-1] - cold.cables[name].positions[0]).max()
        assert gap < 1e-9, f"{name}: cold solve {gap:.3e} m from the continued equilibrium"


def test_a_cold_solve_of_the_saved_dragged_scene_equals_the_drag(tmp_path):
    """The workbench drags the powertrain (10 steps, each warm from the last) and saves; a
    cold batch static solve of the saved scene (reference = the moved pose) is the same
    equilibrium."""
    from cablelife.rotations import euler_matrix, matrix_quaternions
    from cablelife.workbench.session import Session, at_rest

    for f in HARNESS.parent.iterdir():
        if f.is_file():
            shutil.copy(f, tmp_path / f.name)
    session = Session.open(tmp_path / HARNESS.name)
    o0 = np.array([0.8, 0.0, -0.1])
    for k in range(1, 11):
        f = k / 10
        q = matrix_quaternions(euler_matrix([0.0, TURNS[0] * f, TURNS[1] * f])[None])[0]
        origin = o0 + f * np.array([0.0, *SHIFT])
        errors = session.move_body("powertrain", origin.tolist(), q.tolist(), mark=k == 1)
        assert errors == {"engine": "", "gearbox": ""}
    saved = load_scene(session.save(tmp_path / "moved.toml"))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        cold = simulate(at_rest(saved), mode="static")
    for name, live in session.cables.items():
        gap = np.abs(live.state.positions - cold.cables[name].positions[0]).max()
        assert gap < 1e-9, f"{name}: cold solve {gap:.3e} m from the dragged equilibrium"
