"""Generated bad scenes: every leaf value of a rich scene (bodies, motions, loads, damping) and
of a scene with surroundings (geometry parts of every kind, contact, clearance) replaced by a
boolean, a NaN and 1e300. Each must give exit code 2 with the leaf's key in the
message, or (for a huge value a scene may hold) a run whose outputs are finite — never a
traceback, a panic, or a misleading solver failure (exit code 1)."""

from __future__ import annotations

import copy

import pytest
from badinput import cli, scene, write_scene


def _rich_scene() -> dict:
    d = scene()
    d["simulation"].update(mode="quasistatic", duration=0.04, time_step=0.01)
    d["bodies"] = [
        {
            "name": "engine",
            "origin": [0.8, 0.2, 0.0],
            "orientation": [0.0, 0.0, 0.1],
            "motion": [
                {
                    "channel": "z",
                    "signal": {
                        "type": "sine",
                        "amplitude": 0.01,
                        "frequency": 2.0,
                        "phase": 0.1,
                        "offset": 0.001,
                        "fade_in": 0.01,
                    },
                }
            ],
        }
    ]
    cable = d["cables"][0]
    cable["clips"][1].update(body="engine", length=0.02, s=0.99)
    cable["loads"] = [{"s": 0.5, "force": [0.0, 0.0, -1.0], "moment": [0.0, 0.01, 0.0]}]
    cable["damping"] = {"ratio": 0.5}
    cable["natural_curvature"] = [0.1, 0.0, 0.0]
    return d


# A tetrahedron (ASCII STL, metres; 30 cm above the hose) for the mesh part of the
# surroundings scene.
TETRAHEDRON = """solid t
facet normal 0 0 -1
outer loop
vertex 0.4 -0.3 0.3
vertex 0.4 -0.2 0.3
vertex 0.5 -0.3 0.3
endloop
endfacet
facet normal 0 -1 0
outer loop
vertex 0.4 -0.3 0.3
vertex 0.5 -0.3 0.3
vertex 0.4 -0.3 0.4
endloop
endfacet
facet normal -1 0 0
outer loop
vertex 0.4 -0.3 0.3
vertex 0.4 -0.3 0.4
vertex 0.4 -0.2 0.3
endloop
endfacet
facet normal 0.577 0.577 0.577
outer loop
vertex 0.5 -0.3 0.3
vertex 0.4 -0.2 0.3
vertex 0.4 -0.3 0.4
endloop
endfacet
endsolid t
"""


def _surroundings_scene() -> dict:
    """The hose over a table, between a box, a cylinder, a sphere and a mesh (all out of its
    way but for the table), contact with friction on, a clearance limit."""
    d = scene()
    d["simulation"].update(mode="quasistatic", duration=0.02, time_step=0.01)
    d["bodies"] = [
        {
            "name": "engine",
            "origin": [0.8, 0.2, 0.0],
            "motion": [
                {"channel": "z", "signal": {"type": "sine", "amplitude": 0.01, "frequency": 1.0}}
            ],
            "geometry": [
                {
                    "shape": "box",
                    "center": [0.9, 0.5, 0.0],
                    "size": [0.1, 0.1, 0.1],
                    "orientation": [0.0, 0.0, 0.3],
                    "friction": 0.4,
                },
                {"mesh": "part.stl", "scale": 1.0, "name": "block"},
            ],
        },
        {
            "name": "car-body",
            "geometry": [
                {"shape": "plane", "point": [0.0, 0.0, -0.05], "normal": [0.0, 0.0, 1.0]},
                {
                    "shape": "cylinder",
                    "center": [0.4, 0.5, 0.0],
                    "axis": [0.0, 0.0, 1.0],
                    "radius": 0.02,
                    "length": 0.2,
                },
                {"shape": "sphere", "center": [0.4, -0.5, 0.0], "radius": 0.05, "frame": "body"},
            ],
        },
    ]
    d["cables"][0]["clips"][1]["body"] = "engine"
    d["contact"] = {
        "enabled": True,
        "friction": 0.3,
        "distance": 5e-5,
        "stiffness": 0.0,
        "stick_distance": 5e-6,
        "stick_velocity": 1e-3,
        "damping": 5e-4,
    }
    d["clearance"] = {"min_clearance": 0.01}
    return d


def _leaves(node, path=()):
    if isinstance(node, dict):
        for k, v in node.items():
            yield from _leaves(v, (*path, k))
    elif isinstance(node, list):
        for i, v in enumerate(node):
            yield from _leaves(v, (*path, i))
    elif not isinstance(node, str):
        yield path


def _key(path) -> str:
    """The key path as the messages print it: cables[0].clips[1].s."""
    text = ""
    for p in path:
        text += f"[{p}]" if isinstance(p, int) else f".{p}"
    return text.lstrip(".")


SCENES = {"rich": _rich_scene(), "surroundings": _surroundings_scene()}
VALUES = [("bool", True), ("nan", float("nan")), ("huge", 1e300)]
CASES = [
    (which, path, name, value)
    for which, base in SCENES.items()
    for path in _leaves(base)
    for name, value in VALUES
]


@pytest.mark.parametrize(
    ("which", "path", "name", "value"),
    CASES,
    ids=[f"{w}:{_key(p)}={n}" for w, p, n, _ in CASES],
)
def test_generated_bad_value(tmp_path, which, path, name, value):
    d = copy.deepcopy(SCENES[which])
    (tmp_path / "part.stl").write_text(TETRAHEDRON)
    node = d
    for p in path[:-1]:
        node = node[p]
    if isinstance(node[path[-1]], bool) and name == "bool":
        value = "yes"  # a flag set to a word, not coerced
    node[path[-1]] = value
    out = tmp_path / "out.h5"
    args = ["run", write_scene(tmp_path, d), "-q", "-o", out]
    key = _key(path)
    parts = key.split(".")  # e.g. ['cables[0]', 'clips[1]', 'position[2]']
    leaf = parts[-1].split("[")[0]  # 'position'
    if name in ("bool", "nan"):  # never a number of a scene: refused, the key named
        # (a union member may stand between the parts: cables[0].section.circle.radius)
        cli(args, (parts[0], f".{leaf}"), case=f"gen:{key}={name}")
        return
    from badinput import CASES_RUN, _nan_in
    from cablelife.cli import app
    from typer.testing import CliRunner

    CASES_RUN.append(f"gen:{key}={name}")
    res = CliRunner().invoke(app, [str(a) for a in args])
    assert res.exception is None or isinstance(res.exception, SystemExit), res.output
    assert res.exit_code in (0, 2), f"{key}={value}: exit code {res.exit_code}\n{res.output}"
    assert "Traceback" not in res.output and "panicked" not in res.output
    if res.exit_code == 2:
        named = (leaf, parts[-2] if len(parts) > 1 else leaf, "body motion")
        assert any(n in res.output for n in named), res.output
    else:
        assert _nan_in(out) is None
