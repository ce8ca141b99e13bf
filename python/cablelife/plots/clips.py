"""Clip reaction forces and moments over time."""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from cablelife.plots.figure import new_figure
from cablelife.plots.runs import as_runs, check_runs


def plot_clip_reactions(runs) -> Figure:
    """Per clip, the magnitude of the reaction force (left) and moment (right) over time;
    one line per run (quasistatic dashed, dynamic solid)."""
    runs = as_runs(runs)
    check_runs(runs)
    names = list(dict.fromkeys(n for r in runs for n in r.cable.clips))
    if not names:
        raise ValueError("the runs have no clips")
    fig, axes = new_figure(len(names), 2, height=2.0, sharex=True)
    for row, clip in enumerate(names):
        for k, run in enumerate(runs):
            rc = run.cable.clips.get(clip)
            if rc is None:
                continue
            t = run.cable.time
            lab = run.legend
            axes[row, 0].plot(
                t, np.linalg.norm(rc.force, axis=1), run.linestyle, color=run.colour(k), label=lab
            )
            axes[row, 1].plot(
                t, np.linalg.norm(rc.moment, axis=1), run.linestyle, color=run.colour(k)
            )
        s = next(r.cable.clips[clip].s for r in runs if clip in r.cable.clips)
        axes[row, 0].set_ylabel(f"clip {clip}\n(s = {s:.3f} m)\n|force| [N]", fontsize=8)
        axes[row, 1].set_ylabel("|moment| [N m]", fontsize=8)
        for ax in axes[row]:
            ax.grid(alpha=0.3)
    axes[0, 0].legend(fontsize=8)
    for ax in axes[-1]:
        ax.set_xlabel("time [s]")
    fig.suptitle("clip reactions (on the cable, global frame)")
    return fig
