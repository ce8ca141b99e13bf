"""Harness speed (issue 16): a 5-branch harness, 400 segments in all.

A trunk from the car body to a junction, a second junction down the line, five branches
(two from the first junction, three from the second) to clips on the body and on the engine;
the engine shaken by the ISO 16750-3 engine PSD (as the demo), 1 ms steps. Prints medians of:
- the static equilibrium (from the routed shape): the solver's wall time and the whole
  `simulate(scene, "static")` call a user makes;
- a quasistatic run of 1 s at 1 ms steps through the PSD motion: wall time per simulated
  second (real-time factor of quasistatic sequences);
- a dynamic run (generalized-α, default damping and Newton tolerance) of 1 s at 1 ms steps
  through the PSD motion: real-time factor (simulated time / solver wall time; target ≥ 10×)
  and of the whole simulate() call, harness and single cable alternated; and the same for a
  run of 10 s (`--long S`; 0: none), where the whole call's fixed set-up weighs less.
With --contact, also the dynamic run with a tray (a plane 10 mm below the lowest clip) under
the harness and contact on: the trunk rests on it while shaken. (At 6 mm, before session 13,
the engine's clip of branch d, which the PSD moves 3.6 mm down, pressed the branch into the
tray: 34 % shear strain, outside the model's validity range.) The validity warnings of the
runs (strains, impacts) are printed at the end: the figures are for valid scenes.
One core: OpenBLAS held to one thread.
Run: python benchmarks/bench_harness.py [--repeat K] [--long S] [--contact]
"""

from __future__ import annotations

import os
import statistics
import sys
import time

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

from cablelife.scene import scene_from_dict  # noqa: E402
from cablelife.simulate import simulate  # noqa: E402
from validity_report import run_reporting_warnings  # noqa: E402

SECTION = {"shape": "circle", "radius": 0.005}
MATERIAL = {"youngs_modulus": 5.0e7, "poisson_ratio": 0.4, "density": 2000.0}


def cable(name, length, segments, clip=None):
    c = {"name": name, "length": length, "segments": segments, "section": SECTION}
    c["material"] = MATERIAL
    c["clips"] = [] if clip is None else [clip]
    return c


def clip(name, s, position, direction, body="world"):
    return {
        "name": name,
        "s": s,
        "position": position,
        "direction": direction,
        "normal": [0.0, 0.0, 1.0],
        "body": body,
    }


def scene(mode: str, duration: float | None = None) -> dict:
    psd = {"type": "psd", "profile": "iso16750-3:2007/I-engine", "f_high": 100.0, "fade_in": 0.2}
    sim = {"mode": mode, "time_step": 1e-3}
    if duration is not None:
        sim["duration"] = duration
    return {
        "simulation": sim,
        "bodies": [
            {
                "name": "engine",
                "origin": [1.0, 0.0, -0.1],
                "motion": [
                    {"channel": "z", "signal": {**psd, "seed": 1}},
                    {"channel": "x", "signal": {**psd, "seed": 2}},
                ],
            }
        ],
        # 80 + 60 + 70 + 60 + 70 + 60 = 400 segments
        "cables": [
            cable("trunk", 0.42, 80, clip("body-1", 0.0, [0.0, 0.0, 0.0], [1.0, 0.0, 0.0])),
            cable("link", 0.32, 60),
            cable("a", 0.33, 70, clip("a-end", 0.33, [0.45, 0.3, 0.0], [0.0, 1.0, 0.0])),
            cable("b", 0.33, 60, clip("b-end", 0.33, [0.45, -0.3, 0.0], [0.0, -1.0, 0.0])),
            cable(
                "c",
                0.35,
                70,
                clip("c-end", 0.35, [1.0, 0.1, -0.05], [1.0, 0.0, 0.0], "engine"),
            ),
            cable(
                "d",
                0.37,
                60,
                clip("d-end", 0.37, [1.0, -0.15, -0.1], [1.0, 0.0, 0.0], "engine"),
            ),
        ],
        "junctions": [
            {
                "name": "j1",
                "ends": ["trunk:end", "link:start", "a:start", "b:start"],
                "position": [0.4, 0.0, 0.0],
                "directions": [[-1, 0, 0], [1, 0, 0], [0.2, 1, 0], [0.2, -1, 0]],
            },
            {
                "name": "j2",
                "ends": ["link:end", "c:start", "d:start"],
                "position": [0.7, 0.0, 0.0],
                "directions": [[-1, 0, 0], [1, 0.3, 0], [1, -0.4, -0.3]],
            },
        ],
    }


