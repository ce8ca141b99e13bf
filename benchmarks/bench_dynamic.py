"""Dynamic simulation speed (issue 3).

A 1.2 m cable, four clips, two of them on a bracket excited by a 10–200 Hz random motion of
2 mm RMS (vertical), simulated 5 s at 1 ms: wall time, real-time factor, Newton iterations per
step; then how the cost scales with N = 25 … 400 (1 s each) and with the number of steps.
The solver wall time includes the static equilibrium at t = 0 (≈ 5 ms at N = 100) and the
start-up transient. One core: OpenBLAS is held to one thread (the modal analysis otherwise
leaves a worker thread spinning on the second core while the solver runs).
Run: python benchmarks/bench_dynamic.py [--quick] [--repeat K]   (K runs of the headline case,
     median and spread)
     python benchmarks/bench_dynamic.py --dump N DURATION FILE   (the scene, clip kinematics and
     damping as text for `cargo run --release -p cablelife-rod --example replay_dynamic -- FILE`)
"""

from __future__ import annotations

import os
import statistics
import sys
import time

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402
from cablelife.scene import scene_from_dict  # noqa: E402
from cablelife.simulate import simulate  # noqa: E402
from validity_report import run_reporting_warnings  # noqa: E402

RMS = 2e-3
BAND = (10.0, 200.0)


def scene(segments: int, duration: float) -> dict:
    level = RMS**2 / (BAND[1] - BAND[0])  # flat displacement PSD, m²/Hz
    psd = {
        "type": "psd",
        "quantity": "displacement",
        "seed": 7,
        "fade_in": 0.1,  # start at rest, as dynamic runs should (no start-up transient)
        "breakpoints": [[BAND[0], level], [BAND[1], level]],
    }
    return {
        "simulation": {
            "mode": "dynamic",
            "duration": duration,
            "time_step": 1e-3,
            "output_step": 5e-3,
        },
        "bodies": [
            {
                "name": "bracket",
                "origin": [0.9, 0.2, 0.0],
                "motion": [{"channel": "z", "signal": psd}],
            }
        ],
        "cables": [
            {
                "name": "cable",
                "length": 1.2,
                "segments": segments,
                "section": {"shape": "circle", "radius": 0.005},
                "material": {"youngs_modulus": 1.0e8, "poisson_ratio": 0.45, "density": 2200.0},
                "damping": {"ratio": 0.2},
                "clips": [
                    {"name": "body-1", "s": 0.0, "position": [0, 0, 0], "direction": [1, 0, 0]},
                    {
                        "name": "body-2",
                        "s": 0.4,
                        "position": [0.36, 0.05, -0.05],
                        "direction": [1, 0.2, 0],
                    },
                    {
                        "name": "bracket-1",
                        "s": 0.8,
                        "body": "bracket",
                        "position": [0.7, 0.15, -0.02],
                        "direction": [1, 0.1, 0],
                    },
                    {
                        "name": "bracket-2",
                        "s": 1.2,
                        "body": "bracket",
                        "position": [1.0, 0.25, 0.0],
                        "direction": [1, 0, 0],
                    },
                ],
            }
        ],
    }


# Every run's result is kept to the end: each run writes its records into fresh memory, as a
# user's single run in a new process does (freed before the next run, its memory would be
# reused without page faults and the run look faster than any user's; docs/harness.md).
KEPT: list = []


def run(segments: int, duration: float) -> tuple[float, float, float]:
    sc = scene_from_dict(scene(segments, duration))
    t0 = time.perf_counter()
    res = simulate(sc).cable
    KEPT.append(res)
    total = time.perf_counter() - t0
    wall = res.solver["wall_time"]
    return wall, total, float(np.mean(res.solver["iterations"][1:]))


def dump(segments: int, duration: float, path: str) -> None:
    """Writes the inputs of the Rust dynamic run as text (see crates/rod/examples)."""
    from cablelife.modal import retardation_times
    from cablelife.simulate import clip_kinematics, clip_poses

    sc = scene_from_dict(scene(segments, duration))
    cable = sc.cables[0]
    props = cable.properties()
    h = sc.simulation.time_step
    times = np.arange(int(round(duration / h)) + 1) * h
    tau_shear, tau_bend, _ = retardation_times(sc, cable)
    kin = clip_kinematics(sc, cable, times)
    pos0, quat0 = clip_poses(sc, cable, np.array([0.0]), with_motion=False)

    def row(values) -> str:
        return " ".join(repr(float(v)) for v in values) + "\n"

    with open(path, "w", encoding="utf-8") as f:
        f.write(f"{cable.length} {cable.n_segments}\n")
        f.write(
            row(
                [*props.shear_stiffness, *props.bend_stiffness, props.mass_per_length]
                + list(props.rotary_inertia)
            )
        )
        f.write(row([*cable.natural_curvature, *sc.simulation.gravity]))
        f.write(f"{len(cable.clips)}\n")
        for j, c in enumerate(cable.clips):
            f.write(f"{c.s} {c.length} {c.type} " + row([*pos0[0, j], *quat0[0, j]]))
        f.write(row([*tau_shear, *tau_bend, sc.simulation.spectral_radius, h]))
        f.write(f"{times.size}\n")
        keys = (
            "positions",
            "quaternions",
            "velocities",
            "angular_velocities",
            "accelerations",
            "angular_accelerations",
        )
        for k in range(times.size):
            for j in range(len(cable.clips)):
                f.write(row(np.concatenate([kin[key][k, j] for key in keys])))


def main() -> None:
    if "--dump" in sys.argv:
        i = sys.argv.index("--dump")
        dump(int(sys.argv[i + 1]), float(sys.argv[i + 2]), sys.argv[i + 3])
        return
    quick = "--quick" in sys.argv
    repeat = int(sys.argv[sys.argv.index("--repeat") + 1]) if "--repeat" in sys.argv else 1
    duration = 1.0 if quick else 5.0
    runs = [run(100, duration) for _ in range(repeat)]
    walls = sorted(r[0] for r in runs)
    wall, total, its = statistics.median(walls), runs[0][1], runs[0][2]
    print(f"N = 100, {duration:g} s at 1 ms ({int(duration / 1e-3)} steps), 10–200 Hz, 2 mm RMS:")
    print(
        f"  solver wall {wall:.3f} s (with set-up and modal analysis {total:.3f} s), "
        f"real-time factor {wall / duration:.4f} → {duration / wall:.1f}× faster than real time,"
        f" {wall / duration * 1e3:.1f} µs/step, {its:.2f} Newton iterations per saved step"
    )
    if repeat > 1:
        print(
            f"  median of {repeat} runs; min {walls[0]:.3f} s, max {walls[-1]:.3f} s "
            f"({duration / walls[0]:.1f}× … {duration / walls[-1]:.1f}×)"
        )
    print(
        f"{'N':>5} {'wall [s] for 1 s':>17} {'per step [µs]':>14} {'× real time':>12} "
        f"{'it/step':>8}"
    )
    for n in (25, 50, 100, 200, 400):
        wall, _, its = run(n, 1.0)
        print(f"{n:>5} {wall:>17.3f} {wall / 1000 * 1e6:>14.1f} {1.0 / wall:>12.1f} {its:>8.2f}")
    print("steps scaling at N = 100:")
    for d in (0.5, 1.0, 2.0):
        wall, _, _ = run(100, d)
        print(f"  {int(d / 1e-3):>5} steps: {wall:.3f} s ({wall / (d / 1e-3) * 1e6:.1f} µs/step)")


if __name__ == "__main__":
    run_reporting_warnings(main)
