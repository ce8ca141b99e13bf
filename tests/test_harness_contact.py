"""Surroundings on harnesses (docs/harness.md, "Surroundings"): clearance of every branch
(against exact distances and the cables computed alone); contact in static, quasistatic and
dynamic runs (against the single continuous cable, the weight carried, no penetration, no
energy gained)."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from cablelife.scene import scene_from_dict
from cablelife.simulate import simulate

SECTION = {"shape": "circle", "radius": 0.004}
MATERIAL = {"youngs_modulus": 5e7, "poisson_ratio": 0.4, "density": 2000.0}
R = 0.004
TABLE_Z = -0.01


def clamp(name, s, pos, direction, body="world"):
    return {
        "name": name,
        "s": s,
        "position": pos,
        "direction": direction,
        "normal": [0.0, 0.0, 1.0],
        "body": body,
    }


def cable(name, length, segments, clips):
    return {
        "name": name,
        "length": length,
        "segments": segments,
        "section": SECTION,
        "material": MATERIAL,
        "clips": clips,
    }


def table(d, z=TABLE_Z, **contact):
    """A table (plane z = `z`) on a body; contact enabled with `contact` unless None."""
    d["bodies"] = [
        {
            "name": "table",
            "geometry": [
                {"shape": "plane", "name": "top", "point": [0, 0, z], "normal": [0, 0, 1]}
            ],
        }
    ]
    if contact.get("enabled", True):
        d["contact"] = {"enabled": True, **contact}
    return d


def pair(n: int, mode="static") -> dict:
    """Two collinear cables of 0.5 m clamped at x = ∓0.5 and joined at the origin."""
    return {
        "simulation": {"mode": mode},
        "cables": [
            cable("a", 0.5, n, [clamp("a0", 0.0, [-0.5, 0, 0], [1, 0, 0])]),
            cable("b", 0.5, n, [clamp("b1", 0.5, [0.5, 0, 0], [1, 0, 0])]),
        ],
        "junctions": [
            {
                "name": "j",
                "ends": ["a:end", "b:start"],
                "position": [0.0, 0.0, 0.0],
                "directions": [[-1.0, 0.0, 0.0], [1.0, 0.0, 0.0]],
                "normals": [[0.0, 0.0, 1.0]] * 2,
            }
        ],
    }


def continuous(n: int, mode="static") -> dict:
    """The same span as one cable of 1 m (2n segments)."""
    clips = [
        clamp("a0", 0.0, [-0.5, 0, 0], [1, 0, 0]),
        clamp("b1", 1.0, [0.5, 0, 0], [1, 0, 0]),
    ]
    return {"simulation": {"mode": mode}, "cables": [cable("one", 1.0, 2 * n, clips)]}


def y_scene(mode="static", mass=0.0) -> dict:
    """A trunk from a clamp to a junction, two branches at ±30° to clamps, all in z = 0."""
    c, s = np.cos(np.radians(30)), np.sin(np.radians(30))
    return {
        "simulation": {"mode": mode},
        "cables": [
            cable("trunk", 0.5, 20, [clamp("t0", 0.0, [-0.5, 0, 0], [1, 0, 0])]),
            cable("a", 0.4, 16, [clamp("a1", 0.4, [0.4 * c, 0.4 * s, 0], [c, s, 0])]),
            cable("b", 0.4, 16, [clamp("b1", 0.4, [0.4 * c, -0.4 * s, 0], [c, -s, 0])]),
        ],
        "junctions": [
            {
                "name": "y",
                "ends": ["trunk:end", "a:start", "b:start"],
                "position": [0.0, 0.0, 0.0],
                "directions": [[-1.0, 0.0, 0.0], [c, s, 0.0], [c, -s, 0.0]],
                "normals": [[0.0, 0.0, 1.0]] * 3,
                "mass": mass,
            }
        ],
    }


def test_harness_clearance_is_the_distance_of_every_branch_to_the_geometry():
    d = table(y_scene(), z=-0.03, enabled=False)
    res = simulate(scene_from_dict(d))
    for name, c in res.cables.items():
        cl = c.surroundings
        assert cl is not None, name
        # a node's clearance covers its half edges: the lowest of its midpoints and itself
        z = c.positions[..., 2]
        mid = 0.5 * (z[:, 1:] + z[:, :-1])
        low = z.copy()
        low[:, 1:] = np.minimum(low[:, 1:], mid)
        low[:, :-1] = np.minimum(low[:, :-1], mid)
        exact = low - R + 0.03
        np.testing.assert_allclose(cl.value, exact, atol=1e-12)
        assert {cl.bodies[i] for i in cl.body.ravel()} == {"table"}
    assert min(c.surroundings.value.min() for c in res.cables.values()) < 0.01


def test_harness_clearance_equals_the_clearance_of_the_cables_alone():
    """Each branch's clearance (its own radius) equals the clearance of that cable computed
    alone from its positions; the summary's minimum per body is the least over the branches."""
    from cablelife.surroundings.build import load_surroundings
    from cablelife.surroundings.clearance import cable_clearance

    d = table(y_scene(), z=-0.2, enabled=False)
    d["bodies"][0]["geometry"].append(
        {"shape": "sphere", "name": "ball", "center": [0.1, 0.0, -0.08], "radius": 0.05}
    )
    d["cables"][1]["section"] = {"shape": "circle", "radius": 0.007}  # branch a is thicker
    scene = scene_from_dict(d)
    res = simulate(scene)
    env = load_surroundings(scene)
    times = np.array([0.0])
    seen = set()
    for spec in scene.cables:
        c = res.cables[spec.name]
        alone = cable_clearance(
            env, scene, c.positions, spec.properties().outer_radius, times, np.array([0])
        )
        np.testing.assert_array_equal(c.surroundings.value, alone.value)
        np.testing.assert_array_equal(c.surroundings.body, alone.body)
        seen |= set(alone.part.ravel())
    assert len(seen) == 2  # both parts (table top and ball) are nearest somewhere
    # the radius enters per branch: branch a (7 mm) as if it were 4 mm thick
    a = res.cables["a"]
    thin = cable_clearance(env, scene, a.positions, 0.004, times, np.array([0]))
    np.testing.assert_allclose(thin.value - a.surroundings.value, 0.003, atol=1e-12)


