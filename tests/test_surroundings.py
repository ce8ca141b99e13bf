"""Geometry on bodies and the clearance of cables to it: exact distances for primitives, the
tessellation bound for a mesh sphere, inside/outside, nearest body, moving bodies, corners
between nodes, the result file and the run summary, and bad meshes."""

from __future__ import annotations

import copy
import math
import warnings

import numpy as np
import pytest
from cablelife import _core
from cablelife.scene import SceneError, scene_from_dict
from cablelife.surroundings.build import load_surroundings
from cablelife.surroundings.clearance import cable_clearance
from cablelife.surroundings.meshes import SurroundingsWarning
from scipy.spatial.transform import Rotation

trimesh = pytest.importorskip("trimesh")

RADIUS = 0.005


def scene_with(scene_dict, bodies, base_dir=None, **extra):
    d = copy.deepcopy(scene_dict)
    d["bodies"] = bodies
    d.update(extra)
    return scene_from_dict(d, base_dir=base_dir)


def clearance_at(scene, positions, times=None):
    """Clearance of a cable with node positions (S, N, 3) at the run's steps 0…S−1."""
    env = load_surroundings(scene)
    positions = np.asarray(positions, float)
    times = np.arange(positions.shape[0]) * 0.01 if times is None else times
    steps = np.arange(positions.shape[0])
    return cable_clearance(env, scene, positions, RADIUS, times, steps)


def straight(n=11, y=0.0, z=0.0, x0=0.0, x1=1.0):
    x = np.linspace(x0, x1, n)
    return np.stack([x, np.full(n, y), np.full(n, z)], axis=1)[None]


def by_definition(node_sd, half_edge_d):
    """The documented clearance: the node's signed distance if it is inside, else the least of
    it and its half-edges' distances (0 where a half-edge enters the solid); minus the cable
    radius."""
    node_sd = np.asarray(node_sd, float)
    least = np.minimum(node_sd, np.min(np.maximum(half_edge_d, 0), axis=0))
    return np.where(node_sd < 0, node_sd, least) - RADIUS


def half_edges(pos):
    """Both half-edges of every node as (a, b) pairs (2, N, 3) each; the ends repeat the node."""
    mid = (pos[1:] + pos[:-1]) / 2
    before = np.concatenate([pos[:1], mid])
    after = np.concatenate([mid, pos[-1:]])
    return np.stack([pos, pos]), np.stack([before, after])


def half_edge_sphere(pos, center, radius):
    """Exact node clearance to a sphere (segment–centre distances in closed form)."""
    a, b = half_edges(pos)
    ab = b - a
    t = np.clip(
        np.einsum("knj,knj->kn", center - a, ab) / np.maximum((ab * ab).sum(-1), 1e-300), 0, 1
    )
    seg = np.linalg.norm(a + t[..., None] * ab - center, axis=-1) - radius
    return by_definition(np.linalg.norm(pos - center, axis=1) - radius, seg)


def half_edge_plane(pos, height):
    """Exact node clearance to the half-space z < height (a segment's least height is at an
    end)."""
    a, b = half_edges(pos)
    return by_definition(pos[:, 2] - height, np.minimum(a[..., 2], b[..., 2]) - height)


def test_plane_exact(scene_dict):
    sc = scene_with(
        scene_dict,
        [
            {
                "name": "floor",
                "geometry": [{"shape": "plane", "point": [0, 0, -0.3], "normal": [0, 0, 2]}],
            }
        ],
    )
    pos = straight(z=0.1)
    pos[0, :, 2] += np.linspace(0, 0.2, 11)  # tilted: distance varies along the cable
    c = clearance_at(sc, pos)
    assert np.allclose(c.value[0], half_edge_plane(pos[0], -0.3), rtol=0, atol=1e-15)
    assert c.value[0, 1] < pos[0, 1, 2] + 0.3 - RADIUS  # the half-edge below the node counts
    # below the plane: negative
    c = clearance_at(sc, straight(z=-0.5))
    assert np.allclose(c.value, -0.2 - RADIUS, rtol=0, atol=1e-15)


def test_sphere_beside_and_inside(scene_dict):
    center, r = np.array([0.43, 0.2, 0.05]), 0.1
    sc = scene_with(
        scene_dict,
        [
            {
                "name": "ball",
                "geometry": [{"shape": "sphere", "center": center.tolist(), "radius": r}],
            }
        ],
    )
    pos = straight()
    c = clearance_at(sc, pos)
    assert np.allclose(c.value[0], half_edge_sphere(pos[0], center, r), rtol=0, atol=1e-15)
    # the cable through the sphere: the node at x = 0.4 is inside, 0.1 − |(0.03, 0.2−…)|
    pos = straight(y=0.19, z=0.05)
    c = clearance_at(sc, pos)
    inside = np.linalg.norm(pos[0] - center, axis=1) < r
    assert inside.sum() >= 1
    expected = np.linalg.norm(pos[0] - center, axis=1) - r - RADIUS
    assert np.allclose(c.value[0][inside], expected[inside], rtol=0, atol=1e-15)
    assert np.all(c.value[0][inside] < -RADIUS)


def test_box_and_cylinder_exact(scene_dict):
    rot = Rotation.from_euler("xyz", [0.2, -0.4, 0.9])
    box = {
        "shape": "box",
        "center": [0.5, 0.3, 0.1],
        "size": [0.2, 0.1, 0.3],
        "orientation": [0.2, -0.4, 0.9],
    }
    cyl = {
        "shape": "cylinder",
        "center": [0.2, -0.3, 0.0],
        "axis": [0, 1, 1],
        "radius": 0.05,
        "length": 0.2,
    }
    sc = scene_with(
        scene_dict, [{"name": "b", "geometry": [box]}, {"name": "c", "geometry": [cyl]}]
    )
    env = load_surroundings(sc)
    rng = np.random.default_rng(1)
    # box: local coordinates → signed distance of a box (exact formula)
    local = rng.uniform(-0.25, 0.25, (500, 3))
    pts = rot.apply(local) + [0.5, 0.3, 0.1]
    q = np.abs(local) - [0.1, 0.05, 0.15]
    sd = np.linalg.norm(np.maximum(q, 0), axis=1) + np.minimum(q.max(axis=1), 0)
    got = env.core.project_points(0, pts)
    assert np.abs(got["distance"] - sd).max() < 1e-15
    assert (sd < 0).sum() > 10  # inside points were tested
    # cylinder: axial and radial parts
    axis = np.array([0, 1, 1]) / math.sqrt(2)
    pts = rng.uniform(-0.13, 0.13, (500, 3)) + [0.2, -0.3, 0.0]
    rel = pts - [0.2, -0.3, 0.0]
    z = rel @ axis
    rho = np.linalg.norm(rel - z[:, None] * axis, axis=1)
    dr, dz = rho - 0.05, np.abs(z) - 0.1
    sd = np.hypot(np.maximum(dr, 0), np.maximum(dz, 0)) + np.minimum(np.maximum(dr, dz), 0)
    got = env.core.project_points(1, pts)
    assert np.abs(got["distance"] - sd).max() < 1e-15
    assert (sd < 0).sum() > 10
    # outward normals: the closest point plus distance × normal is the query point
    assert np.allclose(got["point"] + got["distance"][:, None] * got["normal"], pts, atol=1e-15)


