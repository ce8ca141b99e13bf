"""Clip types on harnesses (docs/harness.md): sliding clips on harness cables (slid length in
the results, saved and reloaded) and clips holding a junction (pose, reactions, validation)."""

from __future__ import annotations

import numpy as np
import pytest
from cablelife.results import load_result
from cablelife.scene import SceneError, scene_from_dict
from cablelife.simulate import simulate
from test_harness import C30, MATERIAL, S30, SECTION, y_scene


def test_sliding_clip_on_a_branch_slides_and_its_slid_length_is_saved(tmp_path):
    scene = y_scene(mode="quasistatic", duration=0.2, time_step=0.05)
    # A frictionless guide at the middle of branch a; the trunk's bracket pulls along −x.
    scene["cables"][1]["clips"].append(
        {
            "name": "guide",
            "type": "sliding",
            "s": 0.2,
            "length": 0.05,
            "position": [0.2 * C30, 0.2 * S30, 0.0],
            "direction": [C30, S30, 0.0],
            "normal": [0.0, 0.0, 1.0],
        }
    )
    # x = −0.02 sin(2π 1.25 t): a monotonic pull of 2 cm over the quarter period.
    pull = {"type": "sine", "amplitude": 0.02, "frequency": 1.25, "phase": np.pi}
    scene["bodies"][0]["motion"] = [{"channel": "x", "signal": pull}]
    result = simulate(scene_from_dict(scene))
    assert result.complete, result.message
    guide = result.cables["a"].clips["guide"]
    slid = guide.slid_length
    assert slid.shape == (5,)
    # Pulled towards the junction: the cable slides through the guide towards s = 0 (its
    # material at the guide comes from larger s), monotonically, by less than the pull.
    assert slid[-1] > 1e-4 and slid[-1] < 0.02, slid
    assert np.all(np.diff(slid) > 0), slid
    # A frictionless guide pushes across its line only.
    t = np.array([C30, S30, 0.0])
    f = guide.force
    assert np.abs(f @ t).max() < 1e-6 * max(np.linalg.norm(f, axis=1).max(), 1e-9)
    back = load_result(result.save(tmp_path / "slid.h5"))
    np.testing.assert_array_equal(back.cables["a"].clips["guide"].slid_length, slid)


def held_y(mode: str = "static", **sim) -> dict:
    """The Y of test_harness with its junction clamped to the moving body "bracket" (which
    no longer holds the trunk: the trunk's clamp is on the world)."""
    scene = y_scene(mode=mode, **sim)
    scene["cables"][0]["clips"][0]["body"] = "world"
    scene["junctions"][0]["clip"] = {"body": "bracket", "name": "connector"}
    return scene


