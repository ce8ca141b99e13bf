"""Section loads: maxima along the cable over time (paper Fig. 2) and envelopes along the cable
(max/min over time), several runs overlaid."""

from __future__ import annotations

from matplotlib.figure import Figure

from cablelife.plots.figure import new_figure
from cablelife.plots.runs import QUANTITIES, as_runs, check_runs, extreme_along, quantity

ORDER = ("shear", "tension", "bending", "torsion")


def plot_maxima_over_time(runs, quantities=ORDER) -> Figure:
    """Paper Fig. 2: per quantity, the value of largest magnitude along the cable at each saved
    step (sign kept for tension and torsion), over time; one line per run, quasistatic
    dashed and dynamic solid."""
    runs = as_runs(runs)
    check_runs(runs)
    fig, axes = new_figure(len(quantities), 1, height=2.2, sharex=True)
    for ax, name in zip(axes[:, 0], quantities, strict=True):
        label, unit, _, _ = QUANTITIES[name]
        for k, run in enumerate(runs):
            _, v = quantity(run.cable, name)
            ax.plot(
                run.cable.time,
                extreme_along(v),
                run.linestyle,
                color=run.colour(k),
                label=run.legend,
            )
        ax.set_ylabel(f"{label}\n[{unit}]", fontsize=8)
        ax.grid(alpha=0.3)
    axes[0, 0].legend(fontsize=8, loc="best")
    axes[-1, 0].set_xlabel("time [s]")
    fig.suptitle("largest value along the cable over time")
    return fig


def plot_envelopes(runs, quantities=ORDER) -> Figure:
    """Per quantity, the maximum and minimum over time at each arc length (a shaded band per
    run)."""
    runs = as_runs(runs)
    check_runs(runs)
    fig, axes = new_figure(len(quantities), 1, height=2.2, sharex=True)
    for ax, name in zip(axes[:, 0], quantities, strict=True):
        label, unit, _, _ = QUANTITIES[name]
        for k, run in enumerate(runs):
            s, v = quantity(run.cable, name)
            lo, hi = v.min(axis=0), v.max(axis=0)
            ax.fill_between(s, lo, hi, color=run.colour(k), alpha=0.2, lw=0)
            ax.plot(s, hi, run.linestyle, color=run.colour(k), label=run.legend)
            ax.plot(s, lo, run.linestyle, color=run.colour(k), lw=0.8)
        ax.set_ylabel(f"{label}\n[{unit}]", fontsize=8)
        ax.grid(alpha=0.3)
    axes[0, 0].legend(fontsize=8, loc="best")
    axes[-1, 0].set_xlabel("arc length s [m]")
    fig.suptitle("envelope along the cable (max and min over time)")
    return fig
