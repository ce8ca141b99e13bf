"""Result-file size and speed (issue 14): the histories of one run written with each HDF5
filter (none, lzf, gzip 1 and 4, with byte shuffling) in float64 and float32: size, MB per
simulated second, write and read time (all histories; forces + moments only, as the LDA reads);
and ``cablelife lda`` as a whole process on the uncompressed float64 file and on the file as
cablelife writes it (median of several runs).

    python benchmarks/bench_results.py [RESULT.h5] [--repeat 3]

Without RESULT.h5, variant A of examples/clip-variants (5 s, 1 ms) is simulated first.
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import cablelife
import h5py
from cablelife import results
from cablelife.h5files import put_deflated
from cablelife.results import COMPRESSION, load_result, save_result

ROOT = Path(__file__).resolve().parents[1]
KEYS = ("positions", "quaternions", "forces", "moments")
FILTERS = {
    "none": {},
    "lzf + shuffle": {"compression": "lzf", "shuffle": True},
    "gzip 1 + shuffle": {"compression": "gzip", "compression_opts": 1, "shuffle": True},
    "gzip 4 + shuffle": {"compression": "gzip", "compression_opts": 4, "shuffle": True},
    "gzip 1 + sh., threads": "parallel",  # cablelife.h5files.put_deflated (what cablelife writes)
}


def median_time(fn, repeat: int) -> float:
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def filters_table(result, tmp: Path, repeat: int) -> None:
    c = result.cable
    seconds = float(c.time[-1] - c.time[0])
    data = {k: getattr(c, k) for k in KEYS}
    print(f"{c.n_steps} saved steps, {c.arc_length.size - 1} segments, {seconds:g} s simulated")
    print(
        f"{'filter':21s} {'dtype':8s} {'MB':>7s} {'MB/s sim':>9s} {'write':>7s} {'read':>7s} "
        f"{'read F,M':>9s}"
    )
    for dtype in ("float64", "float32"):
        for name, opts in FILTERS.items():
            path = tmp / "f.h5"

            def write(opts=opts, dtype=dtype, path=path):
                with h5py.File(path, "w") as f:
                    for k, a in data.items():
                        if opts == "parallel":  # cablelife's writer: the same bytes, in threads
                            put_deflated(f, k, a.astype(dtype), 256, 1)
                            continue
                        chunks = (min(256, a.shape[0]), *a.shape[1:]) if opts else None
                        f.create_dataset(k, data=a.astype(dtype), chunks=chunks, **opts)

            def read(keys, path=path):
                with h5py.File(path, "r") as f:
                    for k in keys:
                        f[k][()]

            tw = median_time(write, repeat)
            mb = path.stat().st_size / 1e6
            tr = median_time(lambda: read(KEYS), repeat)
            tl = median_time(lambda: read(("forces", "moments")), repeat)
            print(
                f"{name:21s} {dtype:8s} {mb:7.2f} {mb / seconds:9.2f} {tw:6.3f}s {tr:6.3f}s "
                f"{tl:8.3f}s"
            )


def lda_process(path: Path, repeat: int) -> float:
    cli = Path(sys.executable).parent / "cablelife"
    cmd = [str(cli) if cli.exists() else sys.executable, "lda", str(path), "-o"]
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    out = path.with_suffix(".damage.h5")
    return median_time(
        lambda: subprocess.run([*cmd, str(out)], check=True, capture_output=True, env=env), repeat
    )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("result", nargs="?", type=Path)
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        if args.result is None:
            scene = cablelife.load_scene(ROOT / "examples/clip-variants/scene.toml")
            result = cablelife.simulate(scene)
        else:
            result = load_result(args.result, lazy=False)
        filters_table(result, tmp, args.repeat)
        raw = tmp / "raw.h5"  # as cablelife wrote results before: float64, no filter
        results.COMPRESSION, kept = {}, results.COMPRESSION
        save_result(result, raw, precision="float64")
        results.COMPRESSION = kept
        for label, path, precision in (
            ("uncompressed float64", raw, None),
            ("gzip 1 + shuffle float64", tmp / "f64.h5", "float64"),
            ("gzip 1 + shuffle float32", tmp / "f32.h5", "float32"),
        ):
            if precision is not None:
                save_result(result, path, precision=precision)
            t = lda_process(path, args.repeat)
            mb = path.stat().st_size / 1e6
            print(f"cablelife lda, {label:26s} {mb:6.1f} MB: median {t:.2f} s")
    print(f"(cablelife writes {COMPRESSION})")


if __name__ == "__main__":
    main()
