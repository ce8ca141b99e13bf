"""Margins of the report's 2D figures, wide enough for their labels and legend.

Plotly's automatic margins (``automargin``, on in its default template) grow a margin that is
too small for the tick labels, axis titles or a legend beside the plot, and each growth lays
the figure out a second time: about half of a 2D figure's drawing time in the report
(``benchmarks/bench_report.py``). Starting from margins that already fit, nothing grows;
automargin stays on as the safety net."""

from __future__ import annotations

LEFT = 95  # px: tick labels such as "−0.00916" and a two-line axis title
BOTTOM = 60  # px: tick labels and the x axis title
TOP = 60  # px: the figure's title (70 with a title above the subplots)
# The plot area as with plotly's default margins (50 px top and bottom): figures are this much
# taller (a log axis' labels need the height).
EXTRA_HEIGHT = TOP - 50 + BOTTOM - 50


def legend_room(names) -> int:
    """Right margin (px) for a legend of these entries beside the plot (font size 10)."""
    names = [str(n) for n in names if n]
    return 20 if not names else min(320, 60 + 6 * max(map(len, names)))
