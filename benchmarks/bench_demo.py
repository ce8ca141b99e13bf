"""The application example end to end, and a variant study on 1 and 2 Dask workers (issue 7).

1. ``cablelife demo`` as the README runs it: both variants dynamically and quasistatically
   (5 s at 1 ms each), the LDA, the comparison and the report: wall time per stage.
2. A 20-variant study (examples/clip-variants: body-2 shift × 4 cable lengths × 5 shifts,
   ``--duration`` s each, dynamic, default LDA, 4 mm motion volume) on a local cluster of 1 and
   of 2 worker processes: wall time (cluster start included), per-variant time and the speed-up.

3. ``--process PY [PY …]``: ``PY -m cablelife demo -o DIR`` as a whole process (imports
   included), the interpreters (e.g. the venvs of an older checkout and of this one) taking
   turns ``--repeat`` times: median wall and CPU time (the process and its children, os.wait4)
   of each, with the load average (on a shared machine compare them side by side).

    python benchmarks/bench_demo.py [--duration 1.0] [--skip-demo] [--skip-study]
    python benchmarks/bench_demo.py --process OLD/bin/python NEW/bin/python --repeat 3
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import tempfile
import time
import warnings
from pathlib import Path

from cablelife.demo import run_demo
from cablelife.study import run_study

ROOT = Path(__file__).resolve().parents[1]

STUDY = """
[study]
name = "bench-20"
scene = "{scene}"
mode = "dynamic"
duration = {duration}
combine = "grid"

[[parameters]]
name = "shift"
kind = "clip_position"
clip = "body-2"
direction = [1.0, 0.25, -0.125]
values = [0.0, 0.01, 0.02, 0.03, 0.04]

[[parameters]]
name = "length"
kind = "cable_length"
values = [1.25, 1.26, 1.27, 1.28]
"""


def bench_demo() -> None:
    with tempfile.TemporaryDirectory() as tmp, warnings.catch_warnings():
        warnings.simplefilter("ignore")
        t0 = time.perf_counter()
        out = run_demo(Path(tmp) / "demo")
        total = time.perf_counter() - t0
    print(f"demo end to end: {total:.1f} s (4 runs of 5 s at 1 ms, LDA, comparison, report)")
    for stage, seconds in out.stage_times.items():
        print(f"  {stage:45s} {seconds:7.2f} s")
    best = out.comparison.variants
    print(f"  ranking: {' < '.join(v.label for v in best)}, ratio {best[-1].ratio:.2f}")


def bench_study(duration: float) -> None:
    text = STUDY.format(
        scene=(ROOT / "examples/clip-variants/scene.toml").as_posix(), duration=duration
    )
    walls = {}
    for workers in (1, 2):
        with tempfile.TemporaryDirectory() as tmp:
            path = Path(tmp) / "study.toml"
            path.write_text(text)
            t0 = time.perf_counter()
            outcome = run_study(path, Path(tmp) / "out", workers=workers)
            walls[workers] = time.perf_counter() - t0
            ok = (outcome.table["status"] == "ok").sum()
            per = outcome.table[["simulation_s", "lda_s", "volume_s"]].sum(axis=1).median()
        print(
            f"study of 20 variants ({duration:g} s each), {workers} worker(s): "
            f"{walls[workers]:.1f} s wall, {ok}/20 ok, median {per:.2f} s per variant "
            "(simulation + LDA + volume)"
        )
    print(f"speed-up 2 vs 1 worker: {walls[1] / walls[2]:.2f}")


def bench_process(pythons: list[str], repeat: int) -> None:
    walls: dict[str, list[float]] = {p: [] for p in pythons}
    cpus: dict[str, list[float]] = {p: [] for p in pythons}
    loads = []
    with tempfile.TemporaryDirectory() as tmp:
        for k in range(repeat):
            for i, py in enumerate(pythons):
                out = Path(tmp) / f"demo-{i}-{k}"
                loads.append(os.getloadavg()[0])
                t0 = time.perf_counter()
                proc = subprocess.Popen(
                    [py, "-m", "cablelife", "demo", "-o", str(out)],
                    stdout=subprocess.DEVNULL,
                    stderr=subprocess.DEVNULL,
                    cwd=tmp,
                )
                _, status, ru = os.wait4(proc.pid, 0)
                walls[py].append(time.perf_counter() - t0)
                cpus[py].append(ru.ru_utime + ru.ru_stime)
                if os.waitstatus_to_exitcode(status) != 0:
                    raise SystemExit(f"{py} -m cablelife demo failed")
    med = statistics.median
    for py in pythons:
        w, c = walls[py], cpus[py]
        print(
            f"{py}: demo as a process: wall median {med(w):.2f} s (min {min(w):.2f}, max "
            f"{max(w):.2f}), CPU median {med(c):.2f} s (min {min(c):.2f}), n = {repeat}"
        )
    print(f"load average during the runs: {min(loads):.1f} – {max(loads):.1f}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--duration", type=float, default=1.0, help="simulated s per study variant")
    ap.add_argument("--skip-demo", action="store_true")
    ap.add_argument("--skip-study", action="store_true")
    ap.add_argument("--process", nargs="+", metavar="PYTHON", help="whole-process demo timing")
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()
    if args.process:
        bench_process(args.process, args.repeat)
        return
    if not args.skip_demo:
        bench_demo()
    if not args.skip_study:
        bench_study(args.duration)


if __name__ == "__main__":
    main()