def test_box_corner_between_nodes(scene_dict, tmp_path):
    """A box edge between two nodes: the half-edges see it, the nodes alone would not."""
    half_diag = 0.05 * math.sqrt(2)
    center = [0.25, -half_diag - 0.02, 0.0]
    box = {
        "shape": "box",
        "center": center,
        "size": [0.1, 0.1, 0.1],
        "orientation": [0, 0, math.pi / 4],
    }
    mesh = trimesh.creation.box(extents=[0.1, 0.1, 0.1])
    mesh.apply_transform(trimesh.transformations.rotation_matrix(math.pi / 4, [0, 0, 1]))
    mesh.apply_translation(center)
    mesh.export(tmp_path / "box.stl")
    # the primitive is exact; the STL stores float32 (vertices move by ≤ δ, so does the surface)
    delta = math.sqrt(3) * 2.0**-24 * np.abs(mesh.vertices).max()
    for part, tol in ((box, 1e-15), ({"mesh": "box.stl"}, delta)):
        sc = scene_with(scene_dict, [{"name": "b", "geometry": [part]}], base_dir=tmp_path)
        pos = straight(n=3)  # nodes at x = 0, 0.5, 1; the edge at x = 0.25, 0.02 away
        c = clearance_at(sc, pos)
        assert abs(c.value[0, 0] - (0.02 - RADIUS)) < tol
        assert abs(c.value[0, 1] - (0.02 - RADIUS)) < tol
        node_only = np.hypot(0.25, 0.02) - RADIUS
        assert c.value[0, 0] < node_only - 0.2
        assert c.value[0, 2] > 0.4


def icosphere_bound(mesh, radius):
    """Largest signed-distance error of an inscribed polyhedron against its sphere.

    Each face's plane is at R cos α from the centre, α the angular radius of the face's
    circumcircle (sin α = ρ / R, ρ = abc / (4 area), the circumradius): the convex polyhedron
    lies between the balls of radius R cos α_max and R, so its signed distance exceeds the
    sphere's by 0 … R (1 − cos α_max). (The sagitta R (1 − cos(θ/2)) of an edge of central
    angle θ bounds only the edges; a face centre lies deeper: for an equilateral face
    sin α = 2 sin(θ/2)/√3.)"""
    tri = mesh.vertices[mesh.faces]
    a, b, c = (np.linalg.norm(tri[:, i] - tri[:, (i + 1) % 3], axis=1) for i in range(3))
    area = mesh.area_faces
    rho = a * b * c / (4 * area)
    alpha = np.arcsin(np.minimum(rho / radius, 1))
    return radius * (1 - np.cos(alpha.max()))


def test_icosphere_stl_within_tessellation_bound(scene_dict, tmp_path):
    r, center = 0.1, np.array([0.5, 0.12, 0.0])
    ico = trimesh.creation.icosphere(subdivisions=4, radius=r)
    ico.apply_translation(center)
    ico.export(tmp_path / "ball.stl")  # binary STL
    bound = icosphere_bound(ico, r)
    assert 1e-5 < bound < 1e-3
    sc = scene_with(
        scene_dict, [{"name": "ball", "geometry": [{"mesh": "ball.stl"}]}], base_dir=tmp_path
    )
    env = load_surroundings(sc)
    rng = np.random.default_rng(2)
    # random directions and the directions of the face centres (the deepest points)
    dirs = np.vstack([rng.normal(size=(2000, 3)), ico.triangles_center - center])
    dirs /= np.linalg.norm(dirs, axis=1)[:, None]
    dist = rng.uniform(0.2 * r, 3 * r, len(dirs))
    pts = center + dirs * dist[:, None]
    got = env.core.project_points(0, pts)["distance"]
    err = got - (dist - r)
    # binary STL stores float32: every vertex moves by ≤ δ, so does the surface
    delta = math.sqrt(3) * 2.0**-24 * np.abs(ico.vertices).max()
    assert err.min() >= -delta
    assert err.max() <= bound + delta
    assert err.max() > 0.9 * bound  # the bound is tight: the test can fail
    # a cable passing it: within the bound of the exact sphere values, inside negative
    for y in (0.0, 0.06):
        pos = straight(n=41, y=y)
        c = clearance_at(sc, pos)
        exact = half_edge_sphere(pos[0], center, r)
        assert np.all(c.value[0] - exact >= -delta)
        assert np.all(c.value[0] - exact <= bound + delta)
    assert c.value.min() < -0.02  # y = 0.06 runs through the ball


def test_nearest_body(scene_dict):
    bodies = [
        {
            "name": "left",
            "geometry": [{"shape": "sphere", "center": [0.1, 0.1, 0], "radius": 0.05}],
        },
        {
            "name": "right",
            "geometry": [
                {"shape": "sphere", "center": [0.9, 0.1, 0], "radius": 0.05, "name": "knob"}
            ],
        },
        {"name": "clipper"},  # a body without geometry
    ]
    sc = scene_with(scene_dict, bodies)
    c = clearance_at(sc, straight())
    assert c.bodies == ["left", "right"]
    assert c.parts == ["left/sphere#0", "right/knob"]
    assert np.array_equal(c.body[0], [0] * 6 + [1] * 5)
    assert list(c.body_names()[0][[0, -1]]) == ["left", "right"]


