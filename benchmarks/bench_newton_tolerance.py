"""The dynamic Newton tolerance against the time-discretisation error (issue 13).

For each case: the default tolerance at 1 ms, a tight tolerance (1e-9) at 1 ms and at 0.25 ms.
Iteration error = rms(M_default − M_tight) / rms(M_tight) over all saved steps and nodes
(section moments, saved every 1 ms); time-discretisation error = the same between the tight
runs at 1 ms and 0.25 ms. The default must keep the first below the second on every case.
Run: python benchmarks/bench_newton_tolerance.py [--tolerance T]
"""

from __future__ import annotations

import argparse
import copy
import warnings

import numpy as np
from cablelife._core import DEFAULT_NEWTON_TOLERANCE
from cablelife.scene import scene_from_dict
from cablelife.simulate import simulate


def hose(segments: int, channel: str, amplitude: float, frequency: float, radius=0.005, e=5e7):
    return {
        "simulation": {
            "mode": "dynamic",
            "gravity": [0.0, 0.0, -9.81],
            "duration": 0.5,
            "time_step": 0.001,
            "output_step": 0.001,
        },
        "bodies": [
            {
                "name": "engine",
                "origin": [0.8, 0.2, 0.0],
                "motion": [
                    {
                        "channel": channel,
                        "signal": {
                            "type": "sine",
                            "amplitude": amplitude,
                            "frequency": frequency,
                            "fade_in": 0.1,
                        },
                    }
                ],
            }
        ],
        "cables": [
            {
                "name": "hose",
                "length": 1.0,
                "segments": segments,
                "section": {"shape": "circle", "radius": radius},
                "material": {"youngs_modulus": e, "poisson_ratio": 0.45, "density": 1500.0},
                "clips": [
                    {"name": "a", "s": 0.0, "position": [0, 0, 0], "direction": [1, 0, 0]},
                    {
                        "name": "b",
                        "s": 1.0,
                        "body": "engine",
                        "position": [0.8, 0.2, 0.0],
                        "direction": [1, 0, 0],
                    },
                ],
            }
        ],
    }


def overdamped(d: dict) -> dict:
    d["cables"][0]["damping"] = {"retardation_time": 0.27}  # the former default here
    return d


CASES = {
    "50 seg., 10 Hz (z, 5 mm), τ = 0.27 s on all": overdamped(hose(50, "z", 0.005, 10.0)),
    "50 segments, clip at 10 Hz (x, 2 mm)": hose(50, "x", 0.002, 10.0),
    "50 segments, clip at 10 Hz (z, 5 mm)": hose(50, "z", 0.005, 10.0),
    "100 segments, clip at 3 Hz (z, 10 mm)": hose(100, "z", 0.01, 3.0),
    "40 segments, stiff (E = 1 GPa), 30 Hz (y, 1 mm)": hose(40, "y", 0.001, 30.0, 0.004, 1e9),
}


def run(d: dict, tol: float | None, dt: float) -> tuple[np.ndarray, float]:
    d = copy.deepcopy(d)
    d["simulation"]["time_step"] = dt
    if tol is not None:
        d["simulation"]["newton_tolerance"] = tol
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        c = simulate(scene_from_dict(d)).cable
    return c.moments, float(np.mean(c.solver["iterations"][1:]))


def rel(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.sqrt(np.mean((a - b) ** 2) / np.mean(b**2)))


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--tolerance", type=float, default=None, help="default: the solver's")
    args = ap.parse_args()
    tol = args.tolerance
    print(f"newton_tolerance = {tol if tol is not None else DEFAULT_NEWTON_TOLERANCE}")
    print(f"{'case':48} | iteration err | time err (1 vs 0.25 ms) | ratio | iterations/step")
    for name, d in CASES.items():
        m_def, it_def = run(d, tol, 0.001)
        m_tight, it_tight = run(d, 1e-9, 0.001)
        m_fine, _ = run(d, 1e-9, 0.00025)
        e_it, e_time = rel(m_def, m_tight), rel(m_tight, m_fine)
        print(
            f"{name:48} | {e_it:13.2e} | {e_time:23.2e} | {e_it / e_time:5.2f} | "
            f"{it_def:.2f} (tight {it_tight:.2f})"
        )


if __name__ == "__main__":
    main()