def shaken(d: dict, amplitude: float, duration: float) -> dict:
    """The first cable's first clamp on a body moved up and back by ``amplitude`` (m) in 0.1 s
    (a kick), then held; Kelvin–Voigt time 1e-4 s on every cable (the same on the harness and
    on the single cable: the default damping would be calibrated on different modes)."""
    d["simulation"].update(mode="dynamic", duration=duration, time_step=0.001)
    kick = {"type": "table", "t": [0.0, 0.05, 0.1, 10.0], "value": [0.0, amplitude, 0.0, 0.0],
            "interpolation": "pchip"}  # fmt: skip
    d["bodies"].append({"name": "bracket", "motion": [{"channel": "z", "signal": kick}]})
    d["cables"][0]["clips"][0]["body"] = "bracket"
    for c in d["cables"]:
        c["damping"] = {"retardation_time": 1e-4}
    return d


def test_dynamic_joined_pair_bouncing_on_a_table_equals_the_continuous_cable():
    # The kicked pair bounces on the table with its junction: the harness integrator takes the
    # single cable's contact rules over the tree (step bounds, tolerances, the energy guard and
    # its step splitting), so the same discrete model follows the same path — within the Newton
    # tolerance with contact (1e-4 of each step's increment: at most that fraction of the
    # distance travelled) until the two decide a step differently where the test is
    # borderline: the guard's split or the rest detection (session 8: 5.2e-8 m over the first 90
    # steps, bound 1.0e-6 m; they include the first impact, split at step 85; at step 90 the
    # pair rests and the single cable takes one more step), and within the guard's energy
    # tolerance after that (measured 1.8e-5 m of 5.2 mm: 0.35 %; bouncing motion is chaotic).
    # With the former contact tolerance 1e-5 and no contact damping the paths agreed to
    # 1.4e-11 m over the first 222 steps.
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the kick starts abruptly (a start-up warning)
        pr = simulate(scene_from_dict(shaken(table(pair(16)), 0.005, 0.3)))
        one = simulate(scene_from_dict(shaken(table(continuous(16)), 0.005, 0.3))).cables["one"]
    a, b = pr.cables["a"], pr.cables["b"]
    x = np.concatenate([a.positions, b.positions[:, 1:]], axis=1)
    moved = np.abs(one.positions - one.positions[0]).max()
    assert moved > 1e-3
    assert one.solver["substeps"].sum() > 0  # the guard split steps
    differ = np.flatnonzero(a.solver["substeps"] != one.solver["substeps"])
    same = differ[0] if differ.size else len(x)
    assert same > np.flatnonzero(one.solver["substeps"] > 1)[0]  # the first impact's split
    travel = np.abs(np.diff(one.positions[:same], axis=0)).sum(axis=0).max()
    assert np.abs(x[:same] - one.positions[:same]).max() < 1e-4 * travel
    gap = np.minimum(a.contact["contact_gap"], b.contact["contact_gap"])  # smallest per step
    np.testing.assert_allclose(gap[:same], one.contact["contact_gap"][:same], rtol=0,
                               atol=1e-4 * travel)  # fmt: skip
    assert np.abs(x - one.positions).max() < 0.02 * moved