def test_junction_held_by_a_clip_moves_with_it_and_the_reactions_balance(tmp_path):
    scene = held_y("quasistatic", duration=0.2, time_step=0.05)
    scene["bodies"][0]["motion"] = [
        {"channel": "z", "signal": {"type": "sine", "amplitude": 0.02, "frequency": 1.25}},
        {"channel": "rx", "signal": {"type": "sine", "amplitude": 0.1, "frequency": 1.25}},
    ]
    result = simulate(scene_from_dict(scene))
    assert result.complete, result.message
    j = result.junctions["y"]
    # The body's origin is the world origin, where the junction sits: it moves up by
    # 0.02 sin(2π 1.25 t) and turns about x by 0.1 sin(…) rad.
    t = j.time
    phase = np.sin(2 * np.pi * 1.25 * t)
    np.testing.assert_allclose(j.position[:, 2], 0.02 * phase, atol=1e-12)
    np.testing.assert_allclose(j.position[:, :2], 0.0, atol=1e-12)
    angle = 2 * np.arctan2(np.linalg.norm(j.quaternion[:, 1:], axis=1), np.abs(j.quaternion[:, 0]))
    np.testing.assert_allclose(angle, 0.1 * phase, atol=1e-9)
    # The whole harness is in equilibrium: the junction clip's reaction, the far clamps'
    # reactions and the weights of the cables and the junction.
    mass = 0.02
    for k in range(t.size):
        f = j.reaction_force[k] + np.array([0.0, 0.0, -9.81 * mass])
        m = j.reaction_moment[k] + np.cross(j.position[k], f)
        for c in result.cables.values():
            (clip,) = c.clips.values()
            x = c.positions[k, 0] if clip.s == 0.0 else c.positions[k, -1]
            f = f + clip.force[k]
            m = m + clip.moment[k] + np.cross(x, clip.force[k])
            ds = np.diff(c.arc_length)
            node = np.concatenate([[ds[0] / 2], (ds[1:] + ds[:-1]) / 2, [ds[-1] / 2]])
            w = np.outer(node, [0.0, 0.0, -9.81 * c.section["mass_per_length"]])
            f = f + w.sum(axis=0)
            m = m + np.cross(c.positions[k], w).sum(axis=0)
        scale = np.linalg.norm(j.reaction_force[k])
        assert scale > 0.01
        assert np.linalg.norm(f) < 1e-8 * scale, (k, f)
        assert np.linalg.norm(m) < 1e-8 * scale, (k, m)
        # The junction's own balance: its clip against the branch loads and its weight.
        fj = sum(b[k] for b in j.branch_force.values()) + j.reaction_force[k]
        assert np.linalg.norm(fj + [0.0, 0.0, -9.81 * mass]) < 1e-8 * scale
        mj = sum(b[k] for b in j.branch_moment.values()) + j.reaction_moment[k]
        assert np.linalg.norm(mj) < 1e-8 * scale
    back = load_result(result.save(tmp_path / "held.h5")).junctions["y"]
    np.testing.assert_array_equal(back.reaction_force, j.reaction_force)
    np.testing.assert_array_equal(back.reaction_moment, j.reaction_moment)
    assert result.junctions["y"].reaction_force is not None
    free = simulate(scene_from_dict(y_scene())).junctions["y"]
    assert free.reaction_force is None


@pytest.mark.parametrize(
    ("change", "message"),
    [
        (lambda s: s["junctions"][0].update(clip={"body": "engine"}), "junctions\\[0\\].clip.body"),
        (lambda s: s["junctions"][0].update(clip={"bdy": "world"}), "bdy"),
    ],
)
def test_bad_junction_clips_are_named(change, message):
    scene = held_y()
    change(scene)
    with pytest.raises(SceneError, match=message):
        scene_from_dict(scene)


def test_a_junction_clip_holds_a_harness_without_other_clips():
    # Branches hanging from a clamped junction: no cable clip at all.
    scene = held_y()
    for c in scene["cables"]:
        c["clips"].clear()
    result = simulate(scene_from_dict(scene))
    j = result.junctions["y"]
    weight = sum(c.section["mass_per_length"] * c.arc_length[-1] for c in result.cables.values())
    w = 9.81 * (weight + 0.02)
    np.testing.assert_allclose(j.reaction_force[0], [0, 0, w], rtol=1e-8, atol=1e-9 * w)


