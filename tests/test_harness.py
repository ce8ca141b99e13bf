"""Harness scenes (docs/harness.md): junction validation, static and quasistatic runs through
the Python workflow, junction equilibrium and symmetry, results round trip."""

from __future__ import annotations

import copy
import math

import numpy as np
import pytest
from cablelife.results import load_result
from cablelife.scene import SceneError, scene_from_dict
from cablelife.simulate import simulate

C30, S30 = math.cos(math.radians(30)), math.sin(math.radians(30))
SECTION = {"shape": "circle", "radius": 0.004}
MATERIAL = {"youngs_modulus": 5e7, "poisson_ratio": 0.4, "density": 2000.0}


def y_scene(**sim) -> dict:
    """A trunk from a clamp to a junction at the origin, two branches at ±30° to clamps."""

    def cable(name, length, clip_s, pos, direction):
        return {
            "name": name,
            "length": length,
            "segments": 24,
            "section": SECTION,
            "material": MATERIAL,
            "clips": [
                {
                    "name": f"{name}-clamp",
                    "s": clip_s,
                    "position": pos,
                    "direction": direction,
                    "normal": [0.0, 0.0, 1.0],
                    "body": "bracket" if name == "trunk" else "world",
                }
            ],
        }

    return {
        "simulation": {"mode": "static", **sim},
        "bodies": [{"name": "bracket"}],
        "cables": [
            cable("trunk", 0.5, 0.0, [-0.5, 0.0, 0.0], [1.0, 0.0, 0.0]),
            cable("a", 0.4, 0.4, [0.4 * C30, 0.4 * S30, 0.0], [C30, S30, 0.0]),
            cable("b", 0.4, 0.4, [0.4 * C30, -0.4 * S30, 0.0], [C30, -S30, 0.0]),
        ],
        "junctions": [
            {
                "name": "y",
                "ends": ["trunk:end", "a:start", "b:start"],
                "position": [0.0, 0.0, 0.0],
                "directions": [[-1.0, 0.0, 0.0], [C30, S30, 0.0], [C30, -S30, 0.0]],
                "normals": [[0.0, 0.0, 1.0]] * 3,
                "mass": 0.02,
            }
        ],
    }


def test_static_y_is_symmetric_and_the_junction_in_equilibrium(tmp_path):
    result = simulate(scene_from_dict(y_scene()))
    j = result.junctions["y"]
    assert set(j.branch_force) == {"trunk:end", "a:start", "b:start"}
    fa, fb = j.branch_force["a:start"][0], j.branch_force["b:start"][0]
    mirror = np.array([1.0, -1.0, 1.0])
    scale = np.abs(fa).max()
    assert scale > 0.01
    np.testing.assert_allclose(fb, fa * mirror, atol=1e-8 * scale)
    ma, mb = j.branch_moment["a:start"][0], j.branch_moment["b:start"][0]
    np.testing.assert_allclose(mb, -ma * mirror, atol=1e-8 * np.abs(ma).max())
    weight = np.array([0.0, 0.0, -9.81 * 0.02])
    total_f = sum(f[0] for f in j.branch_force.values()) + weight
    total_m = sum(m[0] for m in j.branch_moment.values())
    # The junction's equilibrium is its residual: within the Newton tolerance of the forces.
    assert np.abs(total_f).max() < 1e-9 * scale
    assert np.abs(total_m).max() < 1e-9 * scale
    # The joined ends sit at the junction; the junction sags under the weights.
    pos = j.position[0]
    assert pos[2] < -1e-4 and abs(pos[1]) < 1e-10
    np.testing.assert_allclose(result.cables["trunk"].positions[0, -1], pos, atol=1e-14)
    np.testing.assert_allclose(result.cables["a"].positions[0, 0], pos, atol=1e-14)
    # Only the scene's clips are clip outputs; the junction loads are the junction's.
    assert list(result.cables["a"].clips) == ["a-clamp"]
    path = result.save(tmp_path / "y.h5")
    back = load_result(path)
    np.testing.assert_array_equal(back.junctions["y"].position, j.position)
    np.testing.assert_array_equal(
        back.junctions["y"].branch_force["trunk:end"], j.branch_force["trunk:end"]
    )


def test_quasistatic_harness_follows_a_moving_clip():
    scene = y_scene(mode="quasistatic", duration=0.2, time_step=0.05)
    scene["bodies"][0]["motion"] = [
        {"channel": "y", "signal": {"type": "sine", "amplitude": 0.03, "frequency": 1.25}}
    ]
    result = simulate(scene_from_dict(scene))
    j = result.junctions["y"]
    assert j.position.shape == (5, 3)
    # The trunk's clamp moves along +y: the junction follows it, less than the clamp.
    dy = j.position[:, 1]
    assert dy[-1] > 1e-4 and dy[-1] < 0.03
    assert np.all(result.cables["trunk"].solver["iterations"] < 40)