def test_dynamic_y_kicked_on_a_table_never_gains_energy():
    # After the kick (the clamps then hold still) the energy of the Y bouncing on the table
    # (kinetic, elastic, gravity, barrier; cables and junction) never exceeds its value at the
    # end of the kick, no surface goes deeper than 1 % of r, and the contact outputs are saved.
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = simulate(scene_from_dict(shaken(table(y_scene(mass=0.02)), 0.005, 0.6)))
    assert res.complete
    e = res.harness_energies
    contact = sum(c.energies["contact_energy"] for c in res.cables.values())
    total = e["kinetic_energy"] + e["elastic_energy"] + e["load_potential"] + contact
    after = e["time"] >= 0.1
    assert total[after].max() <= total[after][0] + 1e-9
    assert e["kinetic_energy"][after].max() > 1e-5  # it does bounce
    for c in res.cables.values():
        assert np.all(c.contact["contact_gap"] > -0.01 * R), c.name
        assert c.contact_force.shape == (c.time.size, c.arc_length.size, 3)
    assert any((c.contact["contact_state"][-1] > 0).any() for c in res.cables.values())


def weight_carried(res, extra_mass=0.0) -> tuple[np.ndarray, float]:
    """Σ contact forces + Σ clip reactions over every cable (N, per step) and the weight."""
    total, weight = 0.0, extra_mass * 9.81
    for c in res.cables.values():
        total = total + c.contact_force.sum(axis=1) + sum(k.force for k in c.clips.values())
        length = c.arc_length[-1]
        weight += float(c.section["mass_per_length"]) * length * 9.81
    return total, weight


def test_joined_pair_on_a_table_equals_the_continuous_cable():
    # The pair sags onto the table with its junction lying on it; it is the continuous cable's
    # discrete model (contact included), so every node and contact force must agree.
    pr = simulate(scene_from_dict(table(pair(16))))
    one = simulate(scene_from_dict(table(continuous(16)))).cables["one"]
    a, b = pr.cables["a"], pr.cables["b"]
    x = np.concatenate([a.positions[0], b.positions[0, 1:]])
    np.testing.assert_allclose(x, one.positions[0], rtol=0, atol=1e-9)
    j = pr.junctions["j"].position[0]
    assert j[2] - R - TABLE_Z == pytest.approx(0.0, abs=0.01 * R)  # on the table
    f1 = one.contact_force[0]
    scale = np.abs(f1).max()
    np.testing.assert_allclose(a.contact_force[0, :-1], f1[:16], atol=1e-8 * scale)
    np.testing.assert_allclose(b.contact_force[0, 1:], f1[17:], atol=1e-8 * scale)
    np.testing.assert_allclose(
        a.contact_force[0, -1] + b.contact_force[0, 0], f1[16], atol=1e-8 * scale
    )
    assert f1[16, 2] > 0.1 * scale  # the junction's node carries weight