def test_dynamic_harness_with_a_sliding_clip_and_a_held_junction(tmp_path):
    """The junction follows its clip's body (2 mm at 10 Hz along z), its velocity and the
    harness energies are saved; the clip accelerates the junction against its branch loads
    and weight; branch a slides through a frictionless guide."""
    scene = held_y("dynamic", duration=0.05, time_step=0.001)
    w = 2 * np.pi * 10.0
    scene["bodies"][0]["motion"] = [
        {"channel": "z", "signal": {"type": "sine", "amplitude": 0.002, "frequency": 10.0}}
    ]
    scene["cables"][1]["clips"].append(
        {
            "name": "guide",
            "type": "sliding",
            "s": 0.2,
            "length": 0.06,
            "position": [0.2 * C30, 0.2 * S30, 0.0],
            "direction": [C30, S30, 0.0],
            "normal": [0.0, 0.0, 1.0],
        }
    )
    result = simulate(scene_from_dict(scene))
    assert result.complete, result.message
    j = result.junctions["y"]
    t = j.time
    assert t.size == 51
    np.testing.assert_allclose(j.position[:, 2], 0.002 * np.sin(w * t), atol=1e-12)
    np.testing.assert_allclose(j.velocity[:, 2], 0.002 * w * np.cos(w * t), atol=1e-9)
    np.testing.assert_allclose(j.velocity[:, :2], 0.0, atol=1e-12)
    np.testing.assert_allclose(j.angular_velocity, 0.0, atol=1e-12)
    # The junction (0.02 kg): clip reaction + branch forces + weight = m a.
    mass = 0.02
    acc = np.zeros((t.size, 3))
    acc[:, 2] = -0.002 * w * w * np.sin(w * t)
    fj = sum(j.branch_force.values()) + j.reaction_force + [0.0, 0.0, -9.81 * mass]
    scale = np.abs(j.reaction_force).max()
    assert scale > 0.01
    np.testing.assert_allclose(fj, mass * acc, atol=1e-8 * scale)
    mj = sum(j.branch_moment.values()) + j.reaction_moment
    np.testing.assert_allclose(mj, 0.0, atol=1e-8 * scale)
    slid = result.cables["a"].clips["guide"].slid_length
    assert slid.shape == (51,) and np.isfinite(slid).all() and np.abs(slid).max() > 0.0
    e = result.harness_energies
    assert set(e) == {
        "time",
        "kinetic_energy",
        "elastic_energy",
        "load_potential",
        "dissipated_energy",
    }
    np.testing.assert_array_equal(e["time"], t)
    assert e["kinetic_energy"].max() > 0.0 and np.isfinite(e["elastic_energy"]).all()
    # The harness's kinetic energy covers its cables (whose ends move with the junction) and
    # the junction's own mass.
    cables = sum(c.energies["kinetic_energy"] for c in result.cables.values())
    np.testing.assert_allclose(
        e["kinetic_energy"], cables + 0.5 * mass * (j.velocity**2).sum(axis=1), rtol=1e-12
    )
    back = load_result(result.save(tmp_path / "dyn.h5"))
    bj = back.junctions["y"]
    np.testing.assert_array_equal(bj.velocity, j.velocity)
    np.testing.assert_array_equal(bj.angular_velocity, j.angular_velocity)
    np.testing.assert_array_equal(bj.reaction_force, j.reaction_force)
    for key, value in e.items():
        np.testing.assert_array_equal(back.harness_energies[key], value)
    static = simulate(scene_from_dict(held_y()))
    assert static.harness_energies == {} and static.junctions["y"].velocity is None


def test_the_example_harness_runs_dynamically_with_its_sliding_guide_and_a_held_breakout():
    import tomllib
    from pathlib import Path

    d = tomllib.loads((Path(__file__).parents[1] / "examples/harness/scene.toml").read_text())
    d["simulation"].update(mode="dynamic", duration=0.01, time_step=0.001)
    motion = d["bodies"][0]["motion"]
    motion[:] = [m for m in motion if m["signal"]["type"] != "psd"]  # needs ≥ 0.2 s
    result = simulate(scene_from_dict(d))
    assert result.complete, result.message
    assert np.isfinite(result.cables["trunk"].clips["trunk-guide"].slid_length).all()
    d["junctions"][0]["clip"] = {"body": "world", "name": "tape"}
    result = simulate(scene_from_dict(d))
    assert result.complete, result.message
    j = result.junctions["breakout"]
    np.testing.assert_allclose(j.position, [[0.4, 0.0, 0.0]] * 11, atol=1e-15)
    np.testing.assert_allclose(j.velocity, 0.0, atol=1e-15)
    for cable in result.cables.values():
        assert np.isfinite(cable.positions).all() and len(cable.time) == 11


