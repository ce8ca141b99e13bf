"""Every bad input gets a clear error naming the key, the value and what is allowed."""

from __future__ import annotations

import pytest
from cablelife.scene import SceneError, load_scene, scene_from_dict
from cablelife.simulate import simulate


def error_of(data) -> str:
    with pytest.raises(SceneError) as info:
        simulate(scene_from_dict(data))
    return str(info.value)


def test_overlapping_clips(scene_dict):
    clips = scene_dict["cables"][0]["clips"]
    clips.append({**clips[1], "name": "c", "s": 0.5, "length": 0.1})
    clips.append({**clips[1], "name": "d", "s": 0.52})
    msg = error_of(scene_dict)
    assert "'c'" in msg and "'d'" in msg and "overlap" in msg


def test_clip_outside_the_cable(scene_dict):
    scene_dict["cables"][0]["clips"][1]["s"] = 1.3
    msg = error_of(scene_dict)
    assert "clips[1]" in msg and "'b'" in msg and "outside the cable [0, 1.0]" in msg


def test_finite_clip_reaching_beyond_the_end(scene_dict):
    scene_dict["cables"][0]["clips"][0]["length"] = 0.04
    msg = error_of(scene_dict)
    assert "covers s = [-0.02, 0.02]" in msg


def test_unknown_key_and_missing_value(scene_dict):
    scene_dict["cables"][0]["lenght"] = 2.0
    del scene_dict["cables"][0]["length"]
    msg = error_of(scene_dict)
    assert "cables[0].lenght: unknown key" in msg
    assert "cables[0].length: required" in msg


def test_non_positive_radius(scene_dict):
    scene_dict["cables"][0]["section"]["radius"] = -0.005
    msg = error_of(scene_dict)
    assert "cables[0].section.circle.radius" in msg and "greater than or equal to 0.00001" in msg
    assert "-0.005" in msg


def test_tube_with_inner_radius_too_large(scene_dict):
    scene_dict["cables"][0]["section"] = {
        "shape": "tube",
        "outer_radius": 0.005,
        "inner_radius": 0.006,
    }
    msg = error_of(scene_dict)
    assert "inner_radius = 0.006 must be smaller than outer_radius = 0.005" in msg


def test_poisson_ratio_out_of_range(scene_dict):
    scene_dict["cables"][0]["material"]["poisson_ratio"] = 0.7
    msg = error_of(scene_dict)
    assert "material.poisson_ratio" in msg and "0.5" in msg and "0.7" in msg


def test_clip_on_unknown_body(scene_dict):
    scene_dict["cables"][0]["clips"][1]["body"] = "engine"
    msg = error_of(scene_dict)
    assert "clips[1].body = 'engine'" in msg and "allowed: ['world']" in msg


def test_unknown_clip_type(scene_dict):
    scene_dict["cables"][0]["clips"][1]["type"] = "clamp"
    msg = error_of(scene_dict)
    assert "clips[1].type" in msg and "'fixed', 'swivel', 'ball', 'hinge' or 'sliding'" in msg


def test_normal_parallel_to_direction(scene_dict):
    scene_dict["cables"][0]["clips"][1]["normal"] = [2.0, 0.0, 0.0]
    msg = error_of(scene_dict)
    assert "parallel to direction" in msg


def test_both_section_and_measured_stiffness(scene_dict):
    scene_dict["cables"][0]["stiffness"] = {
        "EA": 1e4,
        "EI": 0.02,
        "GJ": 0.015,
        "mass_per_length": 0.1,
        "radius": 0.005,
    }
    msg = error_of(scene_dict)
    assert "either section + material or stiffness" in msg


def test_quasistatic_needs_a_duration(scene_dict):
    scene_dict["simulation"]["mode"] = "quasistatic"
    msg = error_of(scene_dict)
    assert "simulation.duration is required" in msg


def test_unheld_cable_is_a_clear_error(scene_dict):
    # One ball clip: the cable can rotate freely about it.
    clip = scene_dict["cables"][0]["clips"][0]
    scene_dict["cables"][0]["clips"] = [{**clip, "type": "ball"}]
    from cablelife.simulate import SimulationError

    with pytest.raises(SimulationError) as info:
        simulate(scene_from_dict(scene_dict))
    assert "singular" in str(info.value) and "rigid-body motion" in str(info.value)


def test_missing_and_malformed_files(tmp_path):
    with pytest.raises(SceneError, match="does not exist"):
        load_scene(tmp_path / "nope.toml")
    bad = tmp_path / "bad.toml"
    bad.write_text("[simulation\nmode = 1")
    with pytest.raises(SceneError, match="not valid TOML"):
        load_scene(bad)