def test_y_on_a_table_carries_its_weight_and_does_not_penetrate():
    # A Y with a 20 g junction lying on a table under gravity: the contact forces and the clamp
    # reactions carry the weight of cables and junction (the solver's residual tolerance is far
    # below 1e-6); no cable surface goes through the table by more than 1 % of r.
    res = simulate(scene_from_dict(table(y_scene(mass=0.02))))
    total, weight = weight_carried(res, extra_mass=0.02)
    assert total[0] == pytest.approx([0.0, 0.0, weight], abs=1e-6 * weight)
    j = res.junctions["y"].position[0]
    assert j[2] - R - TABLE_Z == pytest.approx(0.0, abs=0.01 * R)
    for c in res.cables.values():
        assert c.positions[0, :, 2].min() - R - TABLE_Z > -0.01 * R, c.name
        assert np.all(c.contact["contact_gap"] > -0.01 * R)
        assert (c.contact["contact_state"][0] > 0).any(), c.name
        body = c.contact["body_contact_force"][0]
        np.testing.assert_allclose(body[1], c.contact_force[0].sum(axis=0), rtol=1e-12)


def test_quasistatic_y_on_a_rising_table_follows_it():
    # The table rises 5 mm and falls back (a body motion) under the lying Y: at every step the
    # weight is carried, nothing goes through the table, and each step equals a static solve
    # with the table where it is then (continuation = cold start, to the solver tolerance).
    d = table(y_scene("quasistatic", mass=0.02))
    d["simulation"].update(duration=0.5, time_step=0.05)
    sine = {"type": "sine", "amplitude": 0.005, "frequency": 1.0}
    d["bodies"][0]["motion"] = [{"channel": "z", "signal": sine}]
    res = simulate(scene_from_dict(d))
    total, weight = weight_carried(res, extra_mass=0.02)
    np.testing.assert_allclose(total[:, 2], weight, atol=1e-6 * weight)
    lift = 0.005 * np.sin(2 * np.pi * res.cables["trunk"].time)
    zj = res.junctions["y"].position[:, 2]
    np.testing.assert_allclose(zj - R - TABLE_Z - lift, 0.0, atol=0.01 * R)
    for c in res.cables.values():
        assert np.all(c.contact["contact_gap"] > -0.01 * R), c.name
    k = 3  # the table 4.8 mm up
    s = table(y_scene(mass=0.02), z=TABLE_Z + lift[k])
    cold = simulate(scene_from_dict(s))
    for name, c in res.cables.items():
        np.testing.assert_allclose(
            c.positions[k], cold.cables[name].positions[0], rtol=0, atol=1e-7
        )


def test_disabled_contact_runs_a_harness_with_clearance():
    d = table(y_scene(), z=-0.03, enabled=False)
    d["contact"] = {"enabled": False}
    res = simulate(scene_from_dict(d))
    assert all(c.surroundings is not None and not c.contact for c in res.cables.values())


def test_cablelife_run_of_a_harness_on_a_table(tmp_path):
    # The whole command: scene file → run → result file with every branch's contact outputs.
    import tomli_w
    from cablelife.cli import app
    from cablelife.results import load_result
    from typer.testing import CliRunner

    path = tmp_path / "y.toml"
    path.write_bytes(tomli_w.dumps(table(y_scene(mass=0.02))).encode())
    out = CliRunner().invoke(app, ["run", str(path), "-o", str(tmp_path / "y.h5")])
    assert out.exit_code == 0, out.output
    back = load_result(tmp_path / "y.h5")
    total, weight = weight_carried(back, extra_mass=0.02)
    assert total[0] == pytest.approx([0.0, 0.0, weight], abs=1e-6 * weight)
    assert all("contact_gap" in c.contact for c in back.cables.values())


def test_compressed_pair_on_a_table_escapes_to_a_stable_buckled_state():
    # The joined pair clamped 2 mm short of its length (compressed ~12× beyond its Euler load)
    # above a table: the straight equilibrium Newton finds is unstable; the stability check
    # counts with the (frictionless) contact stiffness and the escape leaves it for the
    # buckled state lying on the table, bent sideways (gravity keeps it down).
    d = pair(16)
    d["cables"][0]["clips"][0]["position"] = [-0.499, 0.0, 0.0]
    d["cables"][1]["clips"][0]["position"] = [0.499, 0.0, 0.0]
    res = simulate(scene_from_dict(table(d, z=-0.0041)))
    for c in res.cables.values():
        assert c.solver["unstable"][0] == 0, c.name
        assert np.ptp(c.positions[0, :, 1]) > 0.01  # buckled sideways
        assert np.all(c.contact["contact_gap"] > -0.01 * R)
    # With friction the symmetric tangent is no stability criterion: not checked (−1).
    res = simulate(scene_from_dict(table(y_scene(mass=0.02), friction=0.3)))
    assert all(c.solver["unstable"][0] == -1 for c in res.cables.values())
    res = simulate(scene_from_dict(table(y_scene(mass=0.02))))
    assert all(c.solver["unstable"][0] == 0 for c in res.cables.values())