def test_geometry_moves_with_its_body(scene_dict):
    """A plane lifted by a table signal and a sphere turning about the body's x axis, given in
    the body frame: the clearance follows the body motion the clips use."""
    lift = {
        "channel": "z",
        "frame": "global",
        "signal": {"type": "table", "t": [0, 1], "value": [0, 0.05]},
    }
    turn = {
        "channel": "rx",
        "frame": "global",
        "signal": {"type": "table", "t": [0, 1], "value": [0, 0.5]},
    }
    bodies = [
        {
            "name": "floor",
            "motion": [lift],
            "geometry": [{"shape": "plane", "point": [0, 0, -0.2], "normal": [0, 0, 1]}],
        },
        {
            "name": "arm",
            "origin": [0.5, 0.0, 0.0],
            "orientation": [0, 0, math.pi / 2],
            "motion": [turn],
            "geometry": [
                {"shape": "sphere", "frame": "body", "center": [0, -0.15, 0], "radius": 0.05}
            ],
        },
    ]
    d = copy.deepcopy(scene_dict)
    d["simulation"].update(mode="quasistatic", duration=1.0, time_step=0.1)
    sc = scene_with(d, bodies)
    times = np.linspace(0, 1, 11)
    pos = np.repeat(straight(n=21), 11, axis=0)
    c = clearance_at(sc, pos, times)
    floor = 0.2 - 0.05 * times  # the floor rises: the gap shrinks
    # the sphere: body frame y' = −x global (rz = 90°): centre at o + (0.15, 0, 0) at rest,
    # then turned about global x by 0.5 t — its centre stays on the x axis: fixed distance
    sphere_center = np.array([0.65, 0.0, 0.0])
    sph = np.array([half_edge_sphere(p, sphere_center, 0.05) for p in pos])
    expected = np.minimum(floor[:, None] - RADIUS, sph)
    assert np.allclose(c.value, expected, rtol=0, atol=1e-14)
    # a sphere off the rotation axis moves: centre o + Rx(0.5 t) (0, 0, 0.15) (body frame
    # (0, 0, 0.15) is global (0, 0, 0.15) under rz = 90°)
    bodies[1]["geometry"][0]["center"] = [0, 0, 0.15]
    sc = scene_with(d, bodies)
    c = clearance_at(sc, pos, times)
    for k, t in enumerate(times):
        center = np.array([0.5, 0, 0]) + Rotation.from_euler("x", 0.5 * t).apply([0, 0, 0.15])
        e = np.minimum(floor[k] - RADIUS, half_edge_sphere(pos[k], center, 0.05))
        assert np.allclose(c.value[k], e, rtol=0, atol=1e-14)


def test_run_stores_and_summarises_clearance(scene_dict, tmp_path):
    from cablelife.cli import app
    from cablelife.results import load_result
    from cablelife.simulate import simulate
    from cablelife.surroundings.summary import clearance_summary
    from typer.testing import CliRunner

    d = copy.deepcopy(scene_dict)
    d["bodies"] = [
        {
            "name": "floor",
            "geometry": [{"shape": "plane", "point": [0, 0, -0.26], "normal": [0, 0, 1]}],
        }
    ]
    d["clearance"] = {"min_clearance": 0.02}
    sc = scene_from_dict(d)
    res = simulate(sc)
    c = res.cable
    assert c.clearance.shape == (1, 41) and c.clearance_body.shape == (1, 41)
    assert np.allclose(c.clearance[0], half_edge_plane(c.positions[0], -0.26), rtol=0, atol=1e-15)
    s = clearance_summary(c)
    i = int(np.argmin(c.clearance[0]))
    assert s["bodies"]["floor"]["min"] == c.clearance[0, i]
    assert s["bodies"]["floor"]["s"] == c.arc_length[i]
    # the cable sags to 0.246 m: closer than 2 cm over some length, not in collision
    below = c.clearance[0] < 0.02
    assert 0 < s["length_below_min"] < 1.0 and below.any()
    assert s["length_in_collision"] == 0.0
    path = res.save(tmp_path / "r.h5")
    back = load_result(path).cable
    assert np.array_equal(back.clearance, c.clearance)
    assert back.surroundings.bodies == ["floor"] and back.surroundings.min_clearance == 0.02

    import tomli_w

    (tmp_path / "s.toml").write_text(tomli_w.dumps(d))
    out = CliRunner().invoke(app, ["run", str(tmp_path / "s.toml"), "-q"])
    assert out.exit_code == 0, out.output
    assert "clearance to the surroundings" in out.output
    assert "closer than min_clearance = 0.02 m" in out.output
    assert "min clearance [m]" in out.output


