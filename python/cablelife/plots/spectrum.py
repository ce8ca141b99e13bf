"""Natural frequencies of the mounted cable over the excitation spectrum."""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from cablelife.plots.figure import new_figure


def variance_band(frequency, psd, share: float = 0.99) -> tuple[float, float]:
    """(lowest, highest) frequency of the band that holds the central ``share`` of the
    variance of the largest of the PSDs ((F,) or (C, F)): a robust estimate of the excited band
    of a measured signal (leakage, e.g. of a fade-in, carries little variance)."""
    f = np.asarray(frequency, dtype=float)
    top = np.atleast_2d(np.asarray(psd, dtype=float)).max(axis=0)
    total = top.sum()
    if not total > 0:
        return (0.0, 0.0)
    c = np.cumsum(top) / total
    lo = f[np.searchsorted(c, (1 - share) / 2)]
    hi = f[min(np.searchsorted(c, 1 - (1 - share) / 2), f.size - 1)]
    return float(lo), float(hi)


def excited_band(frequency, psd, band_level: float = 0.0) -> tuple[float, float]:
    """(lowest, highest) frequency where the largest of the PSDs ((F,) or (C, F)) exceeds
    ``band_level`` × its peak; (0, 0) when every PSD is zero."""
    f = np.asarray(frequency, dtype=float)
    top = np.atleast_2d(np.asarray(psd, dtype=float)).max(axis=0)
    band = f[top > band_level * top.max()] if np.any(top > 0) else f[:0]
    return (float(band.min()), float(band.max())) if band.size else (0.0, 0.0)


def plot_frequencies_over_spectrum(
    natural_frequencies,
    frequency,
    psd,
    *,
    psd_label: str = "excitation PSD",
    psd_unit: str = "(m/s²)²/Hz",
    labels: list[str] | None = None,
    band_level: float = 0.0,
    band: tuple[float, float] | None = None,
) -> Figure:
    """The excitation PSD (``frequency`` (F,) Hz, ``psd`` (F,) or (C, F) for C channels, named
    by ``labels``) on log-log axes, with a vertical line at each natural frequency (Hz)
    labelled by mode number. Modes inside the excited band (where the largest PSD exceeds
    ``band_level`` × its peak) are drawn red."""
    fn = np.atleast_1d(np.asarray(natural_frequencies, dtype=float))
    f = np.asarray(frequency, dtype=float)
    g = np.atleast_2d(np.asarray(psd, dtype=float))
    if f.ndim != 1 or g.shape[1] != f.size:
        raise ValueError(
            f"psd has shape {np.shape(psd)}: must be (F,) or (C, F) with F = {f.size} frequencies"
        )
    if np.any(fn <= 0) or np.any(~np.isfinite(fn)):
        raise ValueError(f"natural_frequencies = {fn}: must be finite and > 0 Hz")
    if labels is not None and len(labels) != len(g):
        raise ValueError(f"labels: {len(labels)} given for {len(g)} PSD channels")
    if not 0.0 <= band_level < 1.0:
        raise ValueError(f"band_level = {band_level}: must be in [0, 1)")
    fig, axes = new_figure(1, 1, height=3.6)
    ax = axes[0, 0]
    for k, row in enumerate(g):
        ax.loglog(
            f,
            np.where(row > 0, row, np.nan),
            color=f"C{k}",
            label=labels[k] if labels else (f"{psd_label} {k + 1}" if len(g) > 1 else psd_label),
        )
    excited = band if band is not None else excited_band(f, g, band_level)
    if band is not None:
        ax.axvspan(*band, color="red", alpha=0.06, lw=0)
    for i, x in enumerate(fn):
        inside = excited[0] <= x <= excited[1]
        ax.axvline(
            x,
            color="red" if inside else "gray",
            lw=1,
            ls="-" if inside else "--",
            label=f"mode {i + 1}: {x:.3g} Hz",
        )
    ax.set_xlim(min(f[f > 0].min(initial=fn.min()), fn.min()) / 1.2, max(f.max(), fn.max()) * 1.2)
    ax.set_xlabel("frequency [Hz]")
    ax.set_ylabel(f"PSD [{psd_unit}]")
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=7, loc="center left", bbox_to_anchor=(1.01, 0.5))
    ax.set_title("natural frequencies over the excitation spectrum (red: inside the excited band)")
    return fig
