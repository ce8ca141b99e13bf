"""Hints about a run a user may not think of, printed by the command line after the run
(warnings from the run itself are printed the same way: naming the scene item, not Python's
file and line)."""

from __future__ import annotations

import math

#: Integration steps per period of the first natural mode below which a dynamic run is
#: flagged: the generalized-α scheme damps and detunes a mode resolved this coarsely.
STEPS_PER_PERIOD = 20


def run_hints(scene, result) -> list[str]:
    """Hints about ``result`` of ``scene``: a dynamic time step that does not resolve the
    cable's first natural frequency; a default damping that cannot give a first mode that is
    hardly bending its damping ratio."""
    from cablelife.modal import MIN_BENDING_SHARE

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
        share, zeta = c.solver.get("bending_share"), c.solver.get("damping_ratio")
        least = MIN_BENDING_SHARE
        if c.solver.get("damping_source") == "ratio" and share is not None and share < least:
            out.append(
                f"cable '{name}': its first natural mode (f₁ = {f1:.3g} Hz) is only "
                f"{100 * share:.0f} % bending (gravity or extension stiffen it): the default "
                f"material damping gives it ζ ≈ {zeta * share / least:.2g} instead of "
                f"{zeta:g} (more would over-damp every bending mode above it); set "
                f"damping.bending or "
                f"damping.retardation_time (s) to choose otherwise (docs/dynamics.md)"
            )
    return out
