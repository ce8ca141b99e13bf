"""Workbench update rate end to end: `cablelife workbench` in its own process, its page in
headless Chromium; each update is a test-hook call (moveClip / moveClips) that resolves when
the new equilibrium is drawn: page → websocket → warm static solve (Rust) → JSON → tube
rebuilt and rendered. Targets (issue 17): ≥ 25 updates/s for a 100-segment cable, ≥ 10 for
five cables moved together and ≥ 10 for a harness (examples/harness/scene.toml: four cables,
150 segments, one junction; its engine-bracket clip dragged, the whole tree re-solved). Also
the solve alone (Session.move_clips, no server), and the body-motion slider (showTime: the
bodies' motion at the steps of the quasistatic grid, one warm static equilibrium each).

    python benchmarks/bench_workbench.py [--updates 200]
"""

from __future__ import annotations

import argparse
import json
import statistics
import tempfile
import time
from pathlib import Path

import numpy as np
import tomli_w

ROOT = Path(__file__).resolve().parents[1]


def scene(cables: int, segments: int) -> dict:
    """`cables` copies of the example hose side by side (10 cm apart), `segments` each."""
    import tomllib

    base = tomllib.loads((ROOT / "examples" / "hose-three-clips.toml").read_text())
    proto = base["cables"][0]
    proto["segments"] = segments
    out = []
    for i in range(cables):
        c = {**proto, "name": f"hose{i}", "clips": []}
        for clip in proto["clips"]:
            p = list(clip["position"])
            p[1] += 0.1 * i
            c["clips"].append({**clip, "position": p})
        out.append(c)
    base["cables"] = out
    return base


HARNESS = ROOT / "examples" / "harness" / "scene.toml"
HARNESS_CLIP = ("engine", "engine-bracket", np.array([0.8, 0.15, -0.05]))


def harness_path(k: int, n: int) -> list[float]:
    """The harness's engine-bracket clip at update k of n: a 3 cm circle (twice)."""
    a = 4 * np.pi * k / n
    return (HARNESS_CLIP[2] + 0.03 * np.array([0.0, np.sin(a), 1 - np.cos(a)])).tolist()


def moves_of(scene_file: Path, cables: int, k: int, n: int) -> list[list]:
    if scene_file == HARNESS:
        return [[HARNESS_CLIP[0], HARNESS_CLIP[1], harness_path(k, n)]]
    return [[f"hose{i}", "engine-bracket", path(i, k, n)] for i in range(cables)]


def path(i: int, k: int, n: int) -> list[float]:
    """Clip position of cable i at update k of n: the end clip circles 4 cm (twice)."""
    a = 4 * np.pi * k / n
    return [0.75, float(0.25 + 0.1 * i + 0.04 * np.sin(a)), float(0.04 * (1 - np.cos(a)))]


def end_to_end(scene_file: Path, cables: int, updates: int, motion: bool = False) -> dict:
    """Updates per second through the page: clip moves, or (``motion``) time-slider steps
    running forwards through the quasistatic grid (and round again)."""
    from cablelife.workbench.drive import run_page, workbench_process

    async def script(page):
        lat, solve = [], []
        steps = (await page.call("motionInfo()"))["steps"] if motion else 0
        t0 = time.perf_counter()
        for k in range(updates):
            t = time.perf_counter()
            if motion:
                r = await page.call(f"showTime({k % steps})")
            else:
                moves = moves_of(scene_file, cables, k, updates)
                r = await page.call(f"moveClips({json.dumps(moves)})")
            if "error" in r:
                raise RuntimeError(r["error"])
            lat.append(time.perf_counter() - t)
            solve.append(r["solveMs"])
        wall = time.perf_counter() - t0
        return wall, lat, solve, await page.call("stats()")

    with workbench_process(scene_file) as (_, url):
        wall, lat, solve, stats = run_page(url, script)
    return {"rate": updates / wall, "latency_ms": 1e3 * statistics.median(lat),
            "solve_ms": statistics.median(solve), "stats": stats}  # fmt: skip


def solve_only(scene_file: Path, cables: int, updates: int) -> float:
    from cablelife.workbench.session import Session

    s = Session.open(scene_file)
    t0 = time.perf_counter()
    for k in range(updates):
        s.move_clips([{"cable": c, "clip": clip, "position": p}
                      for c, clip, p in moves_of(scene_file, cables, k, updates)])  # fmt: skip
    s.close()
    return updates / (time.perf_counter() - t0)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--updates", type=int, default=200)
    args = ap.parse_args()
    print(f"{'case':<34}{'end to end':>14}{'median latency':>16}{'server solve':>14}"
          f"{'solve only':>14}")  # fmt: skip
    with tempfile.TemporaryDirectory() as tmp:
        for cables, target in ((1, 25), (5, 10)):
            f = Path(tmp) / f"bench{cables}.toml"
            f.write_text(tomli_w.dumps(scene(cables, 100)))
            e2e = end_to_end(f, cables, args.updates)
            only = solve_only(f, cables, args.updates)
            name = f"{cables} cable(s) x 100 segments"
            print(
                f"{name:<34}{e2e['rate']:>9.1f} up/s{e2e['latency_ms']:>13.2f} ms"
                f"{e2e['solve_ms']:>11.2f} ms{only:>9.0f} up/s   (target >= {target} up/s)"
            )
        e2e = end_to_end(Path(tmp) / "bench1.toml", 1, args.updates, motion=True)
        name = "motion slider, 1 cable"
        print(
            f"{name:<34}{e2e['rate']:>9.1f} up/s{e2e['latency_ms']:>13.2f} ms"
            f"{e2e['solve_ms']:>11.2f} ms{'':>14}   (target >= 25 up/s)"
        )
    e2e = end_to_end(HARNESS, 1, args.updates)
    only = solve_only(HARNESS, 1, args.updates)
    name = "harness 4 cables, 150 segments"
    print(
        f"{name:<34}{e2e['rate']:>9.1f} up/s{e2e['latency_ms']:>13.2f} ms"
        f"{e2e['solve_ms']:>11.2f} ms{only:>9.0f} up/s   (target >= 10 up/s)"
    )
    e2e = end_to_end(HARNESS, 1, args.updates, motion=True)
    name = "motion slider, harness"
    print(
        f"{name:<34}{e2e['rate']:>9.1f} up/s{e2e['latency_ms']:>13.2f} ms"
        f"{e2e['solve_ms']:>11.2f} ms{'':>14}   (target >= 10 up/s)"
    )


if __name__ == "__main__":
    main()
