"""Bad input of ``signal``, ``study`` and ``demo``, and files named inside scenes: paths
outside the scene's folder are refused unless allowed, messages never quote file content."""

from __future__ import annotations

import copy

import pytest
import tomli_w
from badinput import cli, scene, write_scene

SECRET = "root:x:0:0:secret-line-that-must-not-be-echoed"


def _moving_scene(signal: dict, mode: str = "quasistatic") -> dict:
    d = scene()
    d["simulation"].update(mode=mode, duration=0.2, time_step=0.01)
    d["bodies"] = [{"name": "engine", "motion": [{"channel": "z", "signal": signal}]}]
    d["cables"][0]["clips"][1]["body"] = "engine"
    return d


def _motion_file_scene(path: str) -> dict:
    d = scene()
    d["simulation"].update(mode="quasistatic", duration=0.2, time_step=0.01)
    d["bodies"] = [{"name": "engine", "motion_file": path}]
    d["cables"][0]["clips"][1]["body"] = "engine"
    return d


def _measured(path: str, channel: str = "z") -> dict:
    return {"type": "measured", "file": path, "channel": channel, "format": "csv"}


POSES = "t,x,y,z,rx,ry,rz\n0,0,0,0,0,0,0\n1,0,0,0.01,0,0,0\n"
SIGNAL_CSV = "time,z\n" + "".join(f"{k * 0.01:.2f},{0.001 * k}\n" for k in range(40))


@pytest.fixture
def outside(tmp_path):
    """A secret file outside the scene folder ``tmp_path / 'scene'``, and the folder."""
    (tmp_path / "secret.csv").write_text(SECRET + "\n1,2\n")
    (tmp_path / "poses.csv").write_text(POSES)
    (tmp_path / "signal.csv").write_text(SIGNAL_CSV)
    folder = tmp_path / "scene"
    folder.mkdir()
    return folder


# files named in scenes: (id, scene builder taking the scene folder, expected message parts)
FILE_CASES = [
    (
        "motion-file-etc-passwd",
        lambda f: _motion_file_scene("/etc/passwd"),
        ("motion_file = '/etc/passwd'", "outside the scene's folder", "allow_outside"),
    ),
    (
        "motion-file-dotdot",
        lambda f: _motion_file_scene("../secret.csv"),
        ("motion_file = '../secret.csv'", "outside"),
    ),
    (
        "motion-file-absolute-outside",
        lambda f: _motion_file_scene(str(f.parent / "poses.csv")),
        ("poses.csv", "outside"),
    ),
    (
        "motion-file-missing",
        lambda f: _motion_file_scene("none.csv"),
        ("motion_file = 'none.csv'", "does not exist"),
    ),
    (
        "motion-file-directory",
        lambda f: _motion_file_scene("."),
        ("motion_file = '.'", "directory"),
    ),
    (
        "motion-file-binary",
        lambda f: (
            f.joinpath("b.csv").write_bytes(b"\xff\xfe\x00" * 50),
            _motion_file_scene("b.csv"),
        )[1],
        ("b.csv", "not a numeric CSV table"),
    ),
    (
        "motion-file-columns",
        lambda f: (f.joinpath("c.csv").write_text(SECRET + "\n1\n"), _motion_file_scene("c.csv"))[
            1
        ],
        ("c.csv", "lacks the columns"),
    ),
    (
        "motion-file-markup",
        lambda f: (
            f.joinpath("[red]p.csv").write_text("[/x]\n1\n"),
            _motion_file_scene("[red]p.csv"),
        )[1],
        ("[red]p.csv", "lacks the columns"),
    ),
    (
        "motion-file-nonnumeric",
        lambda f: (
            f.joinpath("n.csv").write_text(POSES + "2,a,0,0,0,0,0\n"),
            _motion_file_scene("n.csv"),
        )[1],
        ("n.csv", "column 'x'", "line 4"),
    ),
    (
        "measured-etc-passwd",
        lambda f: _moving_scene(_measured("/etc/passwd")),
        ("'/etc/passwd'", "outside the scene's folder"),
    ),
    (
        "measured-dotdot",
        lambda f: _moving_scene(_measured("../signal.csv")),
        ("'../signal.csv'", "outside"),
    ),
    (
        "measured-missing",
        lambda f: _moving_scene(_measured("none.csv")),
        ("'none.csv'", "does not exist"),
    ),
    (
        "measured-directory",
        lambda f: (f.joinpath("d.csv").mkdir(), _moving_scene(_measured("d.csv")))[1],
        ("'d.csv'", "directory"),
    ),
    (
        "measured-extension",
        lambda f: _moving_scene({"type": "measured", "file": "/etc/passwd", "channel": "z"}),
        ("'/etc/passwd'", "cannot tell the format"),
    ),
    (
        "measured-channel",
        lambda f: (
            f.joinpath("s.csv").write_text("time,z\n0,1\n1,2\n"),
            _moving_scene(_measured("s.csv", "q")),
        )[1],
        ("channel 'q' not found", "columns:"),
    ),
    (
        "measured-invalid-utf8",
        lambda f: (
            f.joinpath("u.csv").write_bytes(b"time,z\n\xff,1\n"),
            _moving_scene(_measured("u.csv")),
        )[1],
        ("u.csv", "not UTF-8"),
    ),
    (
        "measured-nonnumeric",
        lambda f: (
            f.joinpath("v.csv").write_text("time,z\n0,1\n1,pw=hunter2\n"),
            _moving_scene(_measured("v.csv")),
        )[1],
        ("v.csv", "cannot read columns", "row"),
    ),
]


