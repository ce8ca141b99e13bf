"""Modal damping ratios of the bench_dynamic.py cable: the Rayleigh quotient with the
Kelvin–Voigt damping matrix (``cable_modes(damping=True)``) against the former estimate from
kinetic-energy shares, ζ = ω/2 · Σ share·τ, and each mode's bending strain energy over its
total modal stiffness (φᵀK_bφ/ω², from ``Cable.modes`` with τ = 1 s on EI only).
Run: python benchmarks/modal_damping.py [--segments 100] [--modes 30]
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent))
import cablelife.modal as modal  # noqa: E402
from bench_dynamic import scene  # noqa: E402
from cablelife.scene import scene_from_dict  # noqa: E402


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--segments", type=int, default=100)
    ap.add_argument("--modes", type=int, default=30)
    args = ap.parse_args()
    sc = scene_from_dict(scene(args.segments, 1.0))
    cable = sc.cables[0]
    (ts, _, te), (tb, tb2, tt), info = modal.retardation_times(sc, cable)
    m = modal.cable_modes(sc, cable, args.modes, damping=True)
    core, _ = modal._equilibrium(sc, cable)
    bending = core.modes(args.modes, shear_tau=[0, 0, 0], bend_tau=[1, 1, 0])
    print(
        f"set ζ₁ = {info.get('ratio')}, τ bending {tb:.3g} s, torsion {tt:.3g} s, "
        f"extension {te:.3g} s, shear {ts:.3g} s"
    )
    print(
        f"{'mode':>4} {'kind':11} {'f [Hz]':>7} {'max share':>9} {'ζ shares':>9} "
        f"{'ζ Rayleigh':>10} {'φᵀK_bφ/ω²':>10}"
    )
    for k, w in enumerate(m.omega):
        b1, b2, tor, ax = m.shares[k]
        old = 0.5 * w * (b1 * tb + b2 * tb2 + tor * tt + ax * te)
        kb = 2 * bending["omega"][k] * bending["damping_ratio"][k] / w**2
        print(
            f"{k + 1:4d} {m.kind[k]:11} {w / (2 * math.pi):7.1f} {m.shares[k].max():9.3f} "
            f"{old:9.3g} {m.damping_ratio[k]:10.3g} {kb:10.3g}"
        )


if __name__ == "__main__":
    main()
