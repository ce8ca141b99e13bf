"""Interactive (plotly) versions of the matplotlib plots, for the report: the plots stay the one
place that decides what is drawn; this module redraws their artists in plotly.

Covered (what ``cablelife.plots`` uses): lines and markers (``plot``), horizontal and vertical
lines (``axhline``, ``axvline``), shaded bands (``fill_between``) and spans (``axvspan``),
``pcolormesh`` (a heatmap, log colours as log10), annotations, log axes, axis labels, titles,
limits and the subplot grid. Other artists are left out.
"""

from __future__ import annotations

import numpy as np
from matplotlib.collections import PolyCollection, QuadMesh
from matplotlib.colors import LogNorm, to_hex, to_rgba
from matplotlib.figure import Figure
from matplotlib.patches import Polygon, Rectangle
from matplotlib.text import Annotation

from cablelife.report.margins import BOTTOM, EXTRA_HEIGHT, LEFT, TOP, legend_room

_DASH = {"-": "solid", "--": "dash", ":": "dot", "-.": "dashdot"}
_XANCHOR = {"left": "left", "center": "center", "right": "right"}
_YANCHOR = {"top": "top", "center": "middle", "bottom": "bottom", "baseline": "bottom"}
_MARKERS = {
    "o": "circle",
    "v": "triangle-down",
    "^": "triangle-up",
    "s": "square",
    "D": "diamond",
    "d": "diamond",
    "x": "x",
    "+": "cross",
    ".": "circle",
}


def _rgba(color, alpha=None) -> str:
    r, g, b, a = to_rgba(color, alpha)
    return f"rgba({r * 255:.0f},{g * 255:.0f},{b * 255:.0f},{a:.3g})"


def _values(a) -> np.ndarray:
    """Floats with inf and masked values as NaN (plotly writes null: a gap in the line).
    A numpy array, not a list: plotly validates arrays at once, lists element by element."""
    x = np.ma.filled(np.ma.masked_invalid(np.asarray(a, dtype=float)), np.nan)
    return np.ravel(x)


def _text(s: str) -> str:
    return s.replace("\n", "<br>")


def _plot_axes(fig: Figure) -> list:
    """The data axes of a figure (not colour bars), with a subplot position."""
    return [
        ax for ax in fig.axes if ax.get_subplotspec() is not None and not hasattr(ax, "_colorbar")
    ]


def to_plotly(fig: Figure):
    """A plotly figure of the matplotlib figure ``fig`` (see the module docstring)."""
    import plotly.graph_objects as go
    from plotly.subplots import make_subplots

    axes = _plot_axes(fig)
    if not axes:
        raise ValueError("fig: has no axes to convert")
    rows, cols = axes[0].get_subplotspec().get_gridspec().get_geometry()
    place = {}
    for ax in axes:
        ss = ax.get_subplotspec()
        place[ax] = (ss.rowspan.start + 1, ss.colspan.start + 1)
    titles = [""] * (rows * cols)
    for ax, (r, c) in place.items():
        titles[(r - 1) * cols + c - 1] = ax.get_title()
    shared = any(len(ax.get_shared_x_axes().get_siblings(ax)) > 1 for ax in axes)
    out = make_subplots(
        rows=rows,
        cols=cols,
        shared_xaxes=shared,
        subplot_titles=titles,
        vertical_spacing=min(0.3 / rows, 0.08),
        horizontal_spacing=0.12,
    )
    legend: set[str] = set()
    for ax, (r, c) in place.items():
        _convert_axes(out, ax, r, c, legend, go)
    width, height = fig.get_size_inches()
    title = fig._suptitle.get_text() if fig._suptitle is not None else ""
    out.update_layout(
        title=title or None,
        height=int(max(320, 95 * height)) + EXTRA_HEIGHT,
        # wide enough for labels and legend (cablelife.report.margins)
        margin={"l": LEFT, "r": legend_room(legend), "t": 70 if title else TOP, "b": BOTTOM},
        legend={"font": {"size": 10}},
        hovermode="closest",
    )
    for a in out.layout.annotations:  # subplot titles
        a.font.size = 12
    return out