@pytest.mark.parametrize(("case", "build", "expect"), FILE_CASES, ids=[c[0] for c in FILE_CASES])
def test_bad_file_named_in_scene(outside, case, build, expect):
    path = write_scene(outside, build(outside))
    text = cli(["run", path, "-q"], expect, case=f"files:{case}")
    assert "secret-line" not in text and "hunter2" not in text and "root:x:0:0:root" not in text


def test_outside_files_need_permission(outside):
    d = _motion_file_scene("../poses.csv")
    path = write_scene(outside, d)
    cli(["run", path, "-q"], ("outside",), case="files:outside-default")
    out = outside / "r.h5"
    cli(
        ["run", path, "-q", "--allow-outside-files", "-o", out],
        code=0,
        outputs=(out,),
        case="files:outside-flag",
    )
    d["files"] = {"allow_outside": True}
    cli(["run", write_scene(outside, d, "allowed.toml"), "-q"], code=0, case="files:outside-key")
    m = _moving_scene(_measured("../signal.csv"))
    m["files"] = {"allow_outside": True}
    cli(["run", write_scene(outside, m, "m.toml"), "-q"], code=0, case="files:measured-key")


def test_dynamic_failure_names_the_cable_once(tmp_path, monkeypatch):
    """A scene error inside a cable's run (here: no static equilibrium for the modes of the
    default damping) names the cable once, not 'cable 'hose': cable 'hose':'."""
    import cablelife.modal
    from cablelife.scene import SceneError

    def fails(scene, cable):
        raise SceneError(f"cable '{cable.name}': no static equilibrium: diverged")

    monkeypatch.setattr(cablelife.modal, "retardation_times", fails)
    d = scene()
    d["simulation"].update(mode="dynamic", duration=0.01, time_step=1e-3)
    text = cli(
        ["run", write_scene(tmp_path, d), "-q"], ("cable 'hose': no static",), case="prefix-once"
    )
    assert "cable 'hose': cable 'hose'" not in text


# signal specs
def _spec(signal: dict | None = None, **top) -> dict:
    spec = {
        "signal": {"duration": 1.0, "time_step": 0.01},
        "channels": [
            {
                "name": "z",
                "channel": "z",
                "signal": signal or {"type": "sine", "amplitude": 0.01, "frequency": 2.0},
            }
        ],
    }
    spec.update(top)
    return spec


SIGNAL_CASES = [
    ("unknown-key", _spec(extra=1), ("extra",)),
    (
        "sine-above-nyquist",
        _spec({"type": "sine", "amplitude": 1.0, "frequency": 80.0}),
        ("frequency = 80 Hz", "Nyquist frequency 50 Hz"),
    ),
    (
        "amplitude-bool",
        _spec({"type": "sine", "amplitude": True, "frequency": 1.0}),
        ("amplitude",),
    ),
    (
        "frequency-string",
        _spec({"type": "sine", "amplitude": 1.0, "frequency": "1"}),
        ("frequency", "'1'"),
    ),
    (
        "time-step-tiny",
        {**_spec(), "signal": {"duration": 100.0, "time_step": 1e-9}},
        ("time_step", "samples", "allowed"),
    ),
    (
        "steps-inf",
        {**_spec(), "signal": {"duration": 1e300, "time_step": 1e-300}},
        ("time_step", "inf samples"),
    ),
    (
        "time-step-string",
        {**_spec(), "signal": {"duration": 1.0, "time_step": "1ms"}},
        ("time_step", "'1ms'"),
    ),
    ("measured-outside", _spec(_measured("/etc/passwd")), ("outside", "/etc/passwd")),
    ("measured-missing", _spec(_measured("none.csv")), ("none.csv", "does not exist")),
    ("psd-type", _spec({"type": "psd", "breakpoints": [[1.0, True]]}), ("breakpoints",)),
    (
        "markup-name",
        {
            **_spec(),
            "channels": [
                {
                    "name": "[/x]",
                    "channel": "z",
                    "signal": {"type": "sine", "amplitude": 1.0, "frequency": "x"},
                }
            ],
        },
        ("frequency",),
    ),
]