def test_clearance_reports_progress_and_stops_on_request(scene_dict, monkeypatch, tmp_path):
    """The clearance says how far it is (``progress("clearance of <cable>", done, total)``),
    and a stop request while it runs (Ctrl-C, ``interrupt.request_stop``) ends the call with
    the whole run kept, without the clearance (SimulationError: interrupted)."""
    from cablelife import interrupt
    from cablelife.simulate import CLEARANCE_INTERRUPTED, SimulationError, simulate
    from cablelife.surroundings import clearance as clearance_module

    d = copy.deepcopy(scene_dict)
    d["bodies"] = [
        {
            "name": "floor",
            "geometry": [{"shape": "plane", "point": [0, 0, -0.26], "normal": [0, 0, 1]}],
        }
    ]
    d["simulation"] |= {"mode": "dynamic", "duration": 0.05, "time_step": 0.001}
    sc = scene_from_dict(d)
    reports = []
    res = simulate(sc, progress=lambda what, k, n: reports.append((what, k, n)))
    steps = res.cable.n_steps
    mine = [r for r in reports if r[0] == "clearance of hose"]
    assert mine and mine[-1] == ("clearance of hose", steps, steps), reports[-3:]
    assert all(r[2] == steps and 0 <= r[1] <= steps for r in mine)

    # asked to stop once the clearance starts (the body maps are its first step)
    maps = clearance_module.body_maps

    def stop_then_maps(*args):
        interrupt.request_stop()
        return maps(*args)

    def stopped_run() -> SimulationError:
        try:
            with pytest.raises(SimulationError) as err:
                simulate(sc)
        finally:
            interrupt.reset()
        return err.value

    monkeypatch.setattr(clearance_module, "body_maps", stop_then_maps)
    err = stopped_run()
    assert err.interrupted and "without the clearance" in err.kept
    stopped = err.result
    assert stopped.complete is False and stopped.message == CLEARANCE_INTERRUPTED
    assert stopped.cable.n_steps == steps  # every step of the run kept
    assert stopped.cable.surroundings is None and stopped.cable.clearance is None
    assert np.array_equal(stopped.cable.positions, res.cable.positions)

    # the command line: exit 130, the run saved without the clearance, and says so
    import tomli_w
    from cablelife.cli import app
    from cablelife.results import load_result
    from typer.testing import CliRunner

    scene_file = tmp_path / "s.toml"
    scene_file.write_text(tomli_w.dumps(d))
    try:
        out = CliRunner().invoke(app, ["run", str(scene_file), "-q", "-o", str(tmp_path / "r.h5")])
    finally:
        interrupt.reset()
    assert out.exit_code == interrupt.EXIT_CODE, out.output
    text = " ".join(out.output.split())
    assert "every step of the run, without the clearance" in text, text
    assert "interrupted: the clearance was not computed" in text, text
    from cablelife.resultcheck import PartialResultWarning

    with pytest.warns(PartialResultWarning, match="clearance was not computed .every step"):
        back = load_result(tmp_path / "r.h5")
    assert back.complete is False and back.message == CLEARANCE_INTERRUPTED
    assert back.cable.n_steps == steps and back.cable.clearance is None

    # a run that failed before (here: a strain error) keeps saying so
    import sys

    # (the package's attribute `simulate` is the function, not the module)
    simulate_module = sys.modules["cablelife.simulate"]
    monkeypatch.setattr(simulate_module, "_check_strains", lambda *a: ["cable 'hose': too long"])
    err = stopped_run()
    assert err.interrupted and "before the failure" in err.kept
    assert err.result.message == (
        "interrupted: the clearance was not computed; cable 'hose': too long"
    )


def test_a_failing_clearance_progress_callback_is_an_error_not_an_interruption(scene_dict):
    sc = scene_with(
        scene_dict,
        [
            {
                "name": "floor",
                "geometry": [{"shape": "plane", "point": [0, 0, -1], "normal": [0, 0, 1]}],
            }
        ],
    )
    env = load_surroundings(sc)
    positions = np.zeros((4, 5, 3))
    maps = np.zeros((1, 4, 3, 4))
    maps[0, :, :, :3] = np.eye(3)

    def broken(done, total):
        raise ValueError("display gone")

    with pytest.raises(RuntimeError, match="progress callback failed: ValueError: display gone"):
        env.core.clearance(positions, RADIUS, maps, broken)
    calls = []
    value, _ = env.core.clearance(positions, RADIUS, maps, lambda k, n: calls.append((k, n)))
    assert calls[-1] == (4, 4) and np.allclose(value, 1.0 - RADIUS)


# ---------------------------------------------------------------------------- bad meshes


def mesh_scene(scene_dict, tmp_path, name, **part):
    return scene_with(
        scene_dict, [{"name": "engine", "geometry": [{"mesh": name, **part}]}], base_dir=tmp_path
    )


def test_missing_unreadable_empty(scene_dict, tmp_path):
    with pytest.raises(
        SceneError, match=r"bodies\[0\]\.geometry\[0\].*engine/mesh#0.*does not exist"
    ):
        load_surroundings(mesh_scene(scene_dict, tmp_path, "nope.stl"))
    (tmp_path / "bad.stl").write_bytes(b"\x00\x01garbage" * 3)
    with pytest.raises(SceneError, match="cannot read mesh file|no triangles"):
        load_surroundings(mesh_scene(scene_dict, tmp_path, "bad.stl"))
    (tmp_path / "empty.stl").write_text("solid empty\nendsolid empty\n")
    with pytest.raises(SceneError, match="no triangles|cannot read"):
        load_surroundings(mesh_scene(scene_dict, tmp_path, "empty.stl"))
    with pytest.raises(SceneError, match="unknown type; allowed: .stl, .obj, .ply"):
        mesh_scene(scene_dict, tmp_path, "engine.step")
    with pytest.raises(SceneError, match="friction"):
        scene_with(
            scene_dict,
            [
                {
                    "name": "e",
                    "geometry": [
                        {"shape": "sphere", "center": [0, 0, 0], "radius": 1, "friction": -0.1}
                    ],
                }
            ],
        )
    with pytest.raises(SceneError, match="needs mesh = 'file' or shape"):
        scene_with(scene_dict, [{"name": "e", "geometry": [{"shape": "cone"}]}])


def test_degenerate_triangles(scene_dict, tmp_path):
    ico = trimesh.creation.icosphere(subdivisions=2, radius=0.1)
    v, f = ico.vertices, ico.faces
    extra = np.array([[f[0, 0], f[0, 0], f[0, 1]], [f[1, 0], f[2, 1], f[1, 0]]])
    trimesh.Trimesh(v, np.vstack([f, extra]), process=False).export(tmp_path / "deg.ply")
    with pytest.warns(SurroundingsWarning, match="dropped 2 degenerate"):
        env = load_surroundings(mesh_scene(scene_dict, tmp_path, "deg.ply"))
    assert env.meshes[0][2].shape == (len(f), 3)
    many = np.vstack([f] + [extra] * 40)
    trimesh.Trimesh(v, many, process=False).export(tmp_path / "deg2.ply")
    with pytest.raises(SceneError, match=r"80 of \d+ triangles .* are degenerate"):
        load_surroundings(mesh_scene(scene_dict, tmp_path, "deg2.ply"))


def test_millimetres_and_scale(scene_dict, tmp_path):
    ico = trimesh.creation.icosphere(subdivisions=2, radius=100.0)  # 100 mm
    ico.apply_translation([500, 300, 0])
    ico.export(tmp_path / "mm.obj")
    with pytest.raises(SceneError, match="probably in millimetres; give scale = 0.001"):
        load_surroundings(mesh_scene(scene_dict, tmp_path, "mm.obj"))
    env = load_surroundings(mesh_scene(scene_dict, tmp_path, "mm.obj", scale=0.001))
    d = env.core.project_points(0, np.array([[0.5, 0.3, 0.3]]))["distance"]
    assert 0.2 - 1e-3 < d[0] <= 0.2 + 1e-12


