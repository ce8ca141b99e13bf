"""Body placement (docs/scene.md, Body placement): the geometry of a body given in global
coordinates moved by a rigid transform. A placed part is the same part written where the
placement puts it: clearance, contact, the result's display geometry (report, ParaView); bad
placements are named errors."""

from __future__ import annotations

import copy

import numpy as np
import pytest
from cablelife.rotations import euler_matrix
from cablelife.scene import SceneError, scene_from_dict
from cablelife.simulate import simulate
from cablelife.surroundings.build import load_surroundings
from cablelife.surroundings.clearance import cable_clearance
from cablelife.workbench.bodies import matrix_euler

pytest.importorskip("trimesh")

POSITION = np.array([0.1, -0.05, 0.02])  # m
ANGLES = [0.1, -0.2, 0.3]  # rad
ROT = euler_matrix(ANGLES)


def moved(x) -> list[float]:
    return (POSITION + ROT @ np.asarray(x, float)).tolist()


def write_obj(path, vertices, faces) -> None:
    """An OBJ file with the vertices written exactly (repr), so a moved copy is exact."""
    lines = [f"v {float(x)!r} {float(y)!r} {float(z)!r}" for x, y, z in vertices]
    lines += [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in faces]
    path.write_text("\n".join(lines) + "\n")


def parts(tmp_path, by_hand: bool) -> list[dict]:
    """A box mesh file, a sphere, a box, a cylinder: as given (``by_hand``: with the by_handment
    applied by hand: no by_handment field)."""
    import trimesh

    box = trimesh.creation.box(extents=[0.2, 0.1, 0.05])
    v = np.asarray(box.vertices) + [0.4, 0.15, -0.12]
    name = "moved.obj" if by_hand else "part.obj"
    write_obj(tmp_path / name, [moved(x) for x in v] if by_hand else v, box.faces)
    at = moved if by_hand else (lambda x: list(x))
    turn = (lambda a: (ROT @ euler_matrix(a)).tolist()) if by_hand else euler_matrix
    return [
        {"mesh": name, "name": "block"},
        {"shape": "sphere", "center": at([0.2, 0.0, -0.08]), "radius": 0.04},
        {
            "shape": "box",
            "center": at([0.6, 0.25, 0.08]),
            "size": [0.05, 0.06, 0.04],
            "orientation": matrix_euler(np.asarray(turn([0.2, 0.1, -0.3]))),
        },
        {
            "shape": "cylinder",
            "center": at([0.7, 0.1, -0.05]),
            "axis": (ROT @ [0.0, 1.0, 0.2]).tolist() if by_hand else [0.0, 1.0, 0.2],
            "radius": 0.02,
            "length": 0.1,
        },
    ]


def two_scenes(scene_dict, tmp_path, extra=None):
    """The same surroundings twice: placed by ``placement``, and written where it puts them
    (a CAD mesh on one body, primitives on another; primitives are tessellated for display in
    their own axes, so only the mesh is compared as drawn, the primitives by their clearance)."""
    out = []
    for place in (False, True):
        d = copy.deepcopy(scene_dict)
        geometry = parts(tmp_path, place)
        mesh = {"name": "engine", "origin": [0.5, 0.0, 0.0], "geometry": geometry[:1]}
        shapes = {"name": "bracket", "geometry": geometry[1:]}
        for body in (mesh, shapes):
            if not place:
                body["placement"] = {"position": POSITION.tolist(), "orientation": ANGLES}
        d["bodies"] = [mesh, shapes, *(extra or [])]
        out.append(scene_from_dict(d, base_dir=tmp_path))
    return out


