"""Bad result and damage files through every reader (lda, volume, paraview, compare, report),
and bad options of those commands: clear errors naming the file and the dataset, no HDF5
traceback, no attempt to allocate what a forged header declares, no NaN passed on."""

from __future__ import annotations

import shutil

import h5py
import numpy as np
import pytest
from badinput import cli, cli_subprocess, scene, write_scene


@pytest.fixture(scope="module")
def good(tmp_path_factory):
    """A small quasistatic result with its damage file."""
    from cablelife.lda import analyse
    from cablelife.scene import scene_from_dict
    from cablelife.simulate import simulate

    folder = tmp_path_factory.mktemp("good")
    d = scene()
    d["cables"][0]["segments"] = 8
    d["simulation"].update(mode="quasistatic", duration=0.2, time_step=0.05)
    d["bodies"] = [
        {
            "name": "engine",
            "motion": [
                {"channel": "z", "signal": {"type": "sine", "amplitude": 0.02, "frequency": 2.0}}
            ],
        }
    ]
    d["cables"][0]["clips"][1]["body"] = "engine"
    result = folder / "good.h5"
    simulate(scene_from_dict(d)).save(result)
    damage = analyse(result, sampling_check=False).save(folder / "good.damage.h5")
    return result, damage


def _replace(f: h5py.File, name: str, **kw) -> None:
    del f[name]
    f.create_dataset(name, **kw)


CABLE = "cables/hose"


def _nan(key: str, value=np.nan):
    def apply(f):
        data = f[f"{CABLE}/{key}"][()]
        data.flat[3] = value
        _replace(f, f"{CABLE}/{key}", data=data)

    return apply


def _forged_steps(f):
    """Every dataset declares 2e9 steps (sparse: the file stays small), the stored scene is
    gone: only the size bound can stop the read."""
    del f.attrs["scene_toml"]
    g = f[CABLE]
    n = g["arc_length"].shape[0]
    big = 2_000_000_000
    for key, shape in (
        ("time", (big,)),
        ("positions", (big, n, 3)),
        ("quaternions", (big, n - 1, 4)),
        ("forces", (big, n - 1, 3)),
        ("moments", (big, n, 3)),
        ("elastic_energy", (big,)),
    ):
        _replace(f, f"{CABLE}/{key}", shape=shape, dtype="f8", chunks=True)
    for clip in g["clips"].values():
        for key in ("reaction_force", "reaction_moment"):
            del clip[key]
            clip.create_dataset(key, shape=(big, 3), dtype="f8", chunks=True)


def _more_nodes(f):
    """Consistent shapes, but 60 segments where the stored scene asked for 8."""
    g = f[CABLE]
    t = g["time"].shape[0]
    for key, shape in (
        ("arc_length", (61,)),
        ("positions", (t, 61, 3)),
        ("quaternions", (t, 60, 4)),
        ("forces", (t, 60, 3)),
        ("moments", (t, 61, 3)),
    ):
        _replace(f, f"{CABLE}/{key}", data=np.zeros(shape))


# (id, change of an open copy of the good result, expected message parts)
RESULT_DEFECTS = [
    ("no-format", lambda f: f.attrs.__delitem__("format"), ("not a cablelife result",)),
    ("no-cables", lambda f: f.__delitem__("cables"), ("group 'cables' is missing",)),
    (
        "empty-cables",
        lambda f: [f["cables"].__delitem__(k) for k in list(f["cables"])],
        ("group 'cables' is empty",),
    ),
    (
        "no-positions",
        lambda f: f.__delitem__(f"{CABLE}/positions"),
        ("'hose'", "dataset 'positions' is missing"),
    ),
    (
        "positions-shape",
        lambda f: _replace(f, f"{CABLE}/positions", data=np.zeros((5, 9, 2))),
        ("dataset 'positions' has shape (5, 9, 2)", "expected (5, 9, 3)"),
    ),
    (
        "forces-forged-2e9",
        lambda f: _replace(
            f, f"{CABLE}/forces", shape=(2_000_000_000, 50, 3), dtype="f8", chunks=True
        ),
        ("dataset 'forces' has shape (2000000000, 50, 3)", "expected (5, 8, 3)"),
    ),
    (
        "time-forged-2e9",
        lambda f: _replace(f, f"{CABLE}/time", shape=(2_000_000_000,), dtype="f8", chunks=True),
        ("dataset 'time' has 2000000000 steps", "at most 5"),
    ),
    ("all-forged-2e9", _forged_steps, ("allowed: at most", "GiB")),
    (
        "time-strings",
        lambda f: _replace(f, f"{CABLE}/time", data=np.array([b"a"] * 5)),
        ("dataset 'time' holds", "expected numbers"),
    ),
    (
        "arc-length-2d",
        lambda f: _replace(f, f"{CABLE}/arc_length", data=np.zeros((9, 2))),
        ("dataset 'arc_length' has shape (9, 2)",),
    ),
    ("nan-forces", _nan("forces"), ("dataset 'forces'", "non-finite value nan")),
    ("inf-positions", _nan("positions", np.inf), ("dataset 'positions'", "non-finite value inf")),
    (
        "nan-reaction",
        lambda f: _replace(f, f"{CABLE}/clips/a/reaction_force", data=np.full((5, 3), np.nan)),
        ("clips/a/reaction_force", "non-finite"),
    ),
    (
        "no-reaction",
        lambda f: f.__delitem__(f"{CABLE}/clips/b/reaction_moment"),
        ("clip 'b'", "dataset 'reaction_moment' is missing"),
    ),
    ("more-nodes", _more_nodes, ("'arc_length' has 61 nodes", "8 segments give at most")),
    ("bad-mode", lambda f: f.attrs.__setitem__("mode", "fast"), ("attribute 'mode' is 'fast'",)),
    (
        "bad-scene-toml",
        lambda f: f.attrs.__setitem__("scene_toml", "[x"),
        ("attribute 'scene_toml' is not a valid scene",),
    ),
    (
        "renamed-cable",
        lambda f: f.move(CABLE, "cables/other"),
        ("cable 'other'", "not a cable of the stored scene"),
    ),
]