def test_open_and_inverted_meshes(scene_dict, tmp_path):
    ico = trimesh.creation.icosphere(subdivisions=3, radius=0.1)
    keep = ico.triangles_center[:, 2] > 0
    upper = trimesh.Trimesh(ico.vertices, ico.faces[keep])
    upper.export(tmp_path / "dome.stl")
    with pytest.warns(SurroundingsWarning, match=r"open \(\d+ boundary edges\).*outside"):
        env = load_surroundings(mesh_scene(scene_dict, tmp_path, "dome.stl"))
    # the side the normals point to is outside: above the dome positive, under it negative
    d = env.core.project_points(0, np.array([[0, 0, 0.15], [0, 0, 0.05]]))["distance"]
    assert d[0] > 0.04 and d[1] < -0.04
    inverted = trimesh.Trimesh(ico.vertices, ico.faces[:, ::-1])
    inverted.export(tmp_path / "inv.stl")
    with pytest.warns(SurroundingsWarning, match="face inwards; flipped"):
        env = load_surroundings(mesh_scene(scene_dict, tmp_path, "inv.stl"))
    d = env.core.project_points(0, np.array([[0, 0, 0.0]]))["distance"]
    assert d[0] < -0.09


def test_scene_without_geometry_has_no_clearance(scene_dict):
    from cablelife.simulate import simulate

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        res = simulate(scene_from_dict(scene_dict))
    assert res.cable.clearance is None and res.cable.surroundings is None


def test_environment_docs_example(tmp_path):
    """The Python example of docs/environment.md runs as written."""
    import re
    import subprocess
    import sys
    from pathlib import Path

    text = (Path(__file__).resolve().parents[1] / "docs" / "environment.md").read_text()
    code = re.search(r"```python\n(.*?)```", text, re.S).group(1)
    proc = subprocess.run(
        [sys.executable, "-c", code], cwd=tmp_path, capture_output=True, text=True
    )
    assert proc.returncode == 0, proc.stderr
    assert "least clearance" in proc.stdout and "floor/stone" in proc.stdout


def test_example_scene(tmp_path):
    """The example generates its STL files and runs with clearance on."""
    import shutil
    import subprocess
    import sys
    from pathlib import Path

    from cablelife.scene import load_scene
    from cablelife.simulate import simulate

    src = Path(__file__).resolve().parents[1] / "examples" / "surroundings"
    shutil.copy(src / "hose-near-engine.toml", tmp_path)
    proc = subprocess.run(
        [sys.executable, str(src / "make_geometry.py"), str(tmp_path)],
        capture_output=True,
        text=True,
    )
    assert proc.returncode == 0, proc.stderr
    for name in ("engine.stl", "bracket.stl"):  # the committed files are the generated ones
        assert (tmp_path / name).read_bytes() == (src / name).read_bytes()
    sc = load_scene(tmp_path / "hose-near-engine.toml")
    sc.simulation.duration = 0.2
    c = simulate(sc, mode="quasistatic").cable
    assert c.surroundings.bodies == ["engine", "car-body"]
    assert 0 < c.clearance.min() < 0.02  # near the bracket, not through it


def test_display_geometry_follows_the_bodies_and_goes_to_paraview(scene_dict, tmp_path):
    """The result keeps each body's display mesh and poses: the pose of the engine body maps
    the clip's rest position onto the cable end it holds; ParaView gets the bodies per step."""
    import xml.etree.ElementTree as ET

    from cablelife.export.cli import paraview_command
    from cablelife.results import load_result
    from cablelife.simulate import simulate

    d = copy.deepcopy(scene_dict)
    d["simulation"].update(mode="quasistatic", duration=0.5, time_step=0.05)
    turn = {
        "channel": "rz",
        "frame": "global",
        "signal": {"type": "table", "t": [0, 0.5], "value": [0, 0.3]},
    }
    d["bodies"] = [
        {
            "name": "engine",
            "origin": [0.9, 0.2, 0.0],
            "motion": [turn],
            "geometry": [{"shape": "box", "center": [1.0, 0.2, -0.1], "size": [0.1, 0.1, 0.1]}],
        },
        {
            "name": "floor",
            "geometry": [{"shape": "plane", "point": [0, 0, -0.5], "normal": [0, 0, 1]}],
        },
    ]
    d["cables"][0]["clips"][1]["body"] = "engine"
    res = simulate(scene_from_dict(d))
    path = res.save(tmp_path / "r.h5")
    geom = load_result(path).surroundings
    assert geom.bodies == ["engine", "floor"]
    end = np.array([0.8, 0.2, 0.0])  # clip b at rest, on the engine
    pose = geom.poses[0]
    moved = np.einsum("tij,j->ti", pose[..., :3], end) + pose[..., 3]
    assert np.allclose(moved, res.cable.positions[:, -1], rtol=0, atol=1e-9)
    assert np.ptp(moved[:, 1]) > 0.02  # it did move
    assert np.allclose(geom.poses[1, :, :, :3], np.eye(3)) and not geom.poses[1, :, :, 3].any()
    paraview_command(path, tmp_path / "pv" / "run.pvd", None, 5, None)
    index = ET.parse(tmp_path / "pv" / "run_bodies.pvd").getroot()
    files = [e.get("file") for e in index.iter("DataSet")]
    assert len(files) == 2 * 3  # two bodies, steps 0, 5, 10
    last = ET.parse(tmp_path / "pv" / files[2]).getroot()
    pts = np.array(last.find(".//Points/DataArray").text.split(), float).reshape(-1, 3)
    assert np.allclose(pts, geom.at(0, 10), atol=1e-8)
    cable = ET.parse(tmp_path / "pv" / "run" / "run_00010.vtp").getroot()
    names = [a.get("Name") for a in cable.iter("DataArray")]
    assert "clearance" in names and "clearance_body" in names


def _signed_volume(v, f):
    a, b, c = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
    return float(np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6)