def test_dynamic_harness_resting_on_a_tray_with_the_default_damping():
    # The default damping is calibrated on the harness's first mode at its equilibrium, which
    # here rests on a tray (the 5-branch harness of benchmarks/bench_harness.py, 16 segments
    # per cable): the modal analysis takes the contact stiffness into K. Without it the part
    # the tray carries is no equilibrium of K alone ("the equilibrium is unstable (1 negative
    # stiffness eigenvalue)") and the run stopped before its first step.
    def branch(name, length, *clips):
        return cable(name, length, 16, list(clips))

    d = {
        "simulation": {"mode": "dynamic", "duration": 0.02, "time_step": 0.001},
        "bodies": [
            {"name": "engine", "origin": [1.0, 0.0, -0.1]},
            {"name": "tray", "geometry": [
                {"shape": "plane", "name": "tray", "point": [0, 0, -0.106], "normal": [0, 0, 1]}
            ]},
        ],
        "cables": [
            branch("trunk", 0.42, clamp("body-1", 0.0, [0.0, 0.0, 0.0], [1, 0, 0])),
            branch("link", 0.32),
            branch("a", 0.33, clamp("a-end", 0.33, [0.45, 0.3, 0.0], [0, 1, 0])),
            branch("b", 0.33, clamp("b-end", 0.33, [0.45, -0.3, 0.0], [0, -1, 0])),
            branch("c", 0.35, clamp("c-end", 0.35, [1.0, 0.1, -0.05], [1, 0, 0], "engine")),
            branch("d", 0.37, clamp("d-end", 0.37, [1.0, -0.15, -0.1], [1, 0, 0], "engine")),
        ],
        "junctions": [
            {"name": "j1", "ends": ["trunk:end", "link:start", "a:start", "b:start"],
             "position": [0.4, 0.0, 0.0],
             "directions": [[-1, 0, 0], [1, 0, 0], [0.2, 1, 0], [0.2, -1, 0]]},
            {"name": "j2", "ends": ["link:end", "c:start", "d:start"],
             "position": [0.7, 0.0, 0.0],
             "directions": [[-1, 0, 0], [1, 0.3, 0], [1, -0.4, -0.3]]},
        ],
        "contact": {"enabled": True},
    }  # fmt: skip
    res = simulate(scene_from_dict(d))
    assert res.complete
    c = res.cables["trunk"]
    assert c.solver["damping_source"] == "ratio" and c.solver["omega1"] > 0
    assert any((k.contact["contact_state"][-1] > 0).any() for k in res.cables.values())


def test_a_trunk_in_a_frictional_guide_and_on_a_frictional_box_runs_at_1_ms():
    # The example harness with its trunk guide at μ = 0.2, the trunk resting on a box with
    # μ = 0.3 and the 'body' branch 400 times stiffer (E = 20 GPa): before, the step at
    # t = 5 ms failed ("Newton did not converge": contact friction had no stick-zone bound,
    # the corrections grew with fresh matrices), at every stiffness above ≈ 6 GPa.
    import tomllib
    from pathlib import Path

    d = tomllib.loads((Path(__file__).parents[1] / "examples/harness/scene.toml").read_text())
    d["simulation"].update(mode="dynamic", duration=0.03, time_step=1e-3)
    motion = d["bodies"][0]["motion"]
    motion[:] = [m for m in motion if m["signal"]["type"] != "psd"]  # needs ≥ 0.2 s
    d["bodies"].append(
        {
            "name": "car-body",
            "geometry": [
                {"shape": "box", "center": [0.3, 0.0, -0.03], "size": [0.05, 0.05, 0.02]},
            ],
        }
    )
    d["contact"] = {"enabled": True, "friction": 0.3}
    d["cables"][0]["clips"][1]["friction"] = 0.2
    d["cables"][3]["material"]["youngs_modulus"] = 2e10
    result = simulate(scene_from_dict(d))
    assert result.complete, result.message
    trunk = result.cables["trunk"]
    assert (trunk.contact["contact_state"] > 0).any()  # it rests on the box
    assert np.isfinite(trunk.positions).all()
