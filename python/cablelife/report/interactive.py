"""Interactive (plotly) versions of the load plots for the report."""

from __future__ import annotations

from cablelife.plots.loads import ORDER
from cablelife.plots.runs import QUANTITIES, as_runs, extreme_along, quantity

_DASH = {"--": "dash", "-": "solid", ":": "dot"}


def maxima_over_time_figure(runs, quantities=ORDER):
    """Paper Fig. 2 as a plotly figure: one row per quantity, one line per run."""
    from plotly.colors import qualitative
    from plotly.subplots import make_subplots

    runs = as_runs(runs)
    fig = make_subplots(rows=len(quantities), cols=1, shared_xaxes=True, vertical_spacing=0.03)
    for row, name in enumerate(quantities, 1):
        label, unit, _, _ = QUANTITIES[name]
        for k, run in enumerate(runs):
            _, v = quantity(run.cable, name)
            fig.add_scatter(
                x=run.cable.time,
                y=extreme_along(v),
                name=run.legend,
                legendgroup=str(k),
                showlegend=row == 1,
                line={"dash": _DASH[run.linestyle], "color": qualitative.Plotly[k % 10]},
                row=row,
                col=1,
            )
        fig.update_yaxes(title_text=f"{label} [{unit}]", title_font_size=10, row=row, col=1)
    fig.update_xaxes(title_text="time [s]", row=len(quantities), col=1)
    fig.update_layout(
        height=200 * len(quantities) + 80,
        title="largest value along the cable over time",
        margin={"l": 60, "r": 10, "t": 50, "b": 40},
    )
    return fig
