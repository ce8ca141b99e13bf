"""Default damping: start-up section loads and their viscous share (issue 13).

A slack 1 m hose (r = 5 mm, E = 50 MPa, 40 segments, f₁ ≈ 1 Hz) whose far clip starts moving
at 0.3 m/s (a 2 Hz sine without fade-in), 0.5 s dynamic at 1 ms. Peak section loads and the
viscous share of each peak for: the former default (τ = 2/ω₁ on every deformation mode), the
default now (τ = 2ζ/ω₁ on bending, a loss factor 0.1 on the lowest extension, torsion
and shear mode) and a
material-like τ = 2 ms on all modes; then the same with the motion faded in over 0.3 s (1 s).
Run: python benchmarks/bench_damping.py
"""

from __future__ import annotations

import copy
import math
import warnings

import numpy as np
from cablelife.modal import cable_modes
from cablelife.scene import scene_from_dict
from cablelife.simulate import simulate
from cablelife.summary import cable_summary

BASE = {
    "simulation": {
        "mode": "dynamic",
        "gravity": [0.0, 0.0, -9.81],
        "duration": 0.5,
        "time_step": 0.001,
    },
    "bodies": [
        {
            "name": "engine",
            "origin": [0.8, 0.2, 0.0],
            "motion": [
                {
                    "channel": "x",
                    "signal": {
                        "type": "sine",
                        "amplitude": 0.3 / (2 * math.pi * 2.0),
                        "frequency": 2.0,
                    },
                }
            ],
        }
    ],
    "cables": [
        {
            "name": "hose",
            "length": 1.0,
            "segments": 40,
            "section": {"shape": "circle", "radius": 0.005},
            "material": {"youngs_modulus": 5.0e7, "poisson_ratio": 0.45, "density": 1500.0},
            "clips": [
                {"name": "a", "s": 0.0, "position": [0.0, 0.0, 0.0], "direction": [1, 0, 0]},
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


def run(damping: dict | None, fade_in: float = 0.0) -> dict:
    d = copy.deepcopy(BASE)
    if fade_in:
        d["bodies"][0]["motion"][0]["signal"].update(fade_in=fade_in)
        d["simulation"]["duration"] = 1.0
    if damping is not None:
        d["cables"][0]["damping"] = damping
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = simulate(scene_from_dict(d)).cable
    s = cable_summary(res)
    return {
        "tension": s["max_tension"],
        "shear": s["max_shear"],
        "bending": s["max_bending"],
        "torsion": s["max_torsion"],
        "viscous": s["viscous_share"],
        "tau_shear": res.solver["tau_shear"],
        "tau_bend": res.solver["tau_bend"],
    }


def main() -> None:
    scene = scene_from_dict(BASE)
    w1 = float(cable_modes(scene, scene.cables[0], 1).omega[0])
    print(f"f₁ = {w1 / 2 / math.pi:.3f} Hz, 2/ω₁ = {2 / w1:.4f} s")
    cases = {
        "former default (τ = 2/ω₁ on all)": {"retardation_time": 2 / w1},
        "default now": None,
        "τ = 2 ms on all": {"retardation_time": 0.002},
    }
    print(
        f"{'damping':36} | {'τ GA, EA, EI, GJ [s]':31} | {'max F3':>8} {'|F1,F2|':>8} "
        f"{'|M1,M2|':>8} {'|M3|':>8} | viscous share F3, F12, M12, M3"
    )
    for (name, damping), fade in [(c, f) for f in (0.0, 0.3) for c in cases.items()]:
        if damping is None:
            name = f"{name} {'(step start)' if fade == 0 else '(faded in)'}"
        r = run(damping, fade)
        taus = np.array([r["tau_shear"][0], r["tau_shear"][2], r["tau_bend"][0], r["tau_bend"][2]])
        share = ", ".join(f"{100 * v:.0f}%" for v in r["viscous"])
        print(
            f"{name:36} | {' '.join(f'{t:.1e}' for t in taus):31} | {r['tension']:8.3g} "
            f"{r['shear']:8.3g} {r['bending']:8.3g} {r['torsion']:8.3g} | {share}"
        )


if __name__ == "__main__":
    main()
