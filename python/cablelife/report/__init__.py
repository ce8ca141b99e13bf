"""The HTML report and the interactive 3D views (plotly, offline). See docs/visuals.md."""

from cablelife._lazy import lazy_package

__all__ = lazy_package(
    __name__,
    {
        "cablelife.report.html": ["ReportRun", "build_report", "write_report"],
        "cablelife.report.interactive": ["maxima_over_time_figure"],
        "cablelife.report.scene3d": ["cable_figure", "damage_figure"],
        "cablelife.report.tube": ["TubeMesh", "tube_mesh"],
    },
)
