"""The HTML report and the interactive 3D views (plotly, offline). See docs/visuals.md."""

from cablelife.report.html import ReportRun, build_report, write_report
from cablelife.report.interactive import maxima_over_time_figure
from cablelife.report.scene3d import cable_figure, damage_figure
from cablelife.report.tube import TubeMesh, tube_mesh

__all__ = [
    "ReportRun",
    "TubeMesh",
    "build_report",
    "cable_figure",
    "damage_figure",
    "maxima_over_time_figure",
    "tube_mesh",
    "write_report",
]
