"""Plots of results as matplotlib figures (Agg, no display needed): section loads over time
and along the cable, bend radius against a rule, clip reactions, natural frequencies over the
excitation spectrum, rainflow matrices and damage along the cable. See docs/visuals.md."""

from cablelife._lazy import lazy_package

__all__ = lazy_package(
    __name__,
    {
        "cablelife.plots.bend_radius": ["BendRadiusCheck", "check_bend_radius", "plot_bend_radius"],
        "cablelife.plots.clips": ["plot_clip_reactions"],
        "cablelife.plots.fatigue": ["plot_damage_along_cable", "plot_rainflow_matrix"],
        "cablelife.plots.fatigue_data": ["DamageMap", "HotSpot", "RainflowMatrix", "damage_maps"],
        "cablelife.plots.figure": ["png_bytes", "save_png"],
        "cablelife.plots.loads": ["plot_envelopes", "plot_maxima_over_time"],
        "cablelife.plots.runs": ["QUANTITIES", "Run", "as_runs", "quantity"],
        "cablelife.plots.spectrum": ["plot_frequencies_over_spectrum"],
    },
)
