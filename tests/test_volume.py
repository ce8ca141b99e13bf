"""Motion volumes: the compiled distance kernel, the analytic swept tube, comparisons, files."""

from __future__ import annotations

import copy
from math import acos, pi, sqrt

import numpy as np
import pytest
from cablelife import _core
from cablelife.export.mesh_files import read_ply, read_stl
from cablelife.volume import (
    Capsules,
    TriangleMesh,
    compare_volumes,
    motion_volume,
    tube_capsules,
)
from cablelife.volume.cli import parse_length


def brute_distance(starts, ends, radius, points):
    ab = ends - starts
    ap = points[:, None, :] - starts[None]
    l2 = np.einsum("ij,ij->i", ab, ab)
    t = np.clip(np.einsum("pij,ij->pi", ap, ab) / np.where(l2 > 0, l2, 1), 0, 1)
    d = np.linalg.norm(ap - t[..., None] * ab[None], axis=-1) - radius[None]
    return d.min(axis=1)


def random_capsules(rng, m):
    starts = rng.uniform(0, 0.1, (m, 3))
    ends = starts + rng.uniform(-0.02, 0.02, (m, 3))
    return Capsules(starts, ends, rng.uniform(0.001, 0.006, m))


def test_kernel_matches_brute_force_on_grid_and_points():
    rng = np.random.default_rng(1)
    caps = random_capsules(rng, 200)
    origin, h, shape, band = np.array([-0.01, -0.012, -0.008]), 0.0037, (33, 35, 31), 0.006
    field = _core.capsule_signed_distance(
        caps.starts, caps.ends, caps.radius, list(origin), h, list(shape), band
    )
    assert field.shape == shape and field.dtype == np.float32
    idx = np.indices(shape).reshape(3, -1).T
    want = brute_distance(caps.starts, caps.ends, caps.radius, origin + h * idx)
    np.testing.assert_allclose(field.ravel(), np.clip(want, -band, band), atol=1e-6)
    points = rng.uniform(-0.05, 0.15, (500, 3))
    np.testing.assert_allclose(
        caps.distance(points), brute_distance(caps.starts, caps.ends, caps.radius, points), 1e-12
    )


def test_kernel_rejects_bad_input_naming_the_argument():
    z = np.zeros((1, 3))
    with pytest.raises(ValueError, match=r"radius\[0\] = -1"):
        _core.capsule_distance(z, z, np.array([-1.0]), z)
    with pytest.raises(ValueError, match="spacing"):
        _core.capsule_signed_distance(z, z, np.ones(1), [0, 0, 0], -1.0, [2, 2, 2], 1.0)
    with pytest.raises(ValueError, match="starts has shape"):
        _core.capsule_distance(np.zeros((1, 2)), z, np.ones(1), z)


def union_of_translated_capsules(length, r, travel, n):
    """Exact volume of the union of n capsules (axis length ``length``, radius r) at n equally
    spaced positions along a perpendicular line of length ``travel``.

    Slices perpendicular to the axis are unions of n discs in a row; the end caps of all
    capsules together are n balls in a row. In a row, each new disc (ball) adds its area
    (volume) minus the lens it shares with its predecessor: its overlap with earlier ones lies
    inside that lens (convexity)."""
    delta = travel / (n - 1)
    assert delta < 2 * r
    lens2 = 2 * r * r * acos(delta / (2 * r)) - delta / 2 * sqrt(4 * r * r - delta * delta)
    lens3 = pi * (4 * r + delta) * (2 * r - delta) ** 2 / 12
    disc, ball = pi * r * r, 4 / 3 * pi * r**3
    return length * (disc + (n - 1) * (disc - lens2)) + ball + (n - 1) * (ball - lens3)


def translated_tube(length=0.3, travel=0.05, n=11, nodes=16, angle=0.3, offset=0.0):
    """A straight cable along a tilted direction translated perpendicular to its axis."""
    pos = np.zeros((n, nodes, 3))
    pos[..., 0] = np.linspace(0, length, nodes)
    pos[..., 1] = np.linspace(0, travel, n)[:, None] + offset
    c, s = np.cos(angle), np.sin(angle)
    rot = np.array([[c, -s, 0], [s * 0.8, c * 0.8, 0.6], [-s * 0.6, -c * 0.6, 0.8]])
    return pos @ rot.T


def test_swept_tube_volume_converges_to_the_exact_union():
    r = 0.01
    exact = union_of_translated_capsules(0.3, r, 0.05, 11)
    errors = []
    for h in (0.004, 0.002, 0.001):
        mv = motion_volume(translated_tube(), h, radius=r)
        assert mv.mesh.is_watertight()
        err = (mv.volume - exact) / exact
        # Marching cubes puts vertices on the surface and cuts chords of at most one voxel
        # diagonal across the curved tube: error bounded by (h/r)²/4 (1 % at h = r/5).
        assert abs(err) < (h / r) ** 2 / 4, (h, err)
        errors.append(abs(err))
    # Second order: halving the voxel divides the error by about 4.
    assert errors[1] < errors[0] / 3 and errors[2] < errors[1] / 3


def test_bounding_box_and_litres():
    mv = motion_volume(translated_tube(), 0.002, radius=0.01)
    pos = translated_tube().reshape(-1, 3)
    np.testing.assert_allclose(mv.bounding_box[0], pos.min(axis=0) - 0.01)
    np.testing.assert_allclose(mv.bounding_box[1], pos.max(axis=0) + 0.01)
    assert mv.litres == pytest.approx(mv.volume * 1e3)
    mesh_box = mv.mesh.bounding_box
    assert np.all(mesh_box[0] >= mv.bounding_box[0] - 1e-9)
    assert np.all(mesh_box[1] <= mv.bounding_box[1] + 1e-9)


