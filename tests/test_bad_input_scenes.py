"""Bad scenes through ``cablelife run`` / ``modes``: types, ranges, names, sizes, files.

Each case must exit with code 2 and a message naming the key path (or file) and the value,
without a traceback, a panic, an allocation failure or a silent coercion.
"""

from __future__ import annotations

import pytest
from badinput import cli, cli_subprocess, scene, write_scene


def _cable(d):
    return d["cables"][0]


def _set(path: str, value):
    """A mutation setting the dotted ``path`` (ints index lists) of the scene dict."""

    def apply(d):
        keys = [int(k) if k.isdigit() else k for k in path.split(".")]
        node = d
        for k in keys[:-1]:
            node = node.setdefault(k, {}) if isinstance(k, str) else node[k]
        node[keys[-1]] = value

    return apply


def _moving(signal: dict, time_step: float = 1e-3, mode: str = "quasistatic"):
    """Clip b on a body 'engine' moved by ``signal`` along z."""

    def apply(d):
        d["simulation"].update(mode=mode, duration=0.2, time_step=time_step)
        d["bodies"] = [{"name": "engine", "motion": [{"channel": "z", "signal": signal}]}]
        _cable(d)["clips"][1]["body"] = "engine"

    return apply


C = "cables[0]"
CLIP = "cables[0].clips[1]"
SINE = {"type": "sine", "amplitude": 0.01, "frequency": 1.0}