def _bytes_defect(kind: str, good_path, path) -> None:
    if kind == "empty":
        path.write_bytes(b"")
    elif kind == "truncated":
        data = good_path.read_bytes()
        path.write_bytes(data[: len(data) // 3])
    elif kind == "text":
        path.write_text("time,x\n0,1\n")
    elif kind == "foreign-hdf5":
        with h5py.File(path, "w") as f:
            f["x"] = np.arange(3)


BYTE_DEFECTS = [
    ("empty", ("not a readable HDF5 file",)),
    ("truncated", ("not a readable HDF5 file",)),
    ("text", ("not a readable HDF5 file",)),
    ("foreign-hdf5", ("not a cablelife",)),
]


def make_bad_result(good_path, folder, defect) -> object:
    path = folder / "bad.h5"
    if callable(defect):
        shutil.copyfile(good_path, path)
        with h5py.File(path, "r+") as f:
            defect(f)
    else:
        _bytes_defect(defect, good_path, path)
    return path


READERS = {
    "lda": lambda bad, good, tmp: ["lda", bad, "-o", tmp / "d.h5"],
    "volume": lambda bad, good, tmp: ["volume", bad, "-o", tmp / "v.stl"],
    "paraview": lambda bad, good, tmp: ["paraview", bad, "-o", tmp / "p.pvd"],
    "compare": lambda bad, good, tmp: ["compare", good, bad],
    "report": lambda bad, good, tmp: ["report", good, bad, "-o", tmp / "r.html", "--voxel", "none"],
}
OUTPUTS = {"lda": "d.h5", "volume": "v.stl", "paraview": "p.pvd", "report": "r.html"}

# Result histories are read when first used (docs/results.md) and checked as they are read: a
# non-finite value in a dataset that a command does not read cannot reach its outputs, and the
# command succeeds with finite outputs.
NOT_READ = {
    "volume": {"nan-forces", "nan-reaction"},
    "lda": {"inf-positions", "nan-reaction"},
    "compare": {"inf-positions", "nan-reaction"},
    "paraview": {"nan-reaction"},
}

RESULT_CASES = [
    (reader, name, defect, expect)
    for name, defect, expect in [*RESULT_DEFECTS, *((n, n, e) for n, e in BYTE_DEFECTS)]
    for reader in READERS
]


@pytest.mark.parametrize(
    ("reader", "name", "defect", "expect"),
    RESULT_CASES,
    ids=[f"{r}-{n}" for r, n, _, _ in RESULT_CASES],
)
def test_bad_result_file(good, tmp_path, reader, name, defect, expect):
    good_result, _ = good
    bad = make_bad_result(good_result, tmp_path, defect)
    out = tmp_path / OUTPUTS[reader] if reader in OUTPUTS else None
    unread = name in NOT_READ.get(reader, ())
    cli(
        READERS[reader](bad, good_result, tmp_path),
        () if unread else ("bad.h5", *expect),
        code=0 if unread else 2,
        outputs=(out,) if out else (),
        case=f"{reader}:{name}",
    )


@pytest.mark.parametrize("reader", list(READERS))
def test_result_is_a_directory(good, tmp_path, reader):
    folder = tmp_path / "dir.h5"
    folder.mkdir()
    cli(READERS[reader](folder, good[0], tmp_path), ("dir.h5", "directory"), case=f"{reader}:dir")


@pytest.mark.parametrize("reader", list(READERS))
def test_result_missing(good, tmp_path, reader):
    cli(
        READERS[reader](tmp_path / "none.h5", good[0], tmp_path),
        ("none.h5", "does not exist"),
        case=f"{reader}:missing",
    )


def test_forged_result_in_a_real_process(good, tmp_path):
    """The 2e9 × 50 × 3 dataset of a 5 MB file: refused before any allocation."""
    bad = make_bad_result(good[0], tmp_path, _forged_steps)
    assert bad.stat().st_size < 5_000_000
    cli_subprocess(
        ["lda", bad, "-o", tmp_path / "d.h5"],
        ("bad.h5", "allowed: at most"),
        case="lda:forged-subprocess",
    )


DAMAGE_DEFECTS = [
    ("truncated", "truncated", ("not a readable HDF5 file",)),
    (
        "no-damage-planes",
        lambda f: f.__delitem__(f"{CABLE}/damage_planes"),
        ("dataset 'damage_planes' is missing",),
    ),
    (
        "damage-planes-shape",
        lambda f: _replace(f, f"{CABLE}/damage_planes", data=np.zeros((2, 2))),
        ("dataset 'damage_planes' has shape (2, 2)",),
    ),
    (
        "nan-damage",
        lambda f: _replace(
            f,
            f"{CABLE}/damage_planes",
            data=np.where(True, np.nan, f[f"{CABLE}/damage_planes"][()]),
        ),
        ("damage_planes", "non-finite"),
    ),
    (
        "negative-damage",
        lambda f: _replace(
            f, f"{CABLE}/damage_planes", data=-np.ones(f[f"{CABLE}/damage_planes"].shape)
        ),
        ("negative damage",),
    ),
    (
        "forged-2e9",
        lambda f: _replace(
            f, f"{CABLE}/section_index", shape=(2_000_000_000,), dtype="i8", chunks=True
        ),
        ("has shape",),
    ),
    ("no-source", lambda f: f.attrs.__delitem__("source"), ("attributes ['source'] are missing",)),
]

DAMAGE_READERS = {
    "paraview": lambda bad, res, dmg, tmp: ["paraview", res, "--damage", bad, "-o", tmp / "p.pvd"],
    "report": lambda bad, res, dmg, tmp: [
        "report",
        res,
        bad,
        "-o",
        tmp / "r.html",
        "--voxel",
        "none",
    ],
    "compare": lambda bad, res, dmg, tmp: ["compare", dmg, bad],
}

DAMAGE_CASES = [(r, *d) for d in DAMAGE_DEFECTS for r in DAMAGE_READERS]


@pytest.mark.parametrize(
    ("reader", "name", "defect", "expect"),
    DAMAGE_CASES,
    ids=[f"{r}-{n}" for r, n, _, _ in DAMAGE_CASES],
)
def test_bad_damage_file(good, tmp_path, reader, name, defect, expect):
    result, damage = good
    bad = tmp_path / "bad.damage.h5"
    if callable(defect):
        shutil.copyfile(damage, bad)
        with h5py.File(bad, "r+") as f:
            defect(f)
    else:
        data = damage.read_bytes()
        bad.write_bytes(data[: len(data) // 3])
    cli(
        DAMAGE_READERS[reader](bad, result, damage, tmp_path),
        ("bad.damage.h5", *expect),
        case=f"damage-{reader}:{name}",
    )


@pytest.fixture(scope="module")
def partial(good, tmp_path_factory):
    path = tmp_path_factory.mktemp("partial") / "partial.h5"
    shutil.copyfile(good[0], path)
    with h5py.File(path, "r+") as f:
        f.attrs["complete"] = False
        f.attrs["message"] = "cable 'hose': Newton did not converge [/x]"
    return path


def test_partial_result_is_said_in_lda(partial, tmp_path):
    out = tmp_path / "d.h5"
    text = cli(["lda", partial, "-o", out], ("partial result", "[/x]"), code=0, outputs=(out,))
    assert "warning" in text


def test_partial_result_is_said_in_compare(partial, good):
    cli(["compare", good[0], partial], ("partial.h5", "partial result"), code=0)


def test_partial_result_is_said_in_report(partial, tmp_path):
    out = tmp_path / "r.html"
    cli(
        ["report", partial, "-o", out, "--voxel", "none", "--frames", "2"],
        ("partial result",),
        code=0,
    )
    assert "incomplete run" in out.read_text()


# bad options of the readers, on good files
OPTION_CASES = [
    ("lda", ["--wohler-k", "-1"], ("k = -1",)),
    ("lda", ["--wohler-k", "nan"], ("k",)),
    ("lda", ["--points", "0"], ("points",)),
    ("lda", ["--plane-step", "0"], ("plane",)),
    ("lda", ["--plane-step", "7"], ("plane",)),
    ("lda", ["--section-step", "0"], ("--section-step = 0",)),
    ("lda", ["--residue", "foo"], ("residue", "'foo'")),
    ("lda", ["--hysteresis", "-1"], ("hysteresis",)),
    ("lda", ["--threads", "0"], ("threads",)),
    ("lda", ["--hot-spots", "-1"], ("--hot-spots = -1",)),
    ("lda", ["--knee-kind", "foo"], ("'foo'",)),
    ("lda", ["--knee-range", "-1"], ("knee",)),
    ("lda", ["--wohler-alpha", "0"], ("alpha",)),
    ("volume", ["--voxel", "big"], ("voxel = 'big'",)),
    ("volume", ["--voxel", "0"], ("voxel = '0'",)),
    ("volume", ["--voxel", "-1mm"], ("voxel = '-1mm'",)),
    ("volume", ["--voxel", "1e-9m"], ("voxel",)),
    ("volume", ["--unit", "km"], ("unit = 'km'",)),
    ("volume", ["--cable", "nope"], ("cable = 'nope'",)),
    ("volume", ["--compare", "none.h5"], ("none.h5", "does not exist")),
    ("volume", ["-o", "v.obj"], ("v.obj", "stl")),
    ("paraview", ["--every", "0"], ("every = 0",)),
    ("paraview", ["--cable", "nope"], ("cable = 'nope'",)),
    ("paraview", ["--damage", "none.h5"], ("none.h5", "does not exist")),
    ("report", ["--frames", "0"], ("frames",)),
    ("report", ["--frames", "-3"], ("frames",)),
    ("report", ["--color-by", "rainbow"], ("'rainbow'",)),
    ("report", ["--bend-factor", "-1"], ("bend-factor", "-1")),
    ("report", ["--bend-factor", "nan"], ("bend-factor", "nan")),
    ("report", ["--voxel", "x"], ("voxel = 'x'",)),
    ("compare", ["--hot-spots", "-1"], ("--hot-spots = -1",)),
    ("compare", ["--labels", "a,b,c"], ("labels",)),
]


@pytest.mark.parametrize(
    ("command", "options", "expect"),
    OPTION_CASES,
    ids=[f"{c}{''.join(o[:2])}" for c, o, _ in OPTION_CASES],
)
def test_bad_reader_option(good, tmp_path, monkeypatch, command, options, expect):
    monkeypatch.chdir(tmp_path)
    result, damage = good
    args = {
        "lda": ["lda", result, "-o", tmp_path / "d.h5"],
        "volume": ["volume", result, "-o", tmp_path / "v.stl"],
        "paraview": ["paraview", result, "-o", tmp_path / "p.pvd"],
        "report": ["report", result, "-o", tmp_path / "r.html"],
        "compare": ["compare", damage, damage],
    }[command]
    cli([*args, *options], expect, case=f"{command}:{' '.join(options)}")


def test_schema_output_errors(tmp_path):
    cli(["schema", "-o", tmp_path / "no" / "dir" / "s.json"], ("s.json",), case="schema:no-dir")
    cli(["schema", "-o", tmp_path], ("directory",), case="schema:dir")


def test_good_result_gives_finite_outputs(good, tmp_path):
    """The other side of the NaN rule: outputs of good files are written and finite."""
    result, damage = good
    cli(
        ["paraview", result, "--damage", damage, "-o", tmp_path / "p.pvd"],
        code=0,
        outputs=tuple(tmp_path.glob("*.vtp")),
    )
    cli(["volume", result, "-o", tmp_path / "v.stl"], code=0, outputs=(tmp_path / "v.stl",))
    assert write_scene  # the helper module is shared


@pytest.mark.parametrize("command", ["run", "lda", "volume", "paraview", "report", "signal"])
@pytest.mark.parametrize("where", ["missing-folder", "directory"])
def test_output_that_cannot_be_written(good, tmp_path, command, where):
    result, _ = good
    out = tmp_path / "no-such" / "out.x" if where == "missing-folder" else tmp_path
    spec = tmp_path / "spec.toml"
    spec.write_text(
        '[signal]\nduration = 1.0\ntime_step = 0.01\n[[channels]]\nname = "z"\n'
        'channel = "z"\nsignal = { type = "sine", amplitude = 0.01, frequency = 1.0 }\n'
    )
    args = {
        "run": ["run", write_scene(tmp_path, scene()), "-q", "-o", out],
        "lda": ["lda", result, "-o", out],
        "volume": ["volume", result, "-o", out],
        "paraview": ["paraview", result, "-o", out],
        "report": ["report", result, "-o", out, "--voxel", "none", "--frames", "2"],
        "signal": ["signal", spec, "-o", out, "--no-plot"],
    }[command]
    if where == "missing-folder" and command in ("lda", "paraview", "report"):
        cli(args, code=0, case=f"{command}:output-{where}")  # these create the folder
    else:
        cli(args, (str(out),), case=f"{command}:output-{where}")