def test_comparison_of_shifted_sweeps():
    # B is A's sweep moved on by 4 of its 10 steps (2 cm): A ∪ B is the sweep over 15 steps.
    r, step, h = 0.01, 0.005, 0.002
    a = motion_volume(translated_tube(travel=10 * step, n=11), h, radius=r)
    b = motion_volume(translated_tube(travel=10 * step, n=11, offset=4 * step), h, radius=r)
    c = compare_volumes(a, b)
    v = c.volumes
    tol = (h / r) ** 2 / 4
    union = union_of_translated_capsules(0.3, r, 14 * step, 15)
    assert v["union"] == pytest.approx(union, rel=tol)
    assert v["a"] == pytest.approx(a.volume, rel=1e-3)
    # Set algebra on one grid: A = (A ∖ B) + (A ∩ B), A ∪ B = A + B − A ∩ B.
    assert v["a_minus_b"] + v["intersection"] == pytest.approx(v["a"], rel=0.01)
    assert v["union"] == pytest.approx(v["a"] + v["b"] - v["intersection"], rel=0.01)
    assert v["b_minus_a"] == pytest.approx(v["a_minus_b"], rel=0.02)  # mirror images
    # Each sticks out of the other by the shift; voxel samples under-estimate by ≤ √3/2 h.
    for excess in (c.a_beyond_b, c.b_beyond_a):
        assert 4 * step - np.sqrt(3) / 2 * h - 1e-9 <= excess.distance <= 4 * step + 1e-9
    assert c.hausdorff == max(c.a_beyond_b.distance, c.b_beyond_a.distance)
    same = compare_volumes(a, a)
    assert same.volumes["a_minus_b"] == 0.0 and same.hausdorff == 0.0


def test_stl_and_ply_round_trip(tmp_path):
    mv = motion_volume(translated_tube(), 0.004, radius=0.01)
    stl = mv.save(tmp_path / "v.stl")
    v, f = read_stl(stl)
    assert TriangleMesh(v, f).volume == pytest.approx(mv.volume, rel=1e-5)
    ply = mv.save(tmp_path / "v_mm.ply", unit="mm")
    v, f, _ = read_ply(ply)
    np.testing.assert_array_equal(f, mv.mesh.faces)
    np.testing.assert_allclose(v, mv.mesh.vertices * 1e3, rtol=1e-6)
    with pytest.raises(ValueError, match="suffix must be .stl or .ply"):
        mv.save(tmp_path / "v.obj")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["v.stl", "v_mm.ply"]  # no temp files


def test_bad_input_names_the_argument():
    with pytest.raises(ValueError, match="voxel = 'two'"):
        parse_length("two")
    assert parse_length("2mm") == pytest.approx(0.002)
    assert parse_length("0.5 cm") == pytest.approx(0.005)
    assert parse_length("3") == pytest.approx(0.003)
    with pytest.raises(ValueError, match="voxel = 0"):
        motion_volume(translated_tube(), 0, radius=0.01)
    with pytest.raises(ValueError, match="radius is required"):
        motion_volume(translated_tube(), 0.002)
    with pytest.raises(ValueError, match="positions has shape"):
        tube_capsules(np.zeros((3, 1, 3)), 0.01)
    with pytest.raises(ValueError, match="use a coarser voxel"):
        motion_volume(translated_tube(), 1e-6, radius=0.01)


@pytest.fixture(scope="module")
def two_runs(tmp_path_factory):
    """A quasistatic run and the same cable with a larger motion, saved to HDF5."""
    from cablelife.scene import scene_from_dict
    from cablelife.simulate import simulate
    from conftest import BASE

    paths = []
    for amplitude in (0.03, 0.06):
        d = copy.deepcopy(BASE)
        d["simulation"].update(mode="quasistatic", duration=1.0, time_step=0.05)
        sine = {"type": "sine", "amplitude": amplitude, "frequency": 1.0}
        d["bodies"] = [
            {
                "name": "engine",
                "origin": [0.8, 0.2, 0.0],
                "motion": [{"channel": "z", "signal": sine}],
            }
        ]
        d["cables"][0]["clips"][1]["body"] = "engine"
        path = tmp_path_factory.mktemp("runs") / f"run_{amplitude}.h5"
        simulate(scene_from_dict(d)).save(path)
        paths.append(path)
    return paths


def test_volume_of_a_result_and_the_cli(two_runs, tmp_path):
    import typer
    from cablelife.results import load_result
    from cablelife.volume.cli import volume_command
    from typer.testing import CliRunner

    res = load_result(two_runs[0])
    mv = motion_volume(res, 0.002)
    c = res.cable
    assert mv.mesh.is_watertight()
    # More than the tube at rest (π r² L), and it holds every node.
    assert mv.volume > pi * 0.005**2 * 1.0
    assert np.all(c.positions.reshape(-1, 3) >= mv.bounding_box[0])
    assert np.all(c.positions.reshape(-1, 3) <= mv.bounding_box[1])

    app = typer.Typer()
    app.command()(volume_command)
    out = tmp_path / "v.stl"
    run = CliRunner().invoke(
        app, [str(two_runs[0]), "--voxel", "2mm", "-o", str(out), "--compare", str(two_runs[1])]
    )
    assert run.exit_code == 0, run.output
    assert "B sticks out of A by" in run.output and out.exists()
    v, f = read_stl(out)
    assert TriangleMesh(v, f).volume == pytest.approx(mv.volume, rel=1e-5)
    bad = CliRunner().invoke(app, [str(two_runs[0]), "--voxel", "big", "-o", str(out)])
    assert bad.exit_code == 2 and "voxel = 'big'" in bad.output