@pytest.mark.parametrize(
    ("change", "message"),
    [
        (lambda s: s["junctions"][0].update(ends=["trunk:end", "c:start", "b:start"]), "no cable"),
        (lambda s: s["junctions"][0].update(ends=["trunk:end", "a:start", "a:start"]), "already"),
        (lambda s: s["junctions"][0].update(directions=[[1.0, 0, 0]]), "1 directions for 3"),
        (lambda s: s["junctions"][0].update(ends=["trunk:end", "a:middle", "b:start"]), "allowed"),
        (lambda s: s["junctions"][0].update(ends=["trunk:start", "a:start", "b:start"]), "holds"),
        (
            lambda s: (
                s["junctions"].append(
                    {
                        "name": "z",
                        "ends": ["a:end", "b:end"],
                        "position": [0.4 * C30, 0.0, 0.0],
                        "directions": [[-1.0, 0, 0], [1.0, 0, 0]],
                    }
                )
                or [c["clips"].clear() for c in s["cables"][1:]]
            ),
            "loop",
        ),
        (lambda s: [c["clips"].clear() for c in s["cables"]], "held by no clip"),
        (lambda s: s["junctions"][0].update(mass=1e12), r"mass.*less than or equal to 1000"),
        (
            lambda s: s["junctions"][0].update(rotary_inertia=1e-300),
            r"rotary_inertia = 1e-300 kg m²; allowed: 0 \(none\) or 1e-12 … 100",
        ),
        (lambda s: s["junctions"][0].update(rotary_inertia=1e12), "allowed: 0"),
    ],
)
def test_bad_junctions_are_named(change, message):
    scene = y_scene()
    change(scene)
    with pytest.raises(SceneError, match=message):
        scene_from_dict(scene)


def test_dynamic_y_stays_symmetric_and_saves_its_junction(tmp_path):
    """The trunk's bracket shaken along its axis (x) and vertically: the Y's motion stays
    mirror-symmetric about the x–z plane (branch loads mirrored at every saved step, the
    junction on the plane), the energies are recorded, and the result survives a round trip."""
    sc = y_scene(mode="dynamic", duration=0.06, time_step=1e-3, output_step=2e-3)
    sine = {"type": "sine", "amplitude": 0.003, "frequency": 20.0}
    sc["bodies"][0]["motion"] = [
        {"channel": "z", "signal": sine},
        {"channel": "x", "signal": {**sine, "amplitude": 0.001}},
    ]
    result = simulate(scene_from_dict(sc))
    assert result.complete
    j = result.junctions["y"]
    assert j.time.size == 31 and j.position.shape == (31, 3)
    moved = np.linalg.norm(j.position - j.position[0], axis=1).max()
    assert moved > 1e-4, moved  # the junction follows the shaken trunk
    # On the symmetry plane to round-off of the motion.
    assert np.abs(j.position[:, 1]).max() < 1e-9 * moved
    mirror = np.array([1.0, -1.0, 1.0])
    fa, fb = j.branch_force["a:start"], j.branch_force["b:start"]
    np.testing.assert_allclose(fb, fa * mirror, atol=1e-8 * np.abs(fa).max())
    trunk = result.cables["trunk"]
    for key in ("kinetic_energy", "elastic_energy", "dissipated_energy", "load_potential"):
        assert np.all(np.isfinite(trunk.energies[key])), key
    assert trunk.energies["kinetic_energy"][1:].max() > 0.0
    assert np.all(np.diff(trunk.energies["dissipated_energy"]) >= 0.0)
    path = tmp_path / "y.h5"
    result.save(path)
    back = load_result(path)
    np.testing.assert_array_equal(back.junctions["y"].position, j.position)
    # The default bending damping is calibrated on the first mode of the whole harness
    # (ζ = 1 from bending, tests/test_harness_damping.py), the same τ on every branch.
    taus = {cable.solver["tau_bend"][0] for cable in result.cables.values()}
    assert len(taus) == 1 and taus.pop() > 0


