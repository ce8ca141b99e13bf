"""Figures without pyplot's global state (Agg canvas): PNG files written atomically, or bytes."""

from __future__ import annotations

import io
import os
from pathlib import Path

from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from cablelife.atomic import write_atomic

DPI = 110


def new_figure(rows: int = 1, cols: int = 1, *, width: float = 9.0, height: float = 3.2, **kw):
    """A figure (Agg canvas) with a grid of axes; returns (figure, axes array)."""
    fig = Figure(figsize=(width, height * rows), layout="constrained")
    FigureCanvasAgg(fig)
    axes = fig.subplots(rows, cols, squeeze=False, **kw)
    return fig, axes


def png_bytes(fig: Figure) -> bytes:
    """The figure as PNG bytes."""
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=DPI)
    return buf.getvalue()


def save_png(fig: Figure, path: str | os.PathLike) -> Path:
    """Writes the figure as PNG atomically; returns the path."""
    data = png_bytes(fig)
    return write_atomic(path, lambda f: f.write(data))
