"""Modal analysis speed and memory: the banded Rust solver against the former dense one.

The 1 m, three-clip hose of examples/hose-three-clips.toml with N = 100 … 2000 segments, the 6
lowest modes. Each measurement is a fresh process (``--one``) so that its peak RSS is its own;
the time is the whole ``cable_modes`` call (static equilibrium, assembly, eigen solver).
Medians of --repeat runs. The dense solver runs only up to --dense-max segments (at 2000 it
needs ~6 GB and minutes).
Run: python benchmarks/bench_modal.py [--repeat 3] [--dense-max 1000]
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import time
from pathlib import Path

EXAMPLE = Path(__file__).parent.parent / "examples" / "hose-three-clips.toml"


def one(segments: int, solver: str) -> None:
    """Child process: one modal analysis; prints seconds, peak RSS and the frequencies."""
    from cablelife import modal
    from cablelife.scene import load_scene

    scene = load_scene(EXAMPLE)
    cable = scene.cables[0].model_copy(update={"segments": segments})
    fn = modal.cable_modes if solver == "banded" else modal.cable_modes_dense
    start = time.perf_counter()
    m = fn(scene, cable, 6)
    wall = time.perf_counter() - start
    rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024  # MB (Linux: kB)
    print(json.dumps({"wall": wall, "rss": rss, "f": m.frequencies.tolist()}))


def measure(segments: int, solver: str, repeat: int) -> dict:
    runs = []
    for _ in range(repeat):
        env = dict(os.environ, OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1")
        out = subprocess.run(
            [sys.executable, __file__, "--one", str(segments), solver],
            capture_output=True,
            text=True,
            check=True,
            env=env,
        )
        runs.append(json.loads(out.stdout.strip().splitlines()[-1]))
    return {
        "wall": statistics.median(r["wall"] for r in runs),
        "rss": statistics.median(r["rss"] for r in runs),
        "f": runs[0]["f"],
    }


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--dense-max", type=int, default=1000)
    ap.add_argument("--one", nargs=2)
    args = ap.parse_args()
    if args.one:
        one(int(args.one[0]), args.one[1])
        return
    # baseline: the interpreter with cablelife and scipy imported (no modal analysis)
    base = subprocess.run(
        [
            sys.executable,
            "-c",
            "import resource, cablelife.modal, scipy.linalg;"
            "print(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024)",
        ],
        capture_output=True,
        text=True,
        check=True,
    )
    print(f"process baseline (imports only): peak RSS {float(base.stdout):.0f} MB")
    print(
        f"{'N':>5} | {'dense s':>9} {'dense MB':>9} | {'banded s':>9} {'banded MB':>9} | "
        f"{'speed-up':>8} | max |Δf|/f"
    )
    for n in (100, 500, 1000, 2000):
        b = measure(n, "banded", args.repeat)
        if n <= args.dense_max:
            d = measure(n, "dense", args.repeat)
            diff = max(abs(x - y) / y for x, y in zip(b["f"], d["f"], strict=True))
            print(
                f"{n:5d} | {d['wall']:9.3f} {d['rss']:9.0f} | {b['wall']:9.3f} {b['rss']:9.0f} | "
                f"{d['wall'] / b['wall']:8.0f} | {diff:.1e}"
            )
        else:
            print(
                f"{n:5d} | {'-':>9} {'-':>9} | {b['wall']:9.3f} {b['rss']:9.0f} | "
                f"{'-':>8} | f1 = {b['f'][0]:.4f} Hz"
            )


if __name__ == "__main__":
    main()
