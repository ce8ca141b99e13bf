"""Hints about a run a user may not think of, printed by the command line after the run
(warnings from the run itself are printed the same way: naming the scene item, not Python's
file and line)."""

from __future__ import annotations

import math

#: Integration steps per period of the first natural mode below which a dynamic run is
#: flagged: the generalized-α scheme damps and detunes a mode resolved this coarsely.
STEPS_PER_PERIOD = 20

#: Share of bending in the first mode's stiffness below which the default damping is flagged:
#: the bending retardation time that gives that mode its ratio ζ damps a pure bending mode
#: at twice its frequency at 2ζ/share (> 8ζ).
BENDING_SHARE = 0.25


def run_hints(scene, result) -> list[str]:
    """Hints about ``result`` of ``scene``: a dynamic time step that does not resolve the
    cable's first natural frequency; a default damping calibrated on a first mode that is
    hardly bending."""
    out = []
    if result.mode != "dynamic":
        return out
    dt = scene.simulation.time_step
    for name, c in result.cables.items():
        w1 = c.solver.get("omega1")
        if w1 is None or not math.isfinite(w1) or w1 <= 0:
            continue
        f1 = w1 / (2 * math.pi)
        steps = 1.0 / (f1 * dt)
        if steps < STEPS_PER_PERIOD:
            out.append(
                f"cable '{name}': simulation.time_step = {dt:g} s gives {steps:.1f} steps per "
                f"period of its first natural mode (f₁ = {f1:.3g} Hz); the dynamics are not "
                f"resolved: use time_step ≤ {1 / (STEPS_PER_PERIOD * f1):.2g} s"
            )
        zeta, tau = c.solver.get("damping_ratio"), c.solver.get("tau_bend")
        if c.solver.get("damping_source") == "ratio" and tau is not None and tau[0] > 0:
            share = 2 * zeta / (tau[0] * w1)  # τ = ζ/ζ₁(1 s), ζ₁(1 s) = share·ω₁/2
            if share < BENDING_SHARE:
                out.append(
                    f"cable '{name}': its first natural mode (f₁ = {f1:.3g} Hz) is only "
                    f"{100 * share:.0f} % bending; the bending damping that gives it ζ = {zeta:g} "
                    f"(τ = {tau[0]:.3g} s) damps a bending mode at {2 * f1:.3g} Hz at ζ ≈ "
                    f"{2 * zeta / share:.2g}: set damping.bending or damping.retardation_time "
                    f"(s) to choose otherwise (docs/dynamics.md)"
                )
    return out