# (id, mutation, expected parts of the message)
SCENE_CASES = [
    # strict types: a TOML number is a number; no bool or string coercion
    ("length-bool", _set("cables.0.length", True), (f"{C}.length", "valid number", "True")),
    ("length-string", _set("cables.0.length", "1.0"), (f"{C}.length", "valid number", "'1.0'")),
    ("segments-float", _set("cables.0.segments", 2.5), (f"{C}.segments", "valid integer", "2.5")),
    ("segments-bool", _set("cables.0.segments", True), (f"{C}.segments", "valid integer")),
    ("radius-string", _set("cables.0.section.radius", "5mm"), ("radius", "'5mm'")),
    ("modulus-bool", _set("cables.0.material.youngs_modulus", True), ("youngs_modulus", "True")),
    ("density-list", _set("cables.0.material.density", [1.0]), ("density", "valid number")),
    ("poisson-string", _set("cables.0.material.poisson_ratio", "0.3"), ("poisson_ratio", "'0.3'")),
    (
        "position-2",
        _set("cables.0.clips.1.position", [0.8, 0.2]),
        (f"{CLIP}.position[2]", "missing"),
    ),
    ("position-string", _set("cables.0.clips.1.position", "0,0,0"), (f"{CLIP}.position",)),
    ("position-bool", _set("cables.0.clips.1.position", [0.8, True, 0.0]), (f"{CLIP}.position",)),
    ("direction-zero", _set("cables.0.clips.1.direction", [0, 0, 0]), ("zero vector",)),
    ("normal-parallel", _set("cables.0.clips.1.normal", [2.0, 0, 0]), ("parallel to direction",)),
    ("clip-s-string", _set("cables.0.clips.1.s", "1"), (f"{CLIP}.s", "'1'")),
    ("clip-type", _set("cables.0.clips.1.type", "nailed"), (f"{CLIP}.type", "'nailed'")),
    ("clip-frame", _set("cables.0.clips.1.frame", "local"), (f"{CLIP}.frame", "'local'")),
    ("gravity-bool", _set("simulation.gravity", True), ("simulation.gravity",)),
    ("time-step-string", _set("simulation.time_step", "1ms"), ("simulation.time_step", "'1ms'")),
    ("duration-bool", _set("simulation.duration", True), ("simulation.duration", "True")),
    ("mode-number", _set("simulation.mode", 5), ("simulation.mode", "5")),
    ("mode-unknown", _set("simulation.mode", "fast"), ("simulation.mode", "'fast'")),
    ("max-iterations-0", _set("simulation.max_iterations", 0), ("max_iterations", "0")),
    ("max-iterations-float", _set("simulation.max_iterations", 1.5), ("max_iterations", "1.5")),
    ("spectral-radius", _set("simulation.spectral_radius", 2.0), ("spectral_radius", "2.0")),
    ("newton-tolerance", _set("simulation.newton_tolerance", 1.0), ("newton_tolerance", "1.0")),
    ("poisson-range", _set("cables.0.material.poisson_ratio", 0.7), ("poisson_ratio", "0.7")),
    ("clips-table", _set("cables.0.clips", {"a": 1}), (f"{C}.clips", "list")),
    ("cables-string", lambda d: d.update(cables="hose"), ("cables", "'hose'")),
    ("simulation-number", lambda d: d.update(simulation=5), ("simulation", "5")),
    ("unknown-key", _set("cables.0.lenght", 1.0), (f"{C}.lenght", "unknown key")),
    ("missing-length", lambda d: _cable(d).pop("length"), (f"{C}.length", "required")),
    ("no-cables", lambda d: d.update(cables=[]), ("cables", "at least 1")),
    ("files-allow-string", _set("files.allow_outside", "yes"), ("files.allow_outside", "'yes'")),
    # ranges that keep the numerics meaningful (docs/scene.md, Limits)
    ("radius-tiny", _set("cables.0.section.radius", 1e-300), ("radius", "1e-300", "0.00001")),
    ("radius-huge", _set("cables.0.section.radius", 10.0), ("radius", "10.0", "less than")),
    ("radius-negative", _set("cables.0.section.radius", -0.005), ("radius", "-0.005")),
    ("modulus-huge", _set("cables.0.material.youngs_modulus", 1e300), ("youngs_modulus", "1e+300")),
    ("modulus-tiny", _set("cables.0.material.youngs_modulus", 1e-3), ("youngs_modulus", "0.001")),
    ("density-tiny", _set("cables.0.material.density", 1e-300), ("density", "1e-300")),
    ("length-huge", _set("cables.0.length", 1.7e308), (f"{C}.length", "1.7e+308")),
    ("length-tiny", _set("cables.0.length", 1e-9), (f"{C}.length", "1e-09")),
    ("length-inf", _set("cables.0.length", float("inf")), (f"{C}.length", "inf")),
    ("length-nan", _set("cables.0.length", float("nan")), (f"{C}.length", "nan")),
    ("position-huge", _set("cables.0.clips.1.position", [1e300, 0, 0]), ("position", "1e+300")),
    ("gravity-nan", _set("simulation.gravity", [0, 0, float("nan")]), ("simulation.gravity",)),
    ("gravity-huge", _set("simulation.gravity", [0, 0, -1e300]), ("simulation.gravity[2]",)),
    (
        "curvature-huge",
        _set("cables.0.natural_curvature", [1e300, 0, 0]),
        ("natural_curvature[0]", "1e+300"),
    ),
    (
        "load-huge",
        _set("cables.0.loads", [{"s": 0.5, "force": [0, 0, 1e300]}]),
        ("loads[0].force[2]", "1e+300"),
    ),
    ("segments-0", _set("cables.0.segments", 0), (f"{C}.segments", "0")),
    ("segments-negative", _set("cables.0.segments", -3), (f"{C}.segments", "-3")),
    ("segments-huge", _set("cables.0.segments", 10_000_000), (f"{C}.segments", "10000000")),
    (
        "max-segment-length-tiny",
        lambda d: (_cable(d).pop("segments"), _cable(d).update(max_segment_length=1e-9)),
        ("max_segment_length", "20000 segments"),
    ),
    (
        "tube-radii",
        _set("cables.0.section", {"shape": "tube", "outer_radius": 0.004, "inner_radius": 0.005}),
        ("inner_radius",),
    ),
    (
        "measured-EA-tiny",
        lambda d: (
            _cable(d).pop("section"),
            _cable(d).pop("material"),
            _cable(d).update(
                stiffness={
                    "EA": 1e-300,
                    "EI": 0.1,
                    "GJ": 0.1,
                    "mass_per_length": 0.1,
                    "radius": 0.005,
                }
            ),
        ),
        ("stiffness.EA", "1e-300"),
    ),
    ("segments-1", _set("cables.0.segments", 1), (f"{C}.segments", "segments = 1", "4 to 20000")),
    ("segments-2", _set("cables.0.segments", 2), (f"{C}.segments", "straight bar")),
    (
        "segments-fewer-than-intervals",
        lambda d: (
            _cable(d).update(segments=4),
            _cable(d)["clips"].extend(
                {**_cable(d)["clips"][1], "name": f"m{k}", "s": 0.1 * k, "length": 0.02}
                for k in range(2, 8)
            ),
        ),
        ("segments = 4", "intervals", "allowed: segments >="),
    ),
    ("clip-length-huge", _set("cables.0.clips.1.length", 1.7e308), ("clips[1]", "outside")),
    # names become HDF5 group names and table entries
    ("cable-slash", _set("cables.0.name", "a/b"), (f"{C}.name", "'/'", "allowed")),
    ("cable-dot", _set("cables.0.name", "."), (f"{C}.name", "'.'", "allowed")),
    ("cable-dotdot", _set("cables.0.name", ".."), (f"{C}.name", "allowed")),
    ("clip-slash", _set("cables.0.clips.1.name", "x/y"), (f"{CLIP}.name", "'/'")),
    ("clip-dot", _set("cables.0.clips.1.name", "."), (f"{CLIP}.name", "allowed")),
    ("cable-markup", _set("cables.0.name", "[/x]"), (f"{C}.name", "[/x]", "allowed")),
    ("clip-emoji", _set("cables.0.clips.1.name", ":x:"), (f"{CLIP}.name", ":x:")),
    ("cable-bold", _set("cables.0.name", "[bold]h"), (f"{C}.name", "[bold]h")),
    ("cable-space", _set("cables.0.name", " hose"), (f"{C}.name", "' hose'")),
    ("cable-newline", _set("cables.0.name", "ho\nse"), (f"{C}.name", "'\\n'")),
    ("cable-long", _set("cables.0.name", "h" * 65), (f"{C}.name", "64 characters")),
    ("cable-empty", _set("cables.0.name", ""), (f"{C}.name", "at least 1")),
    ("cable-number", _set("cables.0.name", 5), (f"{C}.name", "valid string")),
    (
        "body-slash",
        lambda d: d.update(bodies=[{"name": "en/gine"}]),
        ("bodies[0].name", "'/'"),
    ),
    ("body-world", lambda d: d.update(bodies=[{"name": "world"}]), ("'world' is reserved",)),
    ("body-unknown", _set("cables.0.clips.1.body", "engine"), (f"{CLIP}.body", "'engine'")),
    # signals
    (
        "sine-above-nyquist",
        _moving({"type": "sine", "amplitude": 0.01, "frequency": 600.0}),
        ("frequency = 600 Hz", "Nyquist frequency 500 Hz", "time_step"),
    ),
    (
        "sweep-above-nyquist",
        _moving({"type": "sweep", "amplitude": 0.01, "f0": 1.0, "f1": 900.0, "duration": 0.2}),
        ("f0/f1 = 900 Hz", "Nyquist"),
    ),
    ("signal-type", _moving({"type": "noise", "amplitude": 1.0}), ("bodies[0].motion[0]", "noise")),
    (
        "sine-amplitude-negative",
        _moving({"type": "sine", "amplitude": -1.0, "frequency": 1.0}),
        ("amplitude", "-1.0"),
    ),
    (
        "sine-amplitude-string",
        _moving({"type": "sine", "amplitude": "1", "frequency": 1.0}),
        ("amplitude", "'1'"),
    ),
    (
        "channel-unknown",
        lambda d: (_moving(SINE)(d), d["bodies"][0]["motion"][0].update(channel="q")),
        ("bodies[0].motion[0].channel", "'q'"),
    ),
    (
        "frame-body-on-world",
        _set("cables.0.clips.0.frame", "body"),
        ("cables[0].clips[0]", "frame = 'body'", "world"),
    ),
    # sizes: checked before allocating
    (
        "time-step-1e-9-dynamic",
        lambda d: d["simulation"].update(mode="dynamic", duration=15.0, time_step=1e-9),
        ("simulation.time_step = 1e-09", "memory", "allowed"),
    ),
    (
        "time-step-1e-9-quasistatic",
        lambda d: d["simulation"].update(mode="quasistatic", duration=15.0, time_step=1e-9),
        ("simulation.time_step = 1e-09", "memory"),
    ),
    (
        "time-step-static-psd",
        _moving(
            {"type": "psd", "breakpoints": [[5.0, 1e-4], [50.0, 1e-4]], "quantity": "acceleration"},
            time_step=1e-9,
            mode="static",
        ),
        ("memory", "time_step"),
    ),
    (
        "duration-1e300-time-step-1e-300",
        lambda d: d["simulation"].update(mode="dynamic", duration=1e300, time_step=1e-300),
        ("simulation.time_step = 1e-300", "inf time steps", "memory"),
    ),
    (
        "time-step-longer-than-duration",
        lambda d: d["simulation"].update(mode="quasistatic", duration=0.1, time_step=1.0),
        ("time_step", "duration"),
    ),
    (
        "duration-missing",
        lambda d: d["simulation"].update(mode="dynamic"),
        ("simulation.duration is required",),
    ),
    (
        "output-step-not-multiple",
        lambda d: d["simulation"].update(
            mode="dynamic", duration=0.01, time_step=1e-3, output_step=1.5e-3
        ),
        ("output_step", "whole multiple"),
    ),
]


