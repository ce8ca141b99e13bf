"""Plots of results as matplotlib figures (Agg, no display needed): section loads over time
and along the cable, bend radius against a rule, clip reactions, natural frequencies over the
excitation spectrum, rainflow matrices and damage along the cable. See docs/visuals.md."""

from cablelife.plots.bend_radius import BendRadiusCheck, check_bend_radius, plot_bend_radius
from cablelife.plots.clips import plot_clip_reactions
from cablelife.plots.fatigue import plot_damage_along_cable, plot_rainflow_matrix
from cablelife.plots.fatigue_data import DamageMap, HotSpot, RainflowMatrix, damage_maps
from cablelife.plots.figure import png_bytes, save_png
from cablelife.plots.loads import plot_envelopes, plot_maxima_over_time
from cablelife.plots.runs import QUANTITIES, Run, as_runs, quantity
from cablelife.plots.spectrum import plot_frequencies_over_spectrum

__all__ = [
    "QUANTITIES",
    "BendRadiusCheck",
    "DamageMap",
    "HotSpot",
    "RainflowMatrix",
    "Run",
    "as_runs",
    "check_bend_radius",
    "damage_maps",
    "plot_bend_radius",
    "plot_clip_reactions",
    "plot_damage_along_cable",
    "plot_envelopes",
    "plot_frequencies_over_spectrum",
    "plot_maxima_over_time",
    "plot_rainflow_matrix",
    "png_bytes",
    "quantity",
    "save_png",
]
