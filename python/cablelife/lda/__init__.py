"""Comparative load data analysis (LDA): section loads → pseudo-damage map on the surface.

Pipeline (:func:`analyse`): cross sections at the nodes (:mod:`.stations`) → exact
Saint-Venant surface stresses (:mod:`.stress`) → critical-plane normal stresses, one weight
matrix per section (:mod:`.planes`) → rainflow counting (ASTM E1049-85) and Palmgren–Miner with
a Wöhler curve in RANGES (:mod:`.damage`, Rust kernel) → damage map, hot spots, HDF5 damage file
(:mod:`.io`) → ranking of variants (:mod:`.compare`). See docs/lda.md.
"""

from cablelife.lda.compare import Comparison, compare
from cablelife.lda.damage import damage, damage_combined, equivalent_range
from cablelife.lda.io import load_damage, save_damage
from cablelife.lda.pipeline import CableDamage, DamageAnalysis, HotSpot, analyse
from cablelife.lda.planes import plane_angles, plane_weights, section_series
from cablelife.lda.rainflow import (
    Cycles,
    from_to_matrix,
    rainflow_cycles,
    range_mean_matrix,
    turning_points,
)
from cablelife.lda.sampling import SamplingWarning, check_sampling
from cablelife.lda.spectral import dirlik_damage_rate, gaussian_signal, narrow_band_damage_rate
from cablelife.lda.stress import CircularSection, surface_angles
from cablelife.lda.wohler import WohlerCurve, pseudo_damage_curve

__all__ = [
    "CableDamage",
    "CircularSection",
    "Comparison",
    "Cycles",
    "DamageAnalysis",
    "HotSpot",
    "SamplingWarning",
    "WohlerCurve",
    "analyse",
    "check_sampling",
    "compare",
    "damage",
    "damage_combined",
    "dirlik_damage_rate",
    "equivalent_range",
    "from_to_matrix",
    "gaussian_signal",
    "load_damage",
    "narrow_band_damage_rate",
    "plane_angles",
    "plane_weights",
    "pseudo_damage_curve",
    "rainflow_cycles",
    "range_mean_matrix",
    "save_damage",
    "section_series",
    "surface_angles",
    "turning_points",
]