@pytest.mark.parametrize(("case", "mutate", "expect"), SCENE_CASES, ids=[c[0] for c in SCENE_CASES])
def test_bad_scene(tmp_path, case, mutate, expect):
    d = scene()
    mutate(d)
    path = write_scene(tmp_path, d)
    out = tmp_path / "out.h5"
    cli(["run", path, "-q", "-o", out], expect, outputs=(out,), case=f"scene:{case}")


RAW_CASES = [
    ("invalid-utf8", b'[simulation]\nmode = "st\xff\xfeatic"\n', ("not UTF-8 text",)),
    ("binary", bytes(range(256)) * 4, ("binary file",)),
    ("nested-arrays", ("a = " + "[" * 5000 + "]" * 5000 + "\n").encode(), ("nested",)),
    ("nested-tables", ("a = " + "{b = " * 200 + "1" + "}" * 200 + "\n").encode(), ("nested",)),
    ("empty", b"", ("cables", "required")),
    ("toml-syntax", b"[simulation\nmode = 1\n", ("not valid TOML",)),
    ("bom", "\ufeff[simulation]\n".encode(), ("not valid TOML",)),
    ("markup-in-key", b"[simulation]\n'[/x]' = 1\n", ("[/x]", "unknown key")),
    ("emoji-in-value", b"[simulation]\nmode = ':x:'\n", (":x:", "simulation.mode")),
]