@pytest.mark.parametrize(("case", "spec", "expect"), SIGNAL_CASES, ids=[c[0] for c in SIGNAL_CASES])
def test_bad_signal_spec(tmp_path, case, spec, expect):
    path = tmp_path / "spec.toml"
    path.write_text(tomli_w.dumps(spec))
    out = tmp_path / "out.csv"
    cli(["signal", path, "-o", out, "--no-plot"], expect, outputs=(out,), case=f"signal:{case}")


@pytest.mark.parametrize(
    ("case", "raw", "expect"),
    [
        ("invalid-utf8", b"[signal]\nduration = 1.0\xff\n", ("not UTF-8",)),
        ("binary", b"\x00\x01\x02" * 20, ("binary",)),
        ("nested", ("a = " + "[" * 3000 + "]" * 3000).encode(), ("nested",)),
    ],
)
def test_bad_signal_spec_file(tmp_path, case, raw, expect):
    path = tmp_path / "spec.toml"
    path.write_bytes(raw)
    cli(["signal", path, "--no-plot"], expect, case=f"signal-file:{case}")


def test_signal_spec_directory_and_missing(tmp_path):
    cli(["signal", tmp_path, "--no-plot"], ("directory",), case="signal-file:directory")
    cli(
        ["signal", tmp_path / "none.toml", "--no-plot"],
        ("does not exist",),
        case="signal-file:missing",
    )


def test_signal_markup_names_are_printed(tmp_path):
    spec = _spec()
    spec["channels"][0]["name"] = "[/x]:x:"
    path = tmp_path / "spec.toml"
    path.write_text(tomli_w.dumps(spec))
    text = cli(
        ["signal", path, "-o", tmp_path / "o.csv", "--no-plot"],
        code=0,
        outputs=(tmp_path / "o.csv",),
    )
    assert "[/x]:x:" in text


# study files (all fail while the variants are validated, before a Dask cluster starts)
def _study(**parts) -> dict:
    study = {
        "study": {"scene": "scene.toml", "combine": "grid"},
        "parameters": [{"name": "len", "kind": "cable_length", "values": [1.0, 1.1]}],
    }
    study.update(parts)
    return study


STUDY_CASES = [
    ("scene-missing", _study(study={"scene": "none.toml"}), ("none.toml", "does not exist")),
    (
        "kind-unknown",
        _study(parameters=[{"name": "p", "kind": "magic", "values": [1.0]}]),
        ("parameters[0]", "magic"),
    ),
    (
        "values-strings",
        _study(parameters=[{"name": "p", "kind": "cable_length", "values": ["a"]}]),
        ("values",),
    ),
    (
        "set-bad-value",
        _study(
            parameters=[
                {"name": "p", "kind": "set", "path": "cables.hose.segments", "values": [1e7]}
            ]
        ),
        ("variant", "segments"),
    ),
    (
        "set-unknown-path",
        _study(
            parameters=[{"name": "p", "kind": "set", "path": "cables.nope.length", "values": [1.0]}]
        ),
        ("nope",),
    ),
    (
        "clip-unknown",
        _study(parameters=[{"name": "p", "kind": "clip_position", "clip": "zz", "values": [0.01]}]),
        ("'zz'",),
    ),
    (
        "name-bad",
        _study(parameters=[{"name": "a b", "kind": "cable_length", "values": [1.0]}]),
        ("parameters[0]", "name"),
    ),
    (
        "length-tiny",
        _study(parameters=[{"name": "p", "kind": "cable_length", "values": [1e-9]}]),
        ("variant", "length"),
    ),
    ("threads-zero", _study(study={"scene": "scene.toml", "threads": 0}), ("study.threads",)),
    ("no-parameters", _study(parameters=[]), ("parameters",)),
]