def collinear_pair(normals=None) -> dict:
    """Two straight cables along x joined at the origin, clamped at their far ends with the
    normal z; no gravity: the stress-free state, if the junction imposes no twist."""

    def cable(name, s, x):
        clip = {"name": f"{name}-clamp", "s": s, "position": [x, 0.0, 0.0]}
        clip.update(direction=[1.0, 0.0, 0.0], normal=[0.0, 0.0, 1.0])
        return {
            "name": name,
            "length": 0.5,
            "segments": 20,
            "section": SECTION,
            "material": MATERIAL,
            "clips": [clip],
        }

    junction = {"name": "j", "ends": ["a:end", "b:start"], "position": [0.0, 0.0, 0.0]}
    junction["directions"] = [[-1.0, 0.0, 0.0], [1.0, 0.0, 0.0]]
    if normals is not None:
        junction["normals"] = normals
    return {
        "simulation": {"mode": "static", "gravity": [0.0, 0.0, 0.0]},
        "cables": [cable("a", 0.0, -0.5), cable("b", 0.5, 0.5)],
        "junctions": [junction],
    }


def test_default_junction_normals_come_from_the_routed_geometry():
    from cablelife.harness import end_clip_name, harness_cables

    scene = scene_from_dict(collinear_pair())
    cables, _ = harness_cables(scene)
    name = end_clip_name(scene.junctions[0])
    for c in cables:
        (end,) = [k for k in c.clips if k.name == name]
        # The clamps' normal z carried along the straight cable: z (the clip rule would give
        # y, the axis least aligned with x: a quarter turn of twist at the junction).
        np.testing.assert_allclose(end.normal, [0.0, 0.0, 1.0], atol=1e-12)
    result = simulate(scene)
    for c in result.cables.values():
        assert np.abs(c.moments).max() < 1e-9 and np.abs(c.forces).max() < 1e-9
    # Given normals are kept: y on one end and z on the other twist the pair by a quarter
    # turn at the junction.
    twisted = simulate(scene_from_dict(collinear_pair([[0.0, 1.0, 0.0], [0.0, 0.0, 1.0]])))
    gj = np.abs(twisted.cables["a"].moments[..., 2]).max()
    assert gj > 1e-3, gj


def test_workbench_keeps_default_junction_normals_when_clips_move(tmp_path):
    """The default normals follow the routed geometry, which moves with the clips: the
    workbench keeps the ones in effect as opened (drags, rebuilds) and writes them on save, so
    that the saved scene solves to what the workbench shows."""
    import re
    from pathlib import Path

    from cablelife.scene import load_scene
    from cablelife.workbench.session import Session

    text = (Path(__file__).parents[1] / "examples/harness/scene.toml").read_text()
    text = re.sub(r"(?m)^normals = .*\n", "", text)
    path = tmp_path / "harness.toml"
    path.write_text(text)
    session = Session.open(path)
    opened = session.junction_pins["breakout"]
    p0 = np.array([0.8, 0.15, -0.05])
    for k in range(1, 11):
        p = p0 + 0.003 * k * np.array([0.0, 1.0, 1.0])
        errors = session.move_clips(
            [{"cable": "engine", "clip": "engine-bracket", "position": p.tolist()}]
        )
        assert errors == {"engine": ""}
    out = session.save(tmp_path / "saved.toml")
    saved = load_scene(out)
    np.testing.assert_array_equal(np.array(saved.junctions[0].normals), np.array(opened))
    # The moved scene without the pins would get other normals (the engine branch's route
    # changed): the pins matter.
    from cablelife.harness import junction_normals

    moved = junction_normals(
        saved.model_copy(
            update={"junctions": [saved.junctions[0].model_copy(update={"normals": None})]}
        )
    )["breakout"]
    assert np.abs(np.array(moved) - np.array(opened)).max() > 1e-6
    batch = simulate(saved, mode="static")
    for name, live in session.cables.items():
        assert np.abs(live.state.positions - batch.cables[name].positions[0]).max() < 1e-9, name