def test_placed_geometry_is_the_geometry_written_where_it_is_placed(scene_dict, tmp_path):
    placed, written = two_scenes(scene_dict, tmp_path)
    assert placed.bodies[0].placement is not None and written.bodies[0].placement is None
    env_p, env_w = load_surroundings(placed), load_surroundings(written)
    (vp, fp), (vw, fw) = env_p.display_meshes()[0], env_w.display_meshes()[0]  # the mesh
    np.testing.assert_array_equal(fp, fw)
    np.testing.assert_allclose(vp, vw, atol=1e-12)
    # the clearance of a cable path passing each (placed) part
    anchors = [
        [0.0, 0.0, 0.0],
        [0.2, 0.0, -0.03],
        [0.4, 0.15, -0.08],
        [0.6, 0.25, 0.11],
        [0.7, 0.1, -0.02],
        [0.9, 0.1, 0.0],
    ]
    u = np.linspace(0.0, len(anchors) - 1, 101)
    path = np.array([np.interp(u, np.arange(len(anchors)), c) for c in np.array(anchors).T]).T
    path = np.array([moved(x) for x in path])[None]
    a = cable_clearance(env_p, placed, path, 0.005, np.array([0.0]), np.array([0]))
    b = cable_clearance(env_w, written, path, 0.005, np.array([0.0]), np.array([0]))
    np.testing.assert_allclose(a.value, b.value, atol=1e-12)
    np.testing.assert_array_equal(a.part, b.part)
    assert (a.value < 0).any() and set(np.unique(a.part)) == {0, 1, 2, 3}  # near every part
    # a run: the result's clearance and display geometry (report, ParaView) agree
    ra, rb = simulate(placed), simulate(written)
    np.testing.assert_allclose(ra.cable.clearance, rb.cable.clearance, atol=1e-12)
    np.testing.assert_allclose(ra.surroundings.at(0, 0), rb.surroundings.at(0, 0), atol=1e-12)
    assert np.abs(ra.surroundings.at(0, 0) - vp).max() < 1e-12


def test_contact_with_a_placed_table(scene_dict):
    """A hose resting on a table: the table's plane given at z = 0 and placed 2 cm down and
    tilted, against the same plane written there."""
    tilt = [0.05, 0.0, 0.0]
    r = euler_matrix(tilt)
    results = []
    for place in (True, False):
        d = copy.deepcopy(scene_dict)
        plane = {"shape": "plane", "point": [0, 0, 0], "normal": [0, 0, 1]}
        if not place:
            plane = {"shape": "plane", "point": [0, 0, -0.02], "normal": (r @ [0, 0, 1]).tolist()}
        body = {"name": "table", "geometry": [plane]}
        if place:
            body["placement"] = {"position": [0, 0, -0.02], "orientation": tilt}
        d["bodies"] = [body]
        d["contact"] = {"enabled": True}
        results.append(simulate(scene_from_dict(d)).cable)
    a, b = results
    np.testing.assert_allclose(a.positions, b.positions, atol=1e-9)
    free = simulate(scene_from_dict(scene_dict)).cable  # sags 3 cm without the table
    assert np.abs(free.positions - a.positions).max() > 5e-3  # the table holds it up


@pytest.mark.parametrize(
    ("body", "expected"),
    [
        ({"placement": {"position": [0, 0, 0]}}, "has no geometry in global coordinates"),
        (
            {
                "placement": {},
                "geometry": [
                    {"shape": "sphere", "center": [0, 0, 0], "radius": 1.0, "frame": "body"}
                ],
            },
            "body 'b' has no geometry in global coordinates",
        ),
        (
            {
                "placement": {"position": [0, 0, 2e4]},
                "geometry": [{"shape": "sphere", "center": [0, 0, -1], "radius": 0.1}],
            },
            "bodies[0].placement.position[2]: Input should be less than or equal to 10000",
        ),
        (
            {
                "placement": {"orientation": [0, "0.1", 0]},
                "geometry": [{"shape": "sphere", "center": [0, 0, -1], "radius": 0.1}],
            },
            "bodies[0].placement.orientation[1]: Input should be a valid number",
        ),
        (
            {
                "placement": {"turn": [0, 0, 0]},
                "geometry": [{"shape": "sphere", "center": [0, 0, -1], "radius": 0.1}],
            },
            "bodies[0].placement.turn: unknown key",
        ),
    ],
)
def test_bad_placements_are_named(scene_dict, body, expected):
    d = copy.deepcopy(scene_dict)
    d["bodies"] = [{"name": "b", **body}]
    with pytest.raises(SceneError) as err:
        scene_from_dict(d)
    assert expected in str(err.value)
