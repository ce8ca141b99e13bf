"""The demo's HTML report (issue 14): its size, the time to generate it from the run folders
(median of --repeat), and its load in headless Chromium (median of --repeat fresh browsers):
the time until the first screen is drawn (the page's own data-render-ms since navigation
start), each other figure's drawing time as the checker scrolls to it (the page draws figures
lazily; data-ms), and their sum (first screen + every figure on demand), with the figures that
rendered and any overlapping text boxes; and the CPU time chromium's processes spent from
the navigation until every figure was drawn (on this shared machine the wall times grow with
the load, the CPU time much less: on an idle 2-core machine the page takes about the CPU time
or less). An older page that draws everything at once has only the first number (every
figure). Generation: wall and CPU time (all threads) of the process.

    python benchmarks/bench_report.py [DEMO_DIR] [--repeat 3] [--page report.html]

DEMO_DIR: the output of ``cablelife demo --no-report`` (default: run it into a temporary
folder first). ``--page`` measures only the load time of an existing page (e.g. of an older
version, whose page has no data-render-ms: then the time until its own check, minus the
1.5 s it waits, is printed).
"""

from __future__ import annotations

import argparse
import os
import statistics
import tempfile
import time
import warnings
from pathlib import Path

from cablelife.report.browser import check_page


def load_times(page: Path, repeat: int) -> None:
    seen = [check_page(page) for _ in range(repeat)]
    last = seen[-1]
    old = all(s.load_s < 0 for s in seen)  # an older page: no data-render-ms
    loads = [s.wall_s - 1.5 if old else s.load_s for s in seen]
    cpus = [s.cpu_s for s in seen]
    med = statistics.median
    if not old and any(s.on_demand_ms for s in seen):
        firsts = [s.first_screen_s for s in seen]
        each = [ms / 1e3 for s in seen for ms in s.on_demand_ms]
        print(
            f"first screen drawn: median {med(firsts):.2f} s (min {min(firsts):.2f}, max "
            f"{max(firsts):.2f}); each other figure when scrolled to: median {med(each):.2f} s, "
            f"max {max(each):.2f} s ({len(last.on_demand_ms)} figures)"
        )
    print(
        f"load in headless chromium (first screen + every figure on demand): median "
        f"{med(loads):.2f} s (min {min(loads):.2f}, max {max(loads):.2f}, n = {repeat}"
        + (", older page: time to its check − 1.5 s" if old else "")
        + f"); figures rendered {last.rendered}/{last.expected}, script errors "
        f"{len(last.errors)}, overlapping text boxes {len(last.overlaps)}, text cut off at a "
        f"figure's edge {len(last.clipped)}"
    )
    print(
        f"chromium CPU time, navigation to every figure drawn: median {med(cpus):.2f} s "
        f"(min {min(cpus):.2f}, max {max(cpus):.2f}); load average {os.getloadavg()[0]:.1f}"
    )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("demo_dir", nargs="?", type=Path)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--page", type=Path, help="only the load time of this page")
    args = ap.parse_args()
    if args.page is not None:
        print(f"{args.page}: {args.page.stat().st_size / 1e6:.2f} MB")
        load_times(args.page, args.repeat)
        return
    from cablelife.demo import _write_report, demo_runs, run_demo

    with tempfile.TemporaryDirectory() as tmp:
        folder = args.demo_dir
        if folder is None:
            folder = Path(tmp) / "demo"
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                run_demo(folder, report=False)
        runs = demo_runs()
        times, cpus = [], []
        for _ in range(args.repeat):
            t0, c0 = time.perf_counter(), time.process_time()
            page = _write_report(folder, runs, 24)
            times.append(time.perf_counter() - t0)
            cpus.append(time.process_time() - c0)
        print(
            f"report of the demo (4 runs): {page.stat().st_size / 1e6:.2f} MB, generated in "
            f"median {statistics.median(times):.2f} s wall (min {min(times):.2f}), CPU median "
            f"{statistics.median(cpus):.2f} s (min {min(cpus):.2f}), n = {args.repeat}; "
            "results and damage files read included"
        )
        load_times(page, args.repeat)


if __name__ == "__main__":
    main()
