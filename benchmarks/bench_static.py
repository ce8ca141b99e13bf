"""Static and quasistatic solver speed (issue 2).

A 1 m cable with 3 clips under gravity, N = 25 … 400 segments: time per static solve and per
Newton iteration (median of repeats), and quasistatic steps per second at N = 100.
Run: python benchmarks/bench_static.py
"""

from __future__ import annotations

import statistics
import time

import numpy as np
from cablelife.scene import scene_from_dict
from cablelife.simulate import build_cable, clip_poses, output_times


def scene(segments: int, mode: str = "static") -> dict:
    return {
        "simulation": {"mode": mode, "gravity": [0, 0, -9.81], "duration": 2.0, "time_step": 0.01},
        "bodies": [
            {
                "name": "engine",
                "origin": [0.8, 0.1, 0.0],
                "motion": [
                    {
                        "channel": "z",
                        "signal": {"type": "sine", "amplitude": 0.01, "frequency": 1.0},
                    },
                    {
                        "channel": "rx",
                        "signal": {"type": "sine", "amplitude": 0.05, "frequency": 0.5},
                    },
                ],
            }
        ],
        "cables": [
            {
                "name": "cable",
                "length": 1.0,
                "segments": segments,
                "section": {"shape": "circle", "radius": 0.004},
                "material": {"youngs_modulus": 1.0e8, "poisson_ratio": 0.45, "density": 2000.0},
                "clips": [
                    {"name": "a", "s": 0.0, "position": [0, 0, 0], "direction": [1, 0, 0]},
                    {
                        "name": "b",
                        "s": 0.45,
                        "position": [0.42, 0.08, -0.03],
                        "direction": [1, 0.1, 0],
                        "type": "swivel",
                    },
                    {
                        "name": "c",
                        "s": 1.0,
                        "body": "engine",
                        "position": [0.9, 0.1, 0.0],
                        "direction": [1, 0, 0],
                    },
                ],
            }
        ],
    }


def time_static(segments: int, repeats: int = 15) -> tuple[float, float, int]:
    sc = scene_from_dict(scene(segments))
    cable = sc.cables[0]
    pos, quat = clip_poses(sc, cable, np.array([0.0]))
    times, iters = [], 0
    for _ in range(repeats):
        core = build_cable(sc, cable)
        t0 = time.perf_counter()
        out = core.run_sequence(pos, quat)
        times.append(time.perf_counter() - t0)
        iters = int(out["iterations"][0])
    med = statistics.median(times)
    return med, med / max(iters, 1), iters


def time_quasistatic(segments: int = 100) -> tuple[float, float]:
    sc = scene_from_dict(scene(segments, "quasistatic"))
    cable = sc.cables[0]
    times = output_times(sc, "quasistatic")
    pos, quat = clip_poses(sc, cable, times)
    core = build_cable(sc, cable)
    t0 = time.perf_counter()
    out = core.run_sequence(pos, quat)
    wall = time.perf_counter() - t0
    return times.size / wall, float(np.mean(out["iterations"][1:]))


def main() -> None:
    print("static equilibrium, 1 m cable, 3 clips (fixed, swivel, fixed on a body), gravity")
    print(f"{'N':>5} {'solve [ms]':>11} {'per iter [ms]':>14} {'iterations':>11}")
    for n in (25, 50, 100, 200, 400):
        med, per_it, iters = time_static(n)
        print(f"{n:>5} {med * 1e3:>11.3f} {per_it * 1e3:>14.4f} {iters:>11}")
    rate, it = time_quasistatic(100)
    print(f"quasistatic, N = 100, 201 steps: {rate:.0f} steps/s, {it:.2f} Newton iterations/step")


if __name__ == "__main__":
    main()