@pytest.mark.parametrize(("case", "study", "expect"), STUDY_CASES, ids=[c[0] for c in STUDY_CASES])
def test_bad_study(tmp_path, case, study, expect):
    write_scene(tmp_path, scene())
    path = tmp_path / "study.toml"
    path.write_text(tomli_w.dumps(study))
    text = cli(["study", path, "-o", tmp_path / "out"], expect, case=f"study:{case}")
    assert "cable 'hose': cable 'hose'" not in text


@pytest.mark.parametrize(
    ("case", "raw", "expect"),
    [
        ("invalid-utf8", b'[study]\nscene = "\xff"\n', ("not UTF-8",)),
        ("binary", b"\x00" * 64, ("binary",)),
        ("syntax", b"[study\n", ("not valid TOML",)),
    ],
)
def test_bad_study_file(tmp_path, case, raw, expect):
    path = tmp_path / "study.toml"
    path.write_bytes(raw)
    cli(["study", path, "-o", tmp_path / "out"], expect, case=f"study-file:{case}")


def test_study_file_directory_and_missing(tmp_path):
    cli(["study", tmp_path], ("directory",), case="study-file:directory")
    cli(["study", tmp_path / "none.toml"], ("does not exist",), case="study-file:missing")


def test_study_bad_workers(tmp_path):
    write_scene(tmp_path, scene())
    path = tmp_path / "study.toml"
    path.write_text(tomli_w.dumps(_study()))
    cli(
        ["study", path, "--workers", "0", "-o", tmp_path / "o"],
        ("--workers = 0",),
        case="study:workers",
    )


DEMO_CASES = [
    (["--duration", "-1"], ("duration = -1",)),
    (["--duration", "nan"], ("duration = nan",)),
    (["--duration", "0"], ("duration = 0",)),
    (["--example", "none-such-folder"], ("none-such-folder", "does not exist")),
    (["--seed", "-1"], ("seed",)),
]


@pytest.mark.parametrize(
    ("options", "expect"), DEMO_CASES, ids=[" ".join(o) for o, _ in DEMO_CASES]
)
def test_bad_demo_option(tmp_path, options, expect):
    cli(["demo", "-o", tmp_path / "demo", *options], expect, case=f"demo:{' '.join(options)}")


def test_demo_example_outside_files_refused(tmp_path):
    """An example folder whose scene names a file outside it: refused, and says how to allow."""
    from cablelife.demo import example_dir

    example = tmp_path / "ex"
    example.mkdir()
    for p in example_dir().iterdir():
        if p.is_file():
            (example / p.name).write_bytes(p.read_bytes())
    text = (example / "scene.toml").read_text()
    (tmp_path / "poses.csv").write_text(POSES)
    data = __import__("tomllib").loads(text)
    body = copy.deepcopy(data["bodies"][0])
    body.pop("motion", None)
    body["motion_file"] = "../poses.csv"
    data["bodies"][0] = body
    (example / "scene.toml").write_text(tomli_w.dumps(data))
    cli(
        ["demo", "-o", tmp_path / "demo", "--example", example, "--no-report"],
        ("motion_file = '../poses.csv'", "--allow-outside-files"),
        case="demo:outside",
    )


def test_help_texts_keep_brackets():
    for command, needle in (
        ("lda", "[pseudo-damage]"),
        ("lda", "[no knee]"),
        ("compare", "[file names]"),
        ("demo", "[the scene's seeds]"),
        ("run", "--allow-outside-files"),
        ("study", "--allow-outside-files"),
        ("demo", "--allow-outside-files"),
    ):
        text = cli([command, "--help"], code=0, case=f"help:{command}")
        assert needle.replace(" ", "") in "".join(text.split()), (command, needle)


@pytest.mark.parametrize("fmt", ["mdf4", "tdms"])
def test_foreign_measurement_file_is_not_quoted(tmp_path, fmt):
    (tmp_path / "rec.dat").write_text(SECRET + "\n")
    d = _moving_scene({**_measured("rec.dat"), "format": fmt})
    text = cli(
        ["run", write_scene(tmp_path, d), "-q"],
        ("rec.dat", "cannot read as"),
        case=f"files:foreign-{fmt}",
    )
    assert "secret-line" not in text and "root:x" not in text