def single(mode: str, duration: float) -> dict:
    """The peer: one 400-segment cable of the harness's length between the body and the
    engine, the same motion (the speed class a harness should stay in)."""
    sc = scene(mode, duration)
    sc["junctions"] = []
    sc["cables"] = [
        cable(
            "single",
            1.4,
            400,
            clip("body-1", 0.0, [0.0, 0.0, 0.0], [1.0, 0.0, 0.0]),
        )
    ]
    sc["cables"][0]["clips"].append(
        clip("c-end", 1.4, [1.0, 0.1, -0.05], [1.0, 0.0, 0.0], "engine")
    )
    return sc


#: Every run's result, kept to the end of the benchmark (`timed`).
KEPT: list = []


def timed(sc, repeat: int) -> tuple[float, float, float, float]:
    """Medians of the solver wall time, the whole simulate() call, the mean Newton
    iterations per step after the first and the CPU time of the simulate() call (one
    thread: the time on one core, whatever the machine's load). Every run's result is kept
    to the end of the benchmark (`KEPT`): each run writes its records into fresh memory, as a
    user's single run in a new process does, and no run is charged with freeing the one
    before (at 5 s that was 14 ms of the harness's whole call; freed before the next run, its
    memory would be reused without page faults: 0.078 s instead of 0.092 s of solver for the
    1 s run). Session 20: kept per call of `timed` only, the quasistatic runs' memory, freed
    before the dynamic ones, was reused by them (solver 0.070 s instead of 0.082 s)."""
    solver, whole, iters, cpu = [], [], [], []
    kept = KEPT
    for _ in range(repeat):
        t0, c0 = time.perf_counter(), time.process_time()
        res = simulate(sc)
        whole.append(time.perf_counter() - t0)
        cpu.append(time.process_time() - c0)
        kept.append(res)
        s = next(iter(res.cables.values())).solver
        solver.append(s["wall_time"])
        it = s["iterations"]
        iters.append(float(it[1:].mean()) if it.size > 1 else float(it[0]))
    return tuple(statistics.median(v) for v in (solver, whole, iters, cpu))


#: Duration of the long dynamic run (s; `--long S`, 0: none).
LONG = float(sys.argv[sys.argv.index("--long") + 1]) if "--long" in sys.argv else 10.0


