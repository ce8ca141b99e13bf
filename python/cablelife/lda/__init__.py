"""Comparative load data analysis (LDA): section loads → pseudo-damage map on the surface.

Pipeline (:func:`analyse`): cross sections at the nodes (:mod:`.stations`) → exact
Saint-Venant surface stresses (:mod:`.stress`) → critical-plane normal stresses, one weight
matrix per section (:mod:`.planes`) → rainflow counting (ASTM E1049-85) and Palmgren–Miner with
a Wöhler curve in RANGES (:mod:`.damage`, Rust kernel) → damage map, hot spots, HDF5 damage file
(:mod:`.io`) → ranking of variants (:mod:`.compare`). See docs/lda.md.
"""

from cablelife._lazy import lazy_package

__all__ = lazy_package(
    __name__,
    {
        "cablelife.lda.compare": ["Comparison", "compare"],
        "cablelife.lda.damage": ["damage", "damage_combined", "equivalent_range"],
        "cablelife.lda.io": ["load_damage", "save_damage"],
        "cablelife.lda.pipeline": ["CableDamage", "DamageAnalysis", "HotSpot", "analyse"],
        "cablelife.lda.planes": ["plane_angles", "plane_weights", "section_series"],
        "cablelife.lda.rainflow": [
            "Cycles",
            "from_to_matrix",
            "rainflow_cycles",
            "range_mean_matrix",
            "turning_points",
        ],
        "cablelife.lda.sampling": ["SamplingWarning", "check_sampling"],
        "cablelife.lda.spectral": [
            "dirlik_damage_rate",
            "gaussian_signal",
            "narrow_band_damage_rate",
        ],
        "cablelife.lda.stress": ["CircularSection", "surface_angles"],
        "cablelife.lda.wohler": ["WohlerCurve", "pseudo_damage_curve"],
    },
)
