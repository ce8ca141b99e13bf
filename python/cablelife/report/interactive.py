"""Interactive (plotly) versions of the load plots for the report."""

from __future__ import annotations

import numpy as np

from cablelife.plots.loads import ORDER, magnitude_label, span_maxima
from cablelife.plots.runs import QUANTITIES, as_runs, variant_colours
from cablelife.report.decimate import minmax, nice_range
from cablelife.report.margins import BOTTOM, EXTRA_HEIGHT, LEFT, TOP, legend_room

_DASH = {"--": "dash", "-": "solid", ":": "dot"}
#: Points of a span's line (shown on demand; the maxima over the moving spans get MAX_POINTS).
SPAN_POINTS = 600


def _hex(colour: str | None, k: int) -> str:
    from plotly.colors import qualitative

    if colour and not colour.startswith("C"):
        return colour
    return qualitative.Plotly[(int(colour[1:]) if colour else k) % 10]


def maxima_over_time_figure(runs, quantities=ORDER, per_span: bool = True):
    """Paper Fig. 2 as a plotly figure: per quantity, the largest magnitude over the spans
    that move (spans between clips on one body do not; all spans when none moves) at each
    saved step, one line per run (colour: the run's variant, dashed quasistatic, solid
    dynamic); with ``per_span``, each moving span on its own on demand (its legend entry)."""
    from plotly.subplots import make_subplots

    runs = as_runs(runs)
    fig = make_subplots(rows=len(quantities), cols=1, shared_xaxes=True, vertical_spacing=0.03)
    for k, (run, colour) in enumerate(zip(runs, variant_colours(runs), strict=True)):
        colour = _hex(colour, k)
        dash = _DASH[run.linestyle]
        for row, name in enumerate(quantities, 1):
            m = span_maxima(run.cable, name)
            t, y = minmax(m.time, m.largest)
            fig.add_scatter(
                x=t,
                y=y,
                name=run.legend,
                legendgroup=run.legend,
                showlegend=row == 1,
                line={"dash": dash, "color": colour},
                row=row,
                col=1,
            )
            for span, values in m.spans if per_span else []:
                t, y = minmax(m.time, values, SPAN_POINTS)
                fig.add_scatter(
                    x=t,
                    y=y,
                    name=f"{run.legend}: span {span}",
                    legendgroup=f"{run.legend}: {span}",
                    showlegend=row == 1,
                    visible="legendonly",
                    line={"dash": dash, "color": colour, "width": 1},
                    opacity=0.6,
                    row=row,
                    col=1,
                )
    for row, name in enumerate(quantities, 1):
        label, unit = magnitude_label(name), QUANTITIES[name][1]
        ys = [
            np.asarray(t.y, float) for t in fig.data if t.yaxis == ("y" if row == 1 else f"y{row}")
        ]
        rng = nice_range(np.concatenate(ys)) if ys else None
        fig.update_yaxes(
            title_text=f"{label} [{unit}]",
            title_font_size=10,
            tickformat="~g",
            ticklabelstandoff=6,  # clear of the x axis' first tick label at the corner
            range=rng,
            row=row,
            col=1,
        )
    fig.update_xaxes(title_text="time [s]", ticklabelstandoff=5, row=len(quantities), col=1)
    fig.update_layout(
        height=200 * len(quantities) + 80 + EXTRA_HEIGHT,
        title="largest magnitude over the spans that move, over time",
        margin={
            "l": LEFT,
            "r": legend_room(t.name for t in fig.data if t.showlegend),
            "t": TOP,
            "b": BOTTOM,
        },
        legend={"font": {"size": 10}},
    )
    return fig