def test_primitive_display_meshes_are_closed_outward_and_on_the_surface():
    """The solids' display meshes (numpy, without importing trimesh): watertight with
    consistent winding, normals outward (positive signed volume: exact for the box and the
    48-sided prism, the inscribed polyhedron's for the sphere), vertices on the surface, and
    the extents of trimesh.creation's meshes of the same parts."""
    from cablelife.rotations import euler_matrix
    from cablelife.surroundings.display import box_mesh, cylinder_mesh, sphere_mesh

    c = np.array([0.4, -0.2, 0.1])
    rot = euler_matrix([0.3, -0.2, 0.5])
    size = np.array([0.1, 0.2, 0.3])
    v, f = box_mesh(c, rot, size)
    assert _signed_volume(v, f) == pytest.approx(np.prod(size), rel=1e-12)
    local = (v - c) @ rot
    np.testing.assert_allclose(np.abs(local), np.broadcast_to(size / 2, v.shape), rtol=1e-12)
    t = np.eye(4)
    t[:3, :3], t[:3, 3] = rot, c
    ref = trimesh.creation.box(extents=size, transform=t)
    np.testing.assert_allclose(np.sort(v, axis=0), np.sort(ref.vertices, axis=0), atol=1e-15)
    meshes = [(v, f)]

    axis, r, length = np.array([0.2, 1.0, 0.3]), 0.02, 0.3
    v, f = cylinder_mesh(c, axis, r, length)
    n = 48
    assert _signed_volume(v, f) == pytest.approx(n / 2 * np.sin(2 * np.pi / n) * r * r * length)
    a = axis / np.linalg.norm(axis)
    along = (v - c) @ a
    radial = np.linalg.norm((v - c) - along[:, None] * a, axis=1)
    assert np.allclose(np.abs(along), length / 2)
    assert np.allclose(radial[:-2], r) and np.allclose(radial[-2:], 0.0, atol=1e-15)
    t = np.eye(4)
    t[:3, :3] = trimesh.geometry.align_vectors([0, 0, 1], a)[:3, :3]
    t[:3, 3] = c
    ref = trimesh.creation.cylinder(radius=r, height=length, sections=n, transform=t)
    assert ref.volume == pytest.approx(_signed_volume(v, f), rel=1e-12)
    meshes.append((v, f))

    v, f = sphere_mesh(c, 0.03)
    assert np.allclose(np.linalg.norm(v - c, axis=1), 0.03)
    exact = 4 / 3 * np.pi * 0.03**3
    assert 0.97 * exact < _signed_volume(v, f) < exact  # inscribed: a little less
    np.testing.assert_allclose(v.min(axis=0), c - 0.03, atol=1e-4)  # poles on z; ≤ 1 − cos(π/32)
    np.testing.assert_allclose(v.max(axis=0), c + 0.03, atol=1e-4)
    meshes.append((v, f))
    for v, f in meshes:
        m = trimesh.Trimesh(v, f, process=False)
        assert m.is_watertight and m.is_winding_consistent and m.volume > 0


