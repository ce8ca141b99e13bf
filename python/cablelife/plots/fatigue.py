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


def plot_damage_along_cable(maps, clips: dict[str, float] | None = None) -> Figure:
    """Largest damage around the circumference along the cable (log scale), one line per
    damage map (variant); hot spots marked; clips (name → s in m) as vertical lines."""
    maps = [maps] if isinstance(maps, DamageMap) else list(maps)
    if not maps:
        raise ValueError("maps: give at least one DamageMap")
    fig, axes = new_figure(1, 1, height=3.4)
    ax = axes[0, 0]
    for k, dm in enumerate(maps):
        d = dm.along_cable
        ax.plot(
            dm.arc_length,
            np.where(d > 0, d, np.nan),
            color=f"C{k}",
            label=dm.label or f"map {k + 1}",
        )
        for h in dm.hot_spots():
            ax.plot(h.arc_length, h.damage, "v", color=f"C{k}")
            clip = "" if h.nearest_clip is None else f"\nnear {h.nearest_clip}"
            ax.annotate(
                f"s={h.arc_length:.3f} m\nγ={np.degrees(h.angle):.0f}°{clip}",
                (h.arc_length, h.damage),
                fontsize=7,
                textcoords="offset points",
                xytext=(4, 4),
            )
    for name, s in (clips or {}).items():
        ax.axvline(s, color="gray", lw=0.8, ls=":")
        ax.annotate(name, (s, 0.02), xycoords=("data", "axes fraction"), fontsize=7, rotation=90)
    ax.set_yscale("log")
    ax.set_xlabel("arc length s [m]")
    ax.set_ylabel("pseudo-damage (max around the section)")
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=8)
    ax.set_title("damage along the cable")
    return fig
