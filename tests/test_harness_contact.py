"""Surroundings on harnesses (docs/harness.md, "Surroundings"): clearance of every branch
(against exact distances and the cables computed alone); contact is refused by name."""

from __future__ import annotations

import numpy as np
import pytest
from cablelife.scene import SceneError, scene_from_dict
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


@pytest.mark.parametrize("mode", ["static", "quasistatic", "dynamic"])
def test_harness_contact_is_a_named_error(mode):
    d = table(y_scene(mode))
    d["simulation"].update(duration=0.01, time_step=1e-3)
    with pytest.raises(SceneError, match="contact with the geometry is not supported yet for harn"):
        simulate(scene_from_dict(d))


def test_disabled_contact_runs_a_harness_with_clearance():
    d = table(y_scene(), z=-0.03, enabled=False)
    d["contact"] = {"enabled": False}
    res = simulate(scene_from_dict(d))
    assert all(c.surroundings is not None and not c.contact for c in res.cables.values())