def _convert_axes(out, ax, r: int, c: int, legend: set[str], go) -> None:
    from cablelife.report.decimate import minmax, nice_range

    xlog, ylog = ax.get_xscale() == "log", ax.get_yscale() == "log"
    xlim, ylim = ax.get_xlim(), ax.get_ylim()
    if not ylog:  # a (nearly) constant series: a sensible range, not round-off-sized ticks
        ylim = nice_range(np.asarray(ylim)) or ylim

    def add(trace):
        out.add_trace(trace, row=r, col=c)

    def named(label: str) -> dict:
        """Legend entry: labelled lines once per label; unlabelled ones (``_child0``) none."""
        if not label or label.startswith("_"):
            return {"showlegend": False, "hoverinfo": "x+y"}
        show = label not in legend
        legend.add(label)
        return {"name": label, "showlegend": show, "legendgroup": label}

    for coll in ax.collections:
        if isinstance(coll, QuadMesh):
            add(_heatmap(coll, go))
        elif isinstance(coll, PolyCollection):
            fill = _rgba(coll.get_facecolor()[0])
            for path in coll.get_paths():
                v = path.vertices
                add(
                    go.Scatter(
                        x=_values(v[:, 0]),
                        y=_values(v[:, 1]),
                        fill="toself",
                        fillcolor=fill,
                        mode="lines",
                        line={"width": 0},
                        hoverinfo="skip",
                        showlegend=False,
                    )
                )
    for p in ax.patches:
        if isinstance(p, Rectangle | Polygon):
            xy = p.get_xy() if isinstance(p, Polygon) else None
            x0, x1 = (
                (p.get_x(), p.get_x() + p.get_width())
                if xy is None
                else (xy[:, 0].min(), xy[:, 0].max())
            )
            if p.get_data_transform() == ax.get_xaxis_transform():  # axvspan: full height
                y0, y1 = ylim
            else:
                y0, y1 = (
                    (p.get_y(), p.get_y() + p.get_height())
                    if xy is None
                    else (xy[:, 1].min(), xy[:, 1].max())
                )
            add(
                go.Scatter(
                    x=[x0, x1, x1, x0, x0],
                    y=[y0, y0, y1, y1, y0],
                    fill="toself",
                    fillcolor=_rgba(p.get_facecolor()),
                    mode="lines",
                    line={"width": 0},
                    hoverinfo="skip",
                    showlegend=False,
                )
            )
    for line in ax.get_lines():
        label = str(line.get_label())
        style = {
            "color": to_hex(line.get_color()),
            "dash": _DASH.get(line.get_linestyle(), "solid"),
            "width": max(1.0, float(line.get_linewidth())),
        }
        tr = line.get_transform()
        x, y = line.get_xdata(), line.get_ydata()
        if tr == ax.get_yaxis_transform():  # axhline
            x, y = list(xlim), [y[0], y[0]]
        elif tr == ax.get_xaxis_transform():  # axvline
            x, y = [x[0], x[0]], list(ylim)
        marker = line.get_marker()
        has_marker = marker not in (None, "None", "", " ")
        has_line = line.get_linestyle() not in ("None", "", " ")
        mode = "+".join(m for m, on in (("lines", has_line), ("markers", has_marker)) if on)
        x, y = _values(x), _values(y)
        if x.size > 2 and np.all(np.diff(x) >= 0):
            x, y = minmax(x, y)
        add(
            go.Scatter(
                x=x,
                y=y,
                mode=mode or "lines",
                line=style,
                marker={
                    "symbol": _MARKERS.get(str(marker), "circle"),
                    "color": style["color"],
                    "size": 8,
                },
                **named(label),
            )
        )
    for t in ax.texts:
        if not isinstance(t, Annotation):
            continue
        coords = t.xycoords if isinstance(t.xycoords, tuple) else (t.xycoords, t.xycoords)
        if coords[0] != "data" or coords[1] not in ("data", "axes fraction"):
            continue
        x, y = t.xy
        kw = {"x": np.log10(x) if xlog else x}
        if coords[1] == "data":
            kw["y"] = np.log10(y) if ylog else y
        else:
            kw.update(y=y, yref="y domain")
        out.add_annotation(
            text=_text(t.get_text()),
            showarrow=False,
            textangle=-t.get_rotation(),
            font={"size": max(8, t.get_fontsize() + 2)},
            xanchor=_XANCHOR.get(t.get_horizontalalignment(), "left"),
            yanchor=_YANCHOR.get(t.get_verticalalignment(), "bottom"),
            row=r,
            col=c,
            **kw,
        )
    out.update_xaxes(
        title_text=_text(ax.get_xlabel()),
        type="log" if xlog else "linear",
        range=[np.log10(v) for v in xlim] if xlog else list(xlim),
        exponentformat="e",
        ticklabelstandoff=5,  # below the y axis' lowest tick label at the corner
        row=r,
        col=c,
    )
    out.update_yaxes(
        title_text=_text(ax.get_ylabel()),
        title_font_size=10,
        type="log" if ylog else "linear",
        range=[np.log10(v) for v in ylim] if ylog else list(ylim),
        exponentformat="e",
        tickformat="" if ylog else "~g",
        ticklabelstandoff=6,  # clear of the x axis' first tick label at the corner
        row=r,
        col=c,
    )


def _heatmap(mesh: QuadMesh, go):
    coords = mesh.get_coordinates()  # (ny+1, nx+1, 2)
    z = np.ma.filled(np.ma.masked_invalid(np.ma.asarray(mesh.get_array(), dtype=float)), np.nan)
    z = z.reshape(coords.shape[0] - 1, coords.shape[1] - 1)
    label = mesh.colorbar.ax.get_ylabel() if mesh.colorbar is not None else ""
    log = isinstance(mesh.norm, LogNorm)
    shown = np.log10(np.where(z > 0, z, np.nan)) if log else z
    return go.Heatmap(
        x=_values(coords[0, :, 0]),
        y=_values(coords[:, 0, 1]),
        z=[_values(row) for row in shown],
        customdata=[_values(row) for row in z],
        colorscale=str(mesh.get_cmap().name).capitalize() if mesh.get_cmap() else None,
        colorbar={"title": {"text": f"log10 {label}" if log else label, "side": "right"}},
        hovertemplate="x %{x:.4g}, y %{y:.4g}: %{customdata:.4g}<extra></extra>",
    )
