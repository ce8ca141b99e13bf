"""Result files: compressed and chunked (lossless by default), float32 histories on request,
readable with plain h5py, and read lazily (a command reads only the datasets it uses)."""

import os

import cablelife
import h5py
import numpy as np
import pytest
from cablelife.results import Deferred, load_result, save_result

SCENE = """
[simulation]
mode = "dynamic"
duration = 0.3
time_step = 0.002
output_precision = "{precision}"

[[bodies]]
name = "shaker"
[[bodies.motion]]
channel = "z"
signal = {{ type = "sine", amplitude = 0.004, frequency = 8.0, fade_in = 0.05 }}

[[cables]]
name = "hose"
length = 0.6
segments = 30
section = {{ shape = "circle", radius = 0.004 }}
material = {{ youngs_modulus = 5e7, poisson_ratio = 0.4, density = 1200.0 }}

[[cables.clips]]
name = "a"
s = 0.0
position = [0.0, 0.0, 0.0]
direction = [1.0, 0.0, 0.0]
type = "fixed"

[[cables.clips]]
name = "b"
s = 0.6
position = [0.5, 0.0, 0.0]
direction = [1.0, 0.0, 0.0]
type = "fixed"
body = "shaker"
"""


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    out = {}
    for precision in ("float64", "float32"):
        d = tmp_path_factory.mktemp(precision)
        (d / "scene.toml").write_text(SCENE.format(precision=precision))
        scene = cablelife.load_scene(d / "scene.toml")
        result = cablelife.simulate(scene)
        out[precision] = (result, result.save(d / "run.h5"))
    return out


HISTORIES = ["positions", "quaternions", "forces", "moments"]


def test_histories_are_chunked_and_compressed_and_plain_h5py_reads_them(runs):
    result, path = runs["float64"]
    with h5py.File(path, "r") as f:
        g = f["cables/hose"]
        for key in HISTORIES:
            ds = g[key]
            assert ds.compression == "gzip" and ds.shuffle and ds.chunks is not None, key
            np.testing.assert_array_equal(ds[()], getattr(result.cable, key))  # lossless
        np.testing.assert_array_equal(
            g["clips/b/reaction_force"][()], result.cable.clips["b"].force
        )
        assert f.attrs["precision"] == "float64"


def test_float32_history_halves_and_reads_back_as_float64(runs):
    r64, p64 = runs["float64"]
    r32, p32 = runs["float32"]
    with h5py.File(p32, "r") as f:
        assert f["cables/hose/forces"].dtype == np.float32
        assert f["cables/hose/time"].dtype == np.float64  # time and arc length stay exact
        assert f.attrs["precision"] == "float32"
    back = load_result(p32)
    assert back.precision == "float32"
    for key in HISTORIES:
        a = getattr(back.cable, key)
        assert a.dtype == np.float64
        want = getattr(r32.cable, key)
        scale = np.abs(want).max()
        np.testing.assert_allclose(a, want, rtol=0, atol=scale * 2.0**-23)
    size64 = sum(f.stat().st_size for f in [p64])
    assert p32.stat().st_size < 0.7 * size64


def test_lazy_reading_reads_only_what_is_used(runs):
    _, path = runs["float64"]
    r = load_result(path)
    c = r.cable
    for key in HISTORIES:
        assert isinstance(c.__dict__["_" + key], Deferred)
    c.forces  # noqa: B018 — read one
    assert isinstance(c.__dict__["_forces"], np.ndarray)
    assert isinstance(c.__dict__["_positions"], Deferred)
    eager = load_result(path, lazy=False)
    for key in HISTORIES:
        assert isinstance(eager.cable.__dict__["_" + key], np.ndarray)
        np.testing.assert_array_equal(getattr(eager.cable, key), getattr(c, key))


def test_lda_reads_only_loads_and_volume_only_positions(runs):
    from cablelife.lda import analyse
    from cablelife.volume import motion_volume

    _, path = runs["float64"]
    r = load_result(path)
    analyse(r)
    untouched = [k for k in HISTORIES if isinstance(r.cable.__dict__["_" + k], Deferred)]
    assert set(untouched) >= {"positions", "quaternions"}
    r = load_result(path)
    motion_volume(r, 0.004)
    untouched = [k for k in HISTORIES if isinstance(r.cable.__dict__["_" + k], Deferred)]
    assert set(untouched) >= {"forces", "moments"}


def test_bad_precision_is_refused(runs, tmp_path):
    result, _ = runs["float64"]
    with pytest.raises(ValueError, match="precision = 'float16'"):
        save_result(result, tmp_path / "x.h5", precision="float16")
    assert not (tmp_path / "x.h5").exists()


@pytest.mark.parametrize("dtype", ["<f8", "<f4", ">f8", "u1", "<i8"])
def test_parallel_deflate_writes_the_chunks_hdf5_would_write(tmp_path, dtype):
    """`put_deflated` (chunks shuffled and deflated in threads, written directly) gives, chunk
    by chunk, the very bytes of h5py's own shuffle + gzip pipeline, the last (partial) chunk
    too, and reads back equal with the standard filters."""
    from cablelife.h5files import put_deflated

    rng = np.random.default_rng(3)
    a = np.cumsum(rng.normal(size=(1000, 37, 3)), axis=0)  # 4 chunks of 256 rows, the last partial
    a = (a * 10).astype(dtype)
    with h5py.File(tmp_path / "ours.h5", "w") as f, h5py.File(tmp_path / "ref.h5", "w") as g:
        ours = put_deflated(f, "x", a, 256, 1)
        little = a.astype(a.dtype.newbyteorder("<"))  # big-endian input is stored little-endian
        ref = g.create_dataset(
            "x", data=little, chunks=(256, 37, 3), compression="gzip", compression_opts=1,
            shuffle=True,
        )  # fmt: skip
        assert ours.chunks == ref.chunks and ours.compression == "gzip" and ours.shuffle
        for start in range(0, 1000, 256):
            at = (start, 0, 0)
            assert ours.id.read_direct_chunk(at) == ref.id.read_direct_chunk(at), (dtype, start)
    with h5py.File(tmp_path / "ours.h5") as f:
        back = f["x"][()]
    assert back.dtype == a.dtype.newbyteorder("<") and np.array_equal(back, a)


def _write_deflated(path, a):
    from cablelife.h5files import put_deflated

    with h5py.File(path, "w") as f:
        put_deflated(f, "x", a, 256, 1)


@pytest.mark.skipif(not hasattr(os, "fork"), reason="needs fork")
def test_a_forked_child_writes_with_its_own_compression_threads(tmp_path):
    """A process forked after the parent compressed in threads (a study worker, a user's
    multiprocessing) has a copy of the pool without its threads: without its own pool it hung
    forever at its first save. The join's bound is a hang detector, not a speed test."""
    import multiprocessing

    a = np.random.default_rng(0).random((2000, 101, 3))
    _write_deflated(tmp_path / "parent.h5", a)  # the parent's pool is running
    child = multiprocessing.get_context("fork").Process(
        target=_write_deflated, args=(tmp_path / "child.h5", a)
    )
    child.start()
    child.join(120)
    hung = child.is_alive()
    if hung:
        child.kill()
    assert not hung and child.exitcode == 0
    with h5py.File(tmp_path / "child.h5") as f:
        assert np.array_equal(f["x"][()], a)
