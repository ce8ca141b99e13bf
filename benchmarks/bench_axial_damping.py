"""Axial and torsional damping of the default against its time-step error (issue 13).

The random-excitation benchmark of `bench_dynamic.py` (1.2 m cable, E = 100 MPa, four fixed
clips, 10–200 Hz bracket motion, ζ₁ = 0.2 on bending) with extension, torsion and shear damped
by the loss factor η on their own lowest mode (the default: η = 0.1; 0.3 the upper end of
hose rubbers) and with the former default (τ = 2ζ/ω₁ on every deformation mode). For each:
the Kelvin–Voigt modal damping ratios (Rayleigh quotients with the damping matrix,
`cable_modes(damping=True)`) of the lowest axial and torsion modes, and the time-discretisation
error of the section moment histories: rms(M_h − M_ref)/rms(M_ref) at h = 1, 0.5 and
0.25 ms against h = 0.125 ms.
With --demo: the demo's dynamic damage ranking (max pseudo-damage per variant, ratio) for
each loss factor.
Run: python benchmarks/bench_axial_damping.py [--duration 2.0] [--segments 100] [--demo]
"""

from __future__ import annotations

import argparse
import math
import sys
import warnings
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
import cablelife.modal as modal  # noqa: E402
from bench_dynamic import scene  # noqa: E402
from cablelife.scene import scene_from_dict  # noqa: E402
from cablelife.simulate import simulate  # noqa: E402

CASES = {"default, η = 0.1": 0.1, "η = 0.3": 0.3, "former: τ = 2ζ/ω₁ on all": math.inf}


def modal_damping(sc, count: int) -> list[tuple[str, float, float]]:
    """(kind, f [Hz], ζ) of the lowest axial and torsion modes among the first `count`: ζ the
    Rayleigh quotient φᵀCφ / (2ω φᵀMφ) with the Kelvin–Voigt damping matrix
    (``cable_modes(damping=True)``; the former estimate ω/2 · Σ share·τ from kinetic-energy
    shares was exact only for nearly pure modes)."""
    m = modal.cable_modes(sc, sc.cables[0], count, damping=True)
    out = []
    for kind in ("axial", "torsion"):
        for k in range(len(m.omega)):
            if m.kind[k] == kind:
                out.append((kind, m.omega[k] / (2 * math.pi), float(m.damping_ratio[k])))
                break
    return out


def moments(d: dict, h: float) -> np.ndarray:
    d = {**d, "simulation": {**d["simulation"], "time_step": h, "output_step": 1e-3}}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return simulate(scene_from_dict(d)).cable.moments


def rel(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.sqrt(np.mean((a - b) ** 2)) / np.sqrt(np.mean(b**2)))


def demo_ranking(out: str) -> None:
    import tempfile

    from cablelife.demo import run_demo

    default = modal.DEFAULT_LOSS_FACTOR
    for name, eta in CASES.items():
        modal.DEFAULT_LOSS_FACTOR = eta
        try:
            with warnings.catch_warnings(), tempfile.TemporaryDirectory(dir=out) as tmp:
                warnings.simplefilter("ignore")
                res = run_demo(tmp, quasistatic=False, report=False)
        finally:
            modal.DEFAULT_LOSS_FACTOR = default
        rows = ", ".join(
            f"{v.label} {v.max_damage:.3g} (×{v.ratio:.2f})" for v in res.comparison.variants
        )
        print(f"demo, {name:26s}: {rows}; preferred {res.comparison.best.label}")


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--duration", type=float, default=2.0)
    ap.add_argument("--segments", type=int, default=100)
    ap.add_argument("--modes", type=int, default=120)
    ap.add_argument("--demo", action="store_true")
    args = ap.parse_args()
    if args.demo:
        Path("out").mkdir(exist_ok=True)
        demo_ranking("out")
        return
    d = scene(args.segments, args.duration)
    default = modal.DEFAULT_LOSS_FACTOR
    print(f"N = {args.segments}, {args.duration} s; time error vs h = 0.125 ms (rms, relative)")
    print(f"{'case':28s} {'lowest axial: f, ζ':22s} {'torsion: f, ζ':22s} 1 ms   0.5 ms 0.25 ms")
    for name, eta in CASES.items():
        modal.DEFAULT_LOSS_FACTOR = eta
        try:
            sc = scene_from_dict(d)
            md = {k: (f, z) for k, f, z in modal_damping(sc, args.modes)}
            ref = moments(d, 1.25e-4)
            errs = [rel(moments(d, h), ref) for h in (1e-3, 5e-4, 2.5e-4)]
        finally:
            modal.DEFAULT_LOSS_FACTOR = default
        cols = [
            f"{md[k][0]:6.0f} Hz, {md[k][1]:.3f}" if k in md else "(not in modes)"
            for k in ("axial", "torsion")
        ]
        print(f"{name:28s} {cols[0]:22s} {cols[1]:22s} " + " ".join(f"{e:.3f}" for e in errs))


if __name__ == "__main__":
    main()