def main() -> None:
    repeat = int(sys.argv[sys.argv.index("--repeat") + 1]) if "--repeat" in sys.argv else 5
    static = scene_from_dict(scene("static", 1.0))
    segments = sum(c.n_segments for c in static.cables)
    print(f"harness: {len(static.cables)} cables ({segments} segments), 2 junctions; peer: one")
    print("cable of 400 segments, same motion (medians; static of", repeat, "runs)")
    print(f"{'case':<34} {'harness':>12} {'single cable':>14}")
    hs = timed(static, repeat)
    ss = timed(scene_from_dict(single("static", 1.0)), repeat)
    print(f"{'static: solver [ms]':<34} {1e3 * hs[0]:>12.2f} {1e3 * ss[0]:>14.2f}")
    print(f"{'static: whole simulate() [ms]':<34} {1e3 * hs[1]:>12.2f} {1e3 * ss[1]:>14.2f}")
    print(f"{'static: Newton iterations':<34} {hs[2]:>12.0f} {ss[2]:>14.0f}")
    k = max(1, repeat // 2)
    hq = timed(scene_from_dict(scene("quasistatic", 1.0)), k)
    sq = timed(scene_from_dict(single("quasistatic", 1.0)), k)
    print(f"{'quasistatic 1 s @ 1 ms: solver [s]':<34} {hq[0]:>12.3f} {sq[0]:>14.3f}")
    print(f"{'  × real time':<34} {1 / hq[0]:>12.2f} {1 / sq[0]:>14.2f}")
    print(f"{'  Newton iterations per step':<34} {hq[2]:>12.2f} {sq[2]:>14.2f}")
    hd_scene = scene_from_dict(scene("dynamic", 1.0))
    sd_scene = scene_from_dict(single("dynamic", 1.0))
    hd, sd = [], []
    for _ in range(k):  # alternated: the machine's load affects both alike
        hd.append(timed(hd_scene, 1))
        sd.append(timed(sd_scene, 1))
    med = lambda runs, i: statistics.median(r[i] for r in runs)  # noqa: E731
    print(f"{'dynamic 1 s @ 1 ms: solver [s]':<34} {med(hd, 0):>12.3f} {med(sd, 0):>14.3f}")
    print(f"{'  × real time (solver)':<34} {1 / med(hd, 0):>12.2f} {1 / med(sd, 0):>14.2f}")
    whole = (1 / med(hd, 1), 1 / med(sd, 1))
    print(f"{'  × real time (whole simulate())':<34} {whole[0]:>12.2f} {whole[1]:>14.2f}")
    cpu = (1 / med(hd, 3), 1 / med(sd, 3))
    print(f"{'  × real time (simulate() CPU)':<34} {cpu[0]:>12.2f} {cpu[1]:>14.2f}")
    print(f"{'  Newton iterations per step':<34} {med(hd, 2):>12.2f} {med(sd, 2):>14.2f}")
    if LONG > 0:
        # the steady rate a user sees: the whole call's set-up (≈ 14 ms: static start, modal
        # analysis for the default damping, kinematics, checks) spread over a longer run
        hl_scene = scene_from_dict(scene("dynamic", LONG))
        sl_scene = scene_from_dict(single("dynamic", LONG))
        hl, sl = [], []
        for _ in range(max(1, k // 2)):
            hl.append(timed(hl_scene, 1))
            sl.append(timed(sl_scene, 1))
        row = f"dynamic {LONG:g} s @ 1 ms: solver [s]"
        print(f"{row:<34} {med(hl, 0):>12.3f} {med(sl, 0):>14.3f}")
        rates = (LONG / med(hl, 0), LONG / med(sl, 0))
        print(f"{'  × real time (solver)':<34} {rates[0]:>12.2f} {rates[1]:>14.2f}")
        print(
            f"{'  × real time (whole simulate())':<34} {LONG / med(hl, 1):>12.2f}"
            f" {LONG / med(sl, 1):>14.2f}"
        )
    if "--contact" in sys.argv:
        # The harness only: the single cable's span sags 38 cm below the tray's height (a
        # push-out that deep fails; docs/contact.md), it would need a tray of its own.
        tray = {"shape": "plane", "name": "tray", "point": [0, 0, -0.110], "normal": [0, 0, 1]}
        d = scene("dynamic", 1.0)
        d["bodies"].append({"name": "tray", "geometry": [tray]})
        d["contact"] = {"enabled": True}
        hc = [timed(scene_from_dict(d), 1) for _ in range(k)]
        print(f"{'dynamic on a tray, contact: solver':<34} {med(hc, 0):>12.3f} {'-':>14}")
        print(f"{'  × real time (solver)':<34} {1 / med(hc, 0):>12.2f} {'-':>14}")
        print(f"{'  × real time (whole simulate())':<34} {1 / med(hc, 1):>12.2f} {'-':>14}")
        print(f"{'  Newton iterations per step':<34} {med(hc, 2):>12.2f} {'-':>14}")


if __name__ == "__main__":
    run_reporting_warnings(main)