@pytest.mark.parametrize(("case", "raw", "expect"), RAW_CASES, ids=[c[0] for c in RAW_CASES])
def test_bad_scene_file(tmp_path, case, raw, expect):
    path = write_scene(tmp_path, raw)
    cli(["run", path, "-q"], expect, case=f"scene-file:{case}")


def test_scene_is_a_directory(tmp_path):
    cli(["run", tmp_path, "-q"], ("is a directory",), case="scene-file:directory")
    cli(["modes", tmp_path], ("is a directory",), case="modes:directory")


def test_scene_missing(tmp_path):
    cli(["run", tmp_path / "none.toml"], ("does not exist",), case="scene-file:missing")


def test_modes_of_a_bad_scene(tmp_path):
    d = scene()
    _set("cables.0.length", True)(d)
    cli(["modes", write_scene(tmp_path, d)], ("cables[0].length",), case="modes:bad-scene")


@pytest.mark.parametrize("count", ["0", "-2", "x"])
def test_modes_bad_count(tmp_path, count):
    path = write_scene(tmp_path, scene())
    cli(["modes", path, "--count", count], ("count",), case=f"modes:count={count}")


def test_run_bad_mode(tmp_path):
    path = write_scene(tmp_path, scene())
    cli(["run", path, "--mode", "fast", "-q"], ("'fast'", "allowed"), case="run:mode")


def test_unicode_names_are_fine_and_static_runs_need_no_time_grid(tmp_path):
    """Good input next to the bad: letters of any script in names; a static run of a scene
    with time_step = 1e-9 and a sine motion allocates no time grid."""
    d = scene()
    _cable(d)["name"] = "Schlauch_Öl-2"
    _moving(SINE, time_step=1e-9, mode="static")(d)
    d["simulation"]["duration"] = 15.0
    out = tmp_path / "ok.h5"
    text = cli(["run", write_scene(tmp_path, d), "-q", "-o", out], code=0, outputs=(out,))
    assert "Schlauch_Öl-2" in text and "s [m]" in text


def test_markup_in_paths_is_printed_as_written(tmp_path):
    """Rich markup and emoji codes in folder and file names: printed, not interpreted, and
    the result is saved."""
    folder = tmp_path / "runs[bold]:x:"
    folder.mkdir()
    out = folder / "[red]out.h5"
    text = cli(["run", write_scene(folder, scene(), "[b]scene.toml"), "-q", "-o", out], code=0)
    assert out.exists() and "[red]out.h5" in text.replace("\n", "")
    bad = scene()
    _set("cables.0.length", True)(bad)
    cli(["run", write_scene(folder, bad, "x.toml"), "-q"], ("runs[bold]:x:/x.toml",))
    closing = tmp_path / "runs["  # with the file "x].toml": the path holds "[/x]"
    closing.mkdir()
    cli(["run", write_scene(closing, bad, "x].toml"), "-q"], ("runs[/x].toml",))


def test_summary_headers_keep_their_units(tmp_path):
    text = cli(["run", write_scene(tmp_path, scene()), "-q"], code=0)
    for header in ("s [m]", "|force| [N]", "|moment| [N m]"):
        assert header in text


# real processes: the cases that used to abort, allocate 15 GiB or crash after the run
SUBPROCESS_CASES = [
    ("segments-1e7", _set("cables.0.segments", 10_000_000), ("cables[0].segments", "20000")),
    (
        "time-step-1e-9",
        lambda d: d["simulation"].update(mode="dynamic", duration=15.0, time_step=1e-9),
        ("memory",),
    ),
]


@pytest.mark.parametrize(
    ("case", "mutate", "expect"), SUBPROCESS_CASES, ids=[c[0] for c in SUBPROCESS_CASES]
)
def test_bad_scene_in_a_real_process(tmp_path, case, mutate, expect):
    d = scene()
    mutate(d)
    out = tmp_path / "out.h5"
    cli_subprocess(["run", write_scene(tmp_path, d), "-q", "-o", out], expect, case=case)
    assert not out.exists()
