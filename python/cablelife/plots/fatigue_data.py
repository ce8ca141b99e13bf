"""The inputs the pictures take from the fatigue analysis (LDA): a damage map on the cable
surface with its hot spots, and a rainflow range–mean matrix. Plain arrays, so any analysis can
feed them; :func:`damage_maps` makes them from an LDA result or damage file (read by
:func:`cablelife.lda.io.load_damage`, the one reader of damage files).

Angle convention (as in the LDA): the surface angle γ is measured from the section axis d1
towards d2, so the surface point is x + r (cos γ d1 + sin γ d2).
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass

import numpy as np

from cablelife.lda.rainflow import RainflowMatrix

__all__ = ["DAMAGE_FLOOR", "DamageMap", "HotSpot", "RainflowMatrix", "damage_maps"]

#: Damage below this fraction of a map's maximum is "below floor": the pictures' colour and
#: log scales start there and hot spots are listed only above it. Spans that do not move carry
#: numerical-noise damage (1e-50 … 1e-78) that would otherwise set the scale.
DAMAGE_FLOOR = 1e-6


@dataclass
class HotSpot:
    """A damage maximum on the surface; the LDA's hot spots also give the plane and clip."""

    arc_length: float  # m
    angle: float  # rad, surface angle γ
    damage: float
    plane: float | None = None  # rad, critical plane φ from the cable axis
    nearest_clip: str | None = None
    clip_distance: float | None = None  # m

    def describe(self) -> str:
        """One line: s, γ, damage and, when known, the nearest clip."""
        clip = (
            f", {self.clip_distance * 1e3:.0f} mm from clip {self.nearest_clip}"
            if self.nearest_clip is not None and self.clip_distance is not None
            else ""
        )
        return (
            f"s = {self.arc_length:.3f} m, γ = {math.degrees(self.angle):.0f}°, "
            f"D = {self.damage:.3g}{clip}"
        )


@dataclass
class DamageMap:
    """Damage (S, G) over stations ``arc_length`` (S,) m and surface angles ``angle`` (G,) rad;
    ``spots``: the analysis' own hot spots (else :meth:`hot_spots` finds them)."""

    arc_length: np.ndarray
    angle: np.ndarray
    damage: np.ndarray
    label: str = ""
    spots: list[HotSpot] | None = None

    def __post_init__(self):
        self.arc_length = np.asarray(self.arc_length, dtype=float)
        self.angle = np.asarray(self.angle, dtype=float)
        self.damage = np.asarray(self.damage, dtype=float)
        want = (self.arc_length.size, self.angle.size)
        if self.damage.shape != want:
            raise ValueError(
                f"damage has shape {self.damage.shape}: must be {want} "
                "(len(arc_length), len(angle))"
            )
        if np.any(self.damage < 0) or not np.all(np.isfinite(self.damage)):
            raise ValueError("damage: must be finite and >= 0")

    @classmethod
    def from_lda(cls, cable_damage, label: str = "", n_hot_spots: int = 5) -> DamageMap:
        """The map of an LDA :class:`~cablelife.lda.pipeline.CableDamage` (max over the
        planes) with the LDA's hot spots (local maxima along s, nearest clip)."""
        spots = [
            HotSpot(
                h.arc_length,
                math.radians(h.angle),
                h.damage,
                math.radians(h.plane),
                h.nearest_clip,
                h.clip_distance,
            )
            for h in cable_damage.hot_spots(n_hot_spots)
        ]
        c = cable_damage
        return cls(c.arc_length, c.angles, c.damage, label or c.cable, spots)

    def check_fits(self, arc_length: np.ndarray, what: str = "the cable") -> None:
        """ValueError unless the map's stations lie on ``arc_length`` (a cable's nodes, m)."""
        s = np.asarray(arc_length, dtype=float)
        tol = 1e-9 * max(1.0, float(abs(s).max()))
        if self.arc_length.size and (
            self.arc_length.min() < s[0] - tol or self.arc_length.max() > s[-1] + tol
        ):
            raise ValueError(
                f"damage map {self.label!r} spans s = {self.arc_length.min():.4g} … "
                f"{self.arc_length.max():.4g} m, but {what} spans {s[0]:.4g} … {s[-1]:.4g} m: "
                "the damage file belongs to another result"
            )

    @property
    def floor(self) -> float:
        """Damage below which the pictures show "below floor": DAMAGE_FLOOR × the maximum."""
        return DAMAGE_FLOOR * float(self.damage.max()) if self.damage.size else 0.0

    @property
    def along_cable(self) -> np.ndarray:
        """Largest damage around the circumference per station, (S,)."""
        return self.damage.max(axis=1)

    def hot_spots(self, count: int = 3, separation: float = 0.05) -> list[HotSpot]:
        """The analysis' hot spots when given, else the ``count`` largest damages at stations
        at least ``separation`` (m) apart; only those above the floor."""
        floor = self.floor
        if self.spots is not None:
            return [h for h in self.spots if h.damage > 0 and h.damage >= floor][:count]
        along = self.along_cable
        spots: list[HotSpot] = []
        for i in np.argsort(along)[::-1]:
            if along[i] <= 0 or along[i] < floor or len(spots) >= count:
                break
            s = self.arc_length[i]
            if all(abs(s - h.arc_length) >= separation for h in spots):
                j = int(np.argmax(self.damage[i]))
                spots.append(HotSpot(float(s), float(self.angle[j]), float(self.damage[i, j])))
        return spots

    def on_surface(self, arc_length: np.ndarray, angles: np.ndarray) -> np.ndarray:
        """Damage (len(arc_length), len(angles)) at other stations and surface angles: linear
        in s (constant beyond the ends), periodic-linear in γ."""
        s = np.asarray(arc_length, dtype=float)
        along = np.array([np.interp(s, self.arc_length, col) for col in self.damage.T]).T
        order = np.argsort(np.mod(self.angle, 2 * np.pi))
        a = np.mod(self.angle, 2 * np.pi)[order]
        a = np.concatenate([a, [a[0] + 2 * np.pi]])
        rows = np.concatenate([along[:, order], along[:, order[:1]]], axis=1)
        g = np.mod(np.asarray(angles, dtype=float) - a[0], 2 * np.pi) + a[0]
        return np.array([np.interp(g, a, row) for row in rows])


def damage_maps(source, label: str = "") -> dict[str, tuple[DamageMap, RainflowMatrix | None]]:
    """Damage map and rainflow matrix (None when the file has none) per cable of an LDA
    result: a :class:`~cablelife.lda.pipeline.DamageAnalysis` or a damage file written by
    ``cablelife lda``."""
    from cablelife.lda.io import load_damage
    from cablelife.lda.pipeline import DamageAnalysis

    if isinstance(source, str | os.PathLike):
        source = load_damage(source)
    if not isinstance(source, DamageAnalysis):
        raise TypeError(
            f"damage source: got {type(source).__name__}; give a DamageAnalysis or the path of "
            "a damage file (cablelife lda RESULT.h5 -o DAMAGE.h5)"
        )
    out = {}
    for name, c in source.cables.items():
        lab = f"{label}: {name}" if label and len(source.cables) > 1 else (label or name)
        out[name] = (DamageMap.from_lda(c, lab), c.rainflow)
    return out
