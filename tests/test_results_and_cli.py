"""Result files (HDF5, atomic, readable without cablelife), the CLI and the scene schema."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import h5py
import numpy as np
import pytest
from cablelife import load_result
from cablelife.scene import json_schema, load_scene, scene_from_dict
from cablelife.simulate import simulate

ROOT = Path(__file__).resolve().parents[1]


def test_result_round_trip_with_units_and_scene(scene_dict, tmp_path):
    result = simulate(scene_from_dict(scene_dict))
    path = result.save(tmp_path / "r.h5")
    assert [p.name for p in tmp_path.iterdir()] == ["r.h5"]  # no temporary file left
    back = load_result(path)
    c, b = result.cable, back.cable
    for key in ("time", "arc_length", "positions", "quaternions", "forces", "moments"):
        np.testing.assert_array_equal(getattr(c, key), getattr(b, key))
    np.testing.assert_array_equal(c.clips["a"].force, b.clips["a"].force)
    assert b.section["EA"] == pytest.approx(c.section["EA"])
    # Plain HDF5: units in attributes, the scene embedded and loadable again.
    with h5py.File(path) as f:
        assert f["cables/hose/forces"].attrs["unit"] == "N"
        assert f["cables/hose/moments"].attrs["unit"] == "N m"
        assert f["cables/hose/positions"].shape == (1, 41, 3)
        toml_text = f.attrs["scene_toml"]
    import tomllib

    again = scene_from_dict(tomllib.loads(toml_text))
    assert again.cables[0].clips[1].position == tuple(
        scene_dict["cables"][0]["clips"][1]["position"]
    )


def test_failed_write_leaves_the_old_file(scene_dict, tmp_path):
    result = simulate(scene_from_dict(scene_dict))
    path = result.save(tmp_path / "r.h5")
    before = path.read_bytes()
    result.cables["hose"].positions = object()  # not storable
    with pytest.raises(TypeError):
        result.save(path)
    assert path.read_bytes() == before
    assert [p.name for p in tmp_path.iterdir()] == ["r.h5"]


def test_not_a_result_file(tmp_path):
    p = tmp_path / "x.h5"
    with h5py.File(p, "w") as f:
        f["a"] = 1
    with pytest.raises(ValueError, match="not a cablelife result"):
        load_result(p)


def run_cli(*args):
    return subprocess.run(
        [sys.executable, "-m", "cablelife", *args], capture_output=True, text=True, cwd=ROOT
    )


def test_cli_run_prints_the_summary_and_saves(tmp_path):
    out = tmp_path / "hose.h5"
    proc = run_cli("run", "examples/hose-three-clips.toml", "-o", str(out), "-q")
    assert proc.returncode == 0, proc.stderr
    for text in ("max tension", "max bending moment", "min bend radius", "engine-bracket"):
        assert text in proc.stdout
    assert load_result(out).cable.n_steps == 1


def test_cli_reports_bad_scenes_without_traceback(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text('[[cables]]\nname = "x"\nlength = -1.0\n')
    proc = run_cli("run", str(bad))
    assert proc.returncode == 2
    assert "cables[0].length" in proc.stderr and "Traceback" not in proc.stderr


def test_committed_schema_is_current():
    committed = json.loads((ROOT / "docs" / "scene.schema.json").read_text())
    assert committed == json_schema(), (
        "regenerate: python -m cablelife schema -o docs/scene.schema.json"
    )


@pytest.mark.parametrize("example", sorted((ROOT / "examples").glob("*.toml")))
def test_examples_validate(example):
    load_scene(example)
