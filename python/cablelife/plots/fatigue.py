"""Fatigue pictures: the rainflow range–mean matrix and the damage along the cable."""

from __future__ import annotations

import numpy as np
from matplotlib.colors import LogNorm
from matplotlib.figure import Figure

from cablelife.plots.fatigue_data import DamageMap, RainflowMatrix
from cablelife.plots.figure import new_figure


def plot_rainflow_matrix(matrix: RainflowMatrix) -> Figure:
    """Cycle counts over range (y) and mean (x), logarithmic colours; empty bins blank. Pa are
    drawn as MPa; the LDA's series location (s, γ, φ) goes into the title."""
    fig, axes = new_figure(1, 1, width=6.0, height=4.5)
    ax = axes[0, 0]
    c = np.where(matrix.counts > 0, matrix.counts, np.nan)
    if np.all(np.isnan(c)):
        raise ValueError("counts: the rainflow matrix is empty")
    scale, unit = (1e-6, "MPa") if matrix.unit == "Pa" else (1.0, matrix.unit)
    mesh = ax.pcolormesh(
        matrix.mean_edges * scale,
        matrix.range_edges * scale,
        c,
        norm=LogNorm(vmin=np.nanmin(c), vmax=max(np.nanmax(c), np.nanmin(c) * 1.0001)),
        cmap="viridis",
    )
    fig.colorbar(mesh, ax=ax, label="cycles")
    ax.set_xlabel(f"mean [{unit}]")
    ax.set_ylabel(f"range [{unit}]")
    where = ""
    if matrix.arc_length is not None and matrix.angle is not None:
        where = f"\nat s = {matrix.arc_length:.3f} m, γ = {matrix.angle:.0f}°"
        where += "" if matrix.plane is None else f", plane φ = {matrix.plane:.0f}°"
    ax.set_title(
        f"rainflow range–mean matrix {matrix.label}".strip()
        + f" ({matrix.total:.4g} cycles){where}",
        fontsize=10,
    )
    return fig


def clip_label_rows(clips: dict[str, float], span: float, width: float = 700.0) -> list[int]:
    """A row per clip label (0 = top) so that horizontal labels of ~5.5 px per character on a
    plot ``width`` px wide over ``span`` (data units) never overlap."""
    rows: list[int] = []
    ends: list[float] = []  # right end of the last label per row
    for name, s in clips.items():
        w = (len(name) * 5.5 + 8) / width * span
        row = next((r for r, e in enumerate(ends) if s - w / 2 > e), len(ends))
        if row == len(ends):
            ends.append(-np.inf)
        ends[row] = s + w / 2
        rows.append(row)
    return rows


def plot_damage_along_cable(
    maps, clips: dict[str, float] | None = None, colors: list[str] | None = None
) -> Figure:
    """Largest damage around the circumference along the cable (log scale, from the floor
    DAMAGE_FLOOR × the largest maximum: less is "below floor"), one line per damage map
    (variant); hot spots marked (hover and legend); clips (name → s in m) as vertical lines
    labelled at the top in rows that do not overlap; ``colors`` one per map."""
    from cablelife.plots.fatigue_data import DAMAGE_FLOOR

    maps = [maps] if isinstance(maps, DamageMap) else list(maps)
    if not maps:
        raise ValueError("maps: give at least one DamageMap")
    top = max(float(dm.damage.max()) for dm in maps)
    floor = DAMAGE_FLOOR * top
    fig, axes = new_figure(1, 1, height=3.4)
    ax = axes[0, 0]
    for k, dm in enumerate(maps):
        d = dm.along_cable
        label = dm.label or f"map {k + 1}"
        colour = colors[k] if colors else f"C{k}"
        ax.plot(dm.arc_length, np.where(d >= floor, d, np.nan), color=colour, label=label)
        spots = [h for h in dm.hot_spots() if h.damage >= floor]
        if spots:
            ax.plot(
                [h.arc_length for h in spots],
                [h.damage for h in spots],
                "v",
                color=colour,
                label=f"hot spots {label}",
            )
    clips = dict(sorted((clips or {}).items(), key=lambda kv: kv[1]))
    s_all = np.concatenate([dm.arc_length for dm in maps])
    span = float(s_all.max() - s_all.min()) or 1.0
    rows = clip_label_rows(clips, span)
    for (name, s), row in zip(clips.items(), rows, strict=True):
        ax.axvline(s, color="gray", lw=0.8, ls=":")
        ax.annotate(
            name,
            (s, 0.98 - 0.09 * row),
            xycoords=("data", "axes fraction"),
            fontsize=7,
            ha="center",
            va="top",
        )
    ax.set_yscale("log")
    if top > 0:
        # head room above the curves for the clip labels (~9 % of the height per row)
        ax.set_ylim(floor, top * 10.0 ** (0.7 * (max(rows, default=-1) + 1) + 0.2))
    ax.set_xlabel("arc length s [m]")
    ax.set_ylabel("pseudo-damage (max around the section)")
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=8, loc="lower left")
    ax.set_title(f"damage along the cable (from {DAMAGE_FLOOR:g} × the maximum; less not drawn)")
    return fig
