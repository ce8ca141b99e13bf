"""Smallest bend radius along the cable against a routing rule (radius ≥ factor × diameter)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from matplotlib.figure import Figure

from cablelife.plots.figure import new_figure
from cablelife.plots.runs import as_runs, check_runs
from cablelife.results import CableResult

#: Rule of thumb for moving cables (≥ 6 × diameter for static routing).
DEFAULT_FACTOR = 10.0


@dataclass
class BendRadiusCheck:
    """The smallest bend radius over time at each node and where it breaks the rule."""

    arc_length: np.ndarray  # (N+1,) m
    min_radius: np.ndarray  # (N+1,) m, inf where always straight
    allowed: float  # m, factor × diameter
    factor: float

    @property
    def violations(self) -> list[tuple[float, float, float]]:
        """(s from, s to, smallest radius) of each run of nodes below the allowed radius."""
        bad = self.min_radius < self.allowed
        out = []
        i = 0
        while i < len(bad):
            if bad[i]:
                j = i
                while j + 1 < len(bad) and bad[j + 1]:
                    j += 1
                seg = self.min_radius[i : j + 1]
                out.append((float(self.arc_length[i]), float(self.arc_length[j]), float(seg.min())))
                i = j + 1
            else:
                i += 1
        return out

    @property
    def ok(self) -> bool:
        return not self.violations


def check_bend_radius(cable: CableResult, factor: float = DEFAULT_FACTOR) -> BendRadiusCheck:
    """The bend-radius check of one cable: allowed radius = ``factor`` × outer diameter."""
    factor = float(factor)
    if not (np.isfinite(factor) and factor > 0):
        raise ValueError(f"factor = {factor}: must be a number > 0 (e.g. 10 for moving cables)")
    if "outer_radius" not in cable.section:
        raise ValueError(f"cable {cable.name!r} has no section outer_radius")
    diameter = 2.0 * float(cable.section["outer_radius"])
    return BendRadiusCheck(
        arc_length=cable.arc_length,
        min_radius=cable.bend_radius().min(axis=0),
        allowed=factor * diameter,
        factor=factor,
    )


def plot_bend_radius(runs, factor: float = DEFAULT_FACTOR) -> Figure:
    """The smallest bend radius over time along the cable (log scale) with the rule line;
    stretches below the rule are shaded red."""
    runs = as_runs(runs)
    check_runs(runs)
    fig, axes = new_figure(1, 1, height=3.4)
    ax = axes[0, 0]
    for k, run in enumerate(runs):
        chk = check_bend_radius(run.cable, factor)
        r = np.where(np.isfinite(chk.min_radius), chk.min_radius, np.nan)
        ax.plot(chk.arc_length, r, run.linestyle, color=run.colour(k), label=run.legend)
        ax.axhline(chk.allowed, color=run.colour(k), lw=0.8, ls=":")
        for s0, s1, _ in chk.violations:
            ax.axvspan(s0, max(s1, s0 + 1e-3), color="red", alpha=0.15, lw=0)
    ax.axhline(np.nan, color="gray", ls=":", label=f"rule: {factor:g} × diameter")
    ax.set_yscale("log")
    ax.set_xlabel("arc length s [m]")
    ax.set_ylabel("smallest bend radius [m]")
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=8)
    ax.set_title("smallest bend radius along the cable, minimum over time (red: below the rule)")
    return fig