def test_dynamic_start_reuses_the_calibration_equilibrium():
    """The default damping's calibration solves the harness's static equilibrium at t = 0; the
    dynamic run then starts from it (one Newton iteration) instead of solving it again from
    the routed shape, and runs as with the same damping given explicitly (no calibration: the
    equilibrium solved from the route), to the static tolerance."""
    sc = y_scene(mode="dynamic", duration=0.02, time_step=1e-3)
    sine = {"type": "sine", "amplitude": 0.003, "frequency": 20.0}
    sc["bodies"][0]["motion"] = [{"channel": "z", "signal": sine}]
    calibrated = simulate(scene_from_dict(sc))
    given = copy.deepcopy(sc)
    for c in given["cables"]:
        taus = calibrated.cables[c["name"]].solver
        c["damping"] = {
            "shear": float(taus["tau_shear"][0]),
            "extension": float(taus["tau_shear"][2]),
            "bending": float(taus["tau_bend"][0]),
            "torsion": float(taus["tau_bend"][2]),
        }
    explicit = simulate(scene_from_dict(given))
    assert calibrated.cables["trunk"].solver["iterations"][0] <= 1  # converged at the start
    assert explicit.cables["trunk"].solver["iterations"][0] > 1
    for name, c in calibrated.cables.items():
        np.testing.assert_allclose(c.positions, explicit.cables[name].positions, atol=1e-12)


def pair_scene(joined: bool) -> dict:
    """A 1 m cable clamped at both ends along x without gravity: one cable, or two 0.5 m
    cables joined by a massless junction at x = 0.5 (the same discrete model)."""

    def clip(name, s, x):
        return {"name": name, "s": s, "position": [x, 0.0, 0.0], "direction": [1.0, 0.0, 0.0]}

    def cable(name, length, segments, clips):
        return {
            "name": name,
            "length": length,
            "segments": segments,
            "section": SECTION,
            "material": MATERIAL,
            "clips": clips,
        }

    scene = {"simulation": {"mode": "static", "gravity": [0.0, 0.0, 0.0]}}
    if not joined:
        scene["cables"] = [cable("c", 1.0, 32, [clip("a", 0.0, 0.0), clip("b", 1.0, 1.0)])]
        return scene
    scene["cables"] = [
        cable("c", 0.5, 16, [clip("a", 0.0, 0.0)]),
        cable("d", 0.5, 16, [clip("b", 0.5, 1.0)]),
    ]
    scene["junctions"] = [
        {
            "name": "j",
            "ends": ["c:end", "d:start"],
            "position": [0.5, 0.0, 0.0],
            "directions": [[-1.0, 0.0, 0.0], [1.0, 0.0, 0.0]],
            "mass": 0.0,
        }
    ]
    return scene


def test_harness_modes_equal_the_single_cable_and_the_cli_prints_them(tmp_path):
    from cablelife.cli import app
    from cablelife.modal import modes
    from typer.testing import CliRunner

    single = modes(scene_from_dict(pair_scene(False)), 6)["c"]
    harness = modes(scene_from_dict(pair_scene(True)), 6)
    assert set(harness) == {"c", "d"}
    np.testing.assert_allclose(harness["c"].omega, single.omega, rtol=1e-6)
    np.testing.assert_array_equal(harness["d"].omega, harness["c"].omega)
    # Each cable holds its part of the shape: the first bending mode is symmetric about the
    # junction (mirror node k of c and N−k of d).
    c, d = harness["c"].shapes[0], harness["d"].shapes[0]
    assert np.abs(c).max() > 0
    np.testing.assert_allclose(c[1:-1], d[::-1][1:-1], atol=1e-6 * np.abs(c).max())
    path = tmp_path / "pair.toml"
    import tomli_w

    path.write_bytes(tomli_w.dumps(pair_scene(True)).encode())
    out = CliRunner().invoke(app, ["modes", str(path), "-n", "3"])
    assert out.exit_code == 0, out.output
    assert "harness ('c', 'd'): natural frequencies" in out.output
    assert f"{single.frequencies[0]:.4g}" in out.output


def test_harness_static_states_are_checked_for_stability():
    result = simulate(scene_from_dict(y_scene()))
    for name in ("trunk", "a", "b"):
        np.testing.assert_array_equal(result.cables[name].solver["unstable"], [0])


def test_example_harness_runs_from_the_command_line(tmp_path):
    import subprocess
    import sys
    from pathlib import Path

    scene = Path(__file__).resolve().parents[1] / "examples" / "harness" / "scene.toml"
    out = tmp_path / "h.h5"
    proc = subprocess.run(
        [sys.executable, "-m", "cablelife", "run", str(scene), "-o", str(out), "--mode", "static"],
        capture_output=True,
        text=True,
    )
    assert proc.returncode == 0, proc.stderr
    assert "junctions (max over time)" in proc.stdout and "gearbox:start" in proc.stdout
    res = load_result(out)
    j = res.junctions["breakout"]
    assert len(j.branch_force) == 4
    total = sum(f[0] for f in j.branch_force.values()) + np.array([0, 0, -9.81 * 0.01])
    assert np.abs(total).max() < 1e-8 * max(np.abs(f[0]).max() for f in j.branch_force.values())