def test_primitives_need_no_trimesh(scene_dict):
    """Loading surroundings of analytic parts only (and their display meshes) does not import
    trimesh (0.3–0.5 s with scipy.spatial; a quarter of a small run)."""
    import json
    import subprocess
    import sys

    parts = [
        {"shape": "box", "center": [0.3, 0, -0.1], "size": [0.1, 0.1, 0.1]},
        {"shape": "cylinder", "center": [0.3, 0, -0.3], "axis": [0, 1, 0], "radius": 0.02,
         "length": 0.2},
        {"shape": "sphere", "center": [0.5, 0, -0.2], "radius": 0.03},
        {"shape": "plane", "point": [0, 0, -0.6], "normal": [0, 0, 1]},
    ]  # fmt: skip
    scene = copy.deepcopy(scene_dict)
    scene["bodies"] = [{"name": "frame", "geometry": parts}]
    code = (
        "import json, sys\nfrom cablelife.scene import scene_from_dict\n"
        "from cablelife.surroundings.build import load_surroundings\n"
        f"env = load_surroundings(scene_from_dict(json.loads({json.dumps(json.dumps(scene))})))\n"
        "assert len(env.display_meshes()) == 1 and len(env.meshes) == 4\n"
        "print(json.dumps(sorted(sys.modules)))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    loaded = json.loads(out.stdout.strip().splitlines()[-1])
    assert "trimesh" not in loaded and "scipy.spatial" not in loaded


def test_decimation_for_display():
    from cablelife.surroundings.display import decimate

    ico = trimesh.creation.icosphere(subdivisions=6, radius=1.0)  # 81 920 triangles
    v, f = decimate(np.asarray(ico.vertices), np.asarray(ico.faces), 20_000)
    assert 5_000 < len(f) <= 20_000
    assert f.max() < len(v)
    r = np.linalg.norm(v, axis=1)
    assert r.min() > 0.95 and r.max() <= 1.0 + 1e-12  # still the sphere


def test_decimation_takes_few_passes(monkeypatch):
    # the triangles of a surface scale with the square of the cells across the grid: from the
    # first pass's count the grid is coarsened by that estimate, so a 327 680-triangle sphere
    # comes down to the 20 000 allowed in two or three passes (×0.7 per pass took six)
    from cablelife.surroundings import display

    passes = []
    real = display.next_cells

    def counted(faces, max_faces):
        passes.append(faces)
        return real(faces, max_faces)

    monkeypatch.setattr(display, "next_cells", counted)
    ico = trimesh.creation.icosphere(subdivisions=7, radius=1.0)
    v, f = display.decimate(np.asarray(ico.vertices), np.asarray(ico.faces), 20_000)
    assert len(passes) <= 2, passes
    assert 0.8 * 20_000 < len(f) <= 20_000


def test_decimation_equals_the_row_unique_clustering():
    # the packed-key clustering gives exactly what np.unique over rows and np.add.at give
    from cablelife.surroundings.display import _unique_rows, decimate, next_cells

    def reference(vertices, faces, max_faces):
        lo = vertices.min(axis=0)
        extent = float(np.ptp(vertices, axis=0).max())
        cells = 2.0 * np.sqrt(max_faces)
        while True:
            key = np.floor((vertices - lo) / (extent / cells)).astype(np.int64)
            _, inverse, counts = np.unique(key, axis=0, return_inverse=True, return_counts=True)
            inverse = inverse.ravel()
            sums = np.zeros((counts.size, 3))
            np.add.at(sums, inverse, vertices)
            v = sums / counts[:, None]
            f = inverse[faces]
            keep = (f[:, 0] != f[:, 1]) & (f[:, 1] != f[:, 2]) & (f[:, 0] != f[:, 2])
            f = np.unique(f[keep], axis=0)
            if len(f) <= max_faces or cells < 4:
                used, f = np.unique(f, return_inverse=True)
                return v[used], f.reshape(-1, 3)
            cells *= next_cells(len(f), max_faces)

    ico = trimesh.creation.icosphere(subdivisions=5, radius=0.3)  # 20 480 triangles
    ico.apply_transform(trimesh.transformations.rotation_matrix(0.3, [1, 2, 3]))
    v0, f0 = np.asarray(ico.vertices) + [5.0, -2.0, 1.0], np.asarray(ico.faces)
    for m in (3_000, 500):
        v, f = decimate(v0, f0, m)
        rv, rf = reference(v0, f0, m)
        assert np.array_equal(f, rf) and np.allclose(v, rv, rtol=0, atol=1e-15)
    rows = np.random.default_rng(1).integers(0, 7, size=(500, 3))
    first, inverse, counts = _unique_rows(rows)
    u, rfirst, rinv, rcounts = np.unique(
        rows, axis=0, return_index=True, return_inverse=True, return_counts=True
    )
    assert np.array_equal(rows[first], u) and np.array_equal(inverse, rinv.ravel())
    assert np.array_equal(counts, rcounts)


def test_report_has_the_clearance_section(scene_dict, tmp_path):
    from cablelife.cli import app
    from cablelife.simulate import simulate
    from typer.testing import CliRunner

    d = copy.deepcopy(scene_dict)
    d["bodies"] = [
        {
            "name": "floor",
            "geometry": [{"shape": "plane", "point": [0, 0, -0.26], "normal": [0, 0, 1]}],
        }
    ]
    d["clearance"] = {"min_clearance": 0.02}
    path = simulate(scene_from_dict(d)).save(tmp_path / "r.h5")
    out = CliRunner().invoke(
        app, ["report", str(path), "-o", str(tmp_path / "r.html"), "--voxel", "none"]
    )
    assert out.exit_code == 0, out.output
    html = (tmp_path / "r.html").read_text()
    assert "clearance of hose to the surroundings" in html
    assert "clearance of hose along the cable" in html  # the envelope figure
    assert "least clearance" in html and "floor/plane#0" in html
    # the clearance in 3D is a view of the run's 3D view (one WebGL scene), not a scene of its
    # own: its button shows the clearance tube and the floor, nothing of the other views
    from cablelife.report.page import unpack

    figs = unpack(html)
    views = [
        f for f in figs if any(m.get("name") == "views" for m in f["layout"].get("updatemenus", []))
    ]
    assert len(views) == 1 and sum("scene" in f["layout"] for f in figs) == 1
    (menu,) = [m for m in views[0]["layout"]["updatemenus"] if m.get("name") == "views"]
    labels = [b["label"] for b in menu["buttons"]]
    assert len(labels) == 2 and labels[1].startswith("clearance at t = ")
    shown = menu["buttons"][1]["args"][0]["visible"]
    names = [t.get("name") for t, v in zip(views[0]["data"], shown, strict=True) if v]
    assert names == ["hose: clearance", "floor"]
    assert not any(menu["buttons"][0]["args"][0]["visible"][-2:])
    # and the page as a person sees it: every figure drawn, no script error, no text overprinted
    from cablelife.report.browser import check_page, find_browser

    if find_browser() is None:
        pytest.skip("chromium not found (Debian package 'chromium')")
    seen = check_page(tmp_path / "r.html")
    assert seen.errors == [] and seen.rendered == seen.expected == len(figs)
    assert seen.overlaps == [], seen.overlaps
    assert seen.clipped == [], seen.clipped


def test_report_arrays_of_text_go_as_lists():
    """Arrays of objects (customdata with body names) are sent as plain lists: a typed array
    of dtype "O" made plotly.js refuse the clearance figure."""
    from cablelife.report.decimate import compact

    d = compact({"customdata": np.array([[0.5, "engine"], [1.5, "floor"]], dtype=object),
                 "x": np.array([0.0, 1.0])})  # fmt: skip
    assert d["customdata"] == [[0.5, "engine"], [1.5, "floor"]]
    assert d["x"]["dtype"] == "f4"


def test_motion_volume_against_the_bodies(scene_dict, monkeypatch):
    """A straight cable through a 0.1 m thick box: the volume inside is the tube's
    π r² · 0.1 m (to the voxel resolution), the least distance the node depth."""
    from cablelife.simulate import simulate
    from cablelife.surroundings.volume import volume_vs_surroundings

    d = copy.deepcopy(scene_dict)
    d["simulation"]["gravity"] = [0, 0, 0]
    d["cables"][0]["clips"][1]["position"] = [1.0, 0.0, 0.0]
    d["bodies"] = [
        {
            "name": "wall",
            "geometry": [{"shape": "box", "center": [0.5, 0, 0], "size": [0.1, 0.2, 0.2]}],
        },
        {"name": "far", "geometry": [{"shape": "sphere", "center": [0.5, 0.3, 0], "radius": 0.1}]},
    ]
    res = simulate(scene_from_dict(d))
    wall, far = volume_vs_surroundings(res, voxel=0.0005)
    assert wall.min_distance == pytest.approx(-0.05 - RADIUS, abs=1e-12)
    exact = math.pi * RADIUS**2 * 0.1
    assert wall.intersection == pytest.approx(exact, rel=0.03)
    assert far.intersection == 0.0 and far.min_distance == pytest.approx(0.2 - RADIUS, abs=2e-4)
    # Both bodies are at rest: given the motion volume (same voxel, all cables and steps) the
    # check uses its field and finds exactly the same.
    import cablelife.volume.field as field
    from cablelife.volume.motion import motion_volume

    mv = motion_volume(res, 0.0005)
    calls = []
    plain = field.signed_distance
    monkeypatch.setattr(field, "signed_distance", lambda *a, **k: calls.append(1) or plain(*a, **k))
    assert volume_vs_surroundings(res, 0.0005, motion=mv) == [wall, far] and not calls


def test_dynamic_run_uses_the_saved_steps(scene_dict):
    """Dynamic run saving every 10th step: the clearance of saved step k sees the floor where
    its body is at the saved time t_k (a lift of 0.1 m/s, geometry only: no clip on it)."""
    from cablelife.simulate import simulate

    d = copy.deepcopy(scene_dict)
    d["simulation"].update(mode="dynamic", duration=0.1, time_step=0.001, output_step=0.01)
    lift = {
        "channel": "z",
        "frame": "global",
        "signal": {"type": "table", "t": [0, 1], "value": [0, 0.1]},
    }
    d["bodies"] = [
        {
            "name": "floor",
            "motion": [lift],
            "geometry": [{"shape": "plane", "point": [0, 0, -0.3], "normal": [0, 0, 1]}],
        }
    ]
    c = simulate(scene_from_dict(d)).cable
    assert c.clearance.shape == (c.n_steps, 41) and c.n_steps == 11
    for k, t in enumerate(c.time):
        expected = half_edge_plane(c.positions[k], -0.3 + 0.1 * t)
        assert np.allclose(c.clearance[k], expected, rtol=0, atol=1e-14)


def test_vertex_welding_equals_the_rounded_rows_first_appearance():
    """`merge_vertices` (Rust, one hash-map pass) against numpy: the unique rows of the
    coordinates rounded to 8 decimals (ties to even), in order of first appearance, faces
    re-indexed — on a soup with exact repeats, noise below and above the rounding, −0.0, and
    coordinates beyond 9e10 (merged only when equal)."""
    from cablelife.surroundings import meshes

    rng = np.random.default_rng(7)
    base = rng.normal(size=(2000, 3))
    picks = rng.integers(0, len(base), size=(30000,))
    noise = rng.choice([0.0, 0.0, 3e-9, -4e-9, 2e-8], size=(len(picks), 3))
    v = base[picks] + noise
    v[::97, 2] = -0.0
    faces = rng.integers(0, len(v), size=(10000, 3))

    def reference(v, faces, exact=False):
        q = (v + 0.0).view(np.int64) if exact else np.rint(v * 1e8).astype(np.int64)
        _, first, inverse = np.unique(q, axis=0, return_index=True, return_inverse=True)
        order = np.argsort(first, kind="stable")
        rank = np.empty_like(order)
        rank[order] = np.arange(len(order))
        return v[first[order]], rank[inverse.reshape(-1)][faces]

    for vv, exact in ((v, False), (v * 1e11, True)):
        got_v, got_f = meshes.merge_vertices(vv, faces)
        ref_v, ref_f = reference(vv, faces, exact)
        assert np.array_equal(got_v, ref_v) and np.array_equal(got_f, ref_f)
        assert len(ref_v) < len(vv)
    with pytest.raises(ValueError, match="face 0 indexes vertex 30000"):
        meshes.merge_vertices(v, np.array([[0, 1, 30000]]))


def test_vectorised_mesh_reading_equals_trimesh(tmp_path):
    """The STL path (trimesh's reader, vertices merged and checked here) against trimesh's own
    processing: the same merged vertices and faces (up to vertex order), watertightness,
    boundary edges, orientation and shells."""
    from cablelife.surroundings import meshes

    a = trimesh.creation.icosphere(subdivisions=3, radius=0.1)
    b = trimesh.creation.torus(major_radius=0.2, minor_radius=0.05)
    b.apply_translation([0.16, 0.01, 0.0])  # overlaps a: two shells
    two = trimesh.util.concatenate([a, b])
    two.export(tmp_path / "two.stl")
    keep = a.triangles_center[:, 2] > 0.02
    trimesh.Trimesh(a.vertices, a.faces[keep]).export(tmp_path / "cap.stl")
    trimesh.Trimesh(b.vertices, b.faces[:, ::-1]).export(tmp_path / "inv.stl")

    def same(m, ref):
        tris = np.sort(m.vertices[m.faces].reshape(len(m.faces), -1), axis=0)
        ref_tris = np.sort(ref.vertices[ref.faces].reshape(len(ref.faces), -1), axis=0)
        assert len(m.vertices) == len(ref.vertices)
        assert np.array_equal(tris, ref_tris)

    m = meshes.load_mesh(tmp_path / "two.stl", None, "t", 1.0)
    ref = trimesh.load(tmp_path / "two.stl", process=True)
    same(m, ref)
    assert m.watertight and ref.is_watertight and m.boundary_edges == 0
    assert len(m.shells) == ref.body_count == 2
    assert sorted(len(s) for s in m.shells) == sorted([len(a.faces), len(b.faces)])
    with pytest.warns(SurroundingsWarning, match=r"open \((\d+) boundary edges\)") as w:
        m = meshes.load_mesh(tmp_path / "cap.stl", None, "t", 1.0)
    ref = trimesh.load(tmp_path / "cap.stl", process=True)
    same(m, ref)
    n_boundary = len(trimesh.grouping.group_rows(ref.edges_sorted, require_count=1))
    assert m.boundary_edges == n_boundary > 0 and f"({n_boundary} boundary" in str(w[0].message)
    assert not m.watertight and m.shells is None
    with pytest.warns(SurroundingsWarning, match="face inwards; flipped"):
        m = meshes.load_mesh(tmp_path / "inv.stl", None, "t", 1.0)
    tri = m.vertices[m.faces]
    volume = np.einsum("ij,ij->", tri[:, 0], np.cross(tri[:, 1], tri[:, 2])) / 6
    assert volume == pytest.approx(b.volume, rel=1e-6)


def test_queries_of_non_finite_points_are_named():
    """The surroundings' point and segment queries refuse a non-finite row with its index (no
    answer exists; before, a Rust panic), for primitives and meshes alike."""
    s = _core.Surroundings()
    s.add_sphere(0, [0.0, 0.0, 0.0], 1.0)
    tri = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
    s.add_mesh(0, tri, np.array([[0, 1, 2]]))
    ok = np.array([[0.0, 0.0, 2.0]])
    for part in (0, 1):
        assert np.isfinite(s.project_points(part, ok)["distance"]).all()
        with pytest.raises(ValueError, match=r"points: row 1 \[NaN"):
            s.project_points(part, np.array([[0.0, 0.0, 2.0], [np.nan, 0.0, 0.0]]))
        with pytest.raises(ValueError, match=r"b: row 0 \[inf"):
            s.closest_to_segments(part, ok, np.array([[np.inf, 0.0, 0.0]]))
