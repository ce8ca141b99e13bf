"""Section loads: maxima along the cable over time (paper Fig. 2) and envelopes along the cable
(max/min over time), several runs overlaid."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from matplotlib.figure import Figure

from cablelife.plots.figure import new_figure
from cablelife.plots.runs import (
    QUANTITIES,
    as_runs,
    check_runs,
    quantity,
    variant_colours,
)
from cablelife.plots.spans import cable_spans
from cablelife.results import CableResult

ORDER = ("shear", "tension", "bending", "torsion")


@dataclass
class SpanMaxima:
    """A quantity's largest magnitude at each saved step over the spans that move (all spans
    when none moves), and over each moving span on its own (name, (T,))."""

    time: np.ndarray
    largest: np.ndarray
    spans: list[tuple[str, np.ndarray]]


def magnitude_label(name: str) -> str:
    """The axis label of a quantity's magnitude ("|tension F3|")."""
    label = QUANTITIES[name][0]
    return label if "|" in label else f"|{label}|"


def span_maxima(cable: CableResult, name: str) -> SpanMaxima:
    """Paper Fig. 2's data of one quantity: magnitudes, so a torsion or tension that changes
    sign does not flip into spikes, over the spans that move, so a span between two clips on
    one body (constant loads) does not hide the rest."""
    _, v = quantity(cable, name)
    where = "edges" if v.shape[1] == cable.arc_length.size - 1 else "nodes"
    spans = cable_spans(cable)
    moving = [sp for sp in spans if sp.moves] or spans
    mag = np.abs(v)
    pick = np.concatenate([getattr(sp, where) for sp in moving]) if moving else np.zeros(0, int)
    largest = mag[:, pick].max(axis=1) if pick.size else mag.max(axis=1)
    per = [
        (sp.name, mag[:, getattr(sp, where)].max(axis=1))
        for sp in moving
        if len(moving) > 1 and getattr(sp, where).size
    ]
    return SpanMaxima(cable.time, largest, per)


def plot_maxima_over_time(runs, quantities=ORDER) -> Figure:
    """Paper Fig. 2: per quantity, its largest magnitude over the spans that move
    (:func:`span_maxima`) at each saved step, over time; one colour per variant (a run's own
    colour, else by its label without the mode), quasistatic dashed, dynamic solid. The same
    data as the report's interactive figure."""
    runs = as_runs(runs)
    check_runs(runs)
    colours = variant_colours(runs)
    fig, axes = new_figure(len(quantities), 1, height=2.2, sharex=True)
    for ax, name in zip(axes[:, 0], quantities, strict=True):
        unit = QUANTITIES[name][1]
        for run, colour in zip(runs, colours, strict=True):
            m = span_maxima(run.cable, name)
            ax.plot(m.time, m.largest, run.linestyle, color=colour, lw=1, label=run.legend)
        ax.set_ylabel(f"{magnitude_label(name)}\n[{unit}]", fontsize=8)
        ax.grid(alpha=0.3)
    axes[0, 0].legend(fontsize=8, loc="best")
    axes[-1, 0].set_xlabel("time [s]")
    fig.suptitle("largest magnitude over the spans that move, over time")
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
