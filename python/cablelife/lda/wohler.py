"""Wöhler curve in stress RANGES and the documented pseudo-damage default.

N(ΔS) = α ΔS^(−k) cycles to failure at a constant stress RANGE ΔS (peak to valley, not an
amplitude; with amplitudes S_a = ΔS/2 the same curve is N = α 2^(−k) S_a^(−k) — pyLife and
many data sheets use amplitudes). Units: ΔS in Pa, α in Pa^k.

Optional knee at ΔS_D (N_D = α ΔS_D^(−k)): below it Haibach's slope 2k − 1 (``"haibach"``)
or no damage (``"cutoff"``).

Pseudo-damage default (:func:`pseudo_damage_curve`): k = 5 and the curve through
(ΔS = 1 MPa, N = 10⁶), i.e. α = 10⁶ · (10⁶ Pa)^k, so D = Σ n_i (ΔS_i / 1 MPa)^k / 10⁶.
k = 5 is the slope of the FKM guideline's component S–N curve for normal stress and the
common default of comparative load data analyses. The reference point only scales all values:
cable surface stress ranges of a few MPa over a few thousand cycles give pseudo-damage of
order 1–1000, like the paper's figures. Pseudo-damage compares variants; it is not a life.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

PSEUDO_K = 5.0
PSEUDO_REFERENCE_RANGE = 1e6  # Pa
PSEUDO_REFERENCE_CYCLES = 1e6
KNEE_KINDS = ("haibach", "cutoff")


@dataclass(frozen=True)
class WohlerCurve:
    """N = α ΔS^(−k) in ranges (Pa); optional knee at ``knee_range`` (Pa)."""

    k: float
    alpha: float
    knee_range: float | None = None
    knee_kind: str = "haibach"
    pseudo: bool = False

    def __post_init__(self):
        if not (math.isfinite(self.k) and self.k > 0):
            raise ValueError(f"Wöhler slope k = {self.k!r}: must be a finite number > 0")
        if not (math.isfinite(self.alpha) and self.alpha > 0):
            raise ValueError(
                f"Wöhler constant alpha = {self.alpha!r}: must be a finite number > 0 (Pa^k)"
            )
        if self.knee_range is not None and not (
            math.isfinite(self.knee_range) and self.knee_range > 0
        ):
            raise ValueError(
                f"knee_range = {self.knee_range!r}: must be a finite stress range > 0 (Pa) or None"
            )
        if self.knee_kind not in KNEE_KINDS:
            raise ValueError(f"knee_kind = {self.knee_kind!r}: must be one of {KNEE_KINDS}")

    @classmethod
    def from_point(
        cls,
        k: float,
        range_: float,
        cycles: float,
        *,
        knee: bool = False,
        knee_kind: str = "haibach",
    ) -> WohlerCurve:
        """Curve of slope k through (ΔS = ``range_``, N = ``cycles``); with ``knee=True`` that
        point is the knee (ΔS_D, N_D)."""
        if not (math.isfinite(range_) and range_ > 0):
            raise ValueError(f"range_ = {range_!r}: must be a finite stress range > 0 (Pa)")
        if not (math.isfinite(cycles) and cycles > 0):
            raise ValueError(f"cycles = {cycles!r}: must be a finite number > 0")
        return cls(
            k=k,
            alpha=cycles * range_**k,
            knee_range=range_ if knee else None,
            knee_kind=knee_kind,
        )

    @property
    def knee_cycles(self) -> float | None:
        return None if self.knee_range is None else self.alpha * self.knee_range ** (-self.k)

    def cycles_to_failure(self, range_):
        """N(ΔS) for stress ranges (array or scalar); inf at zero range or below a cut-off."""
        import numpy as np

        r = np.asarray(range_, float)
        with np.errstate(divide="ignore"):
            n = self.alpha * r ** (-self.k)
            if self.knee_range is not None:
                below = r < self.knee_range
                if self.knee_kind == "cutoff":
                    n = np.where(below, np.inf, n)
                else:
                    nd = self.knee_cycles
                    n = np.where(below, nd * (r / self.knee_range) ** (-(2 * self.k - 1)), n)
        return n[()] if n.ndim == 0 else n

    def kernel_args(self) -> dict:
        """Keyword arguments of the Rust kernels."""
        return {
            "k": float(self.k),
            "alpha": float(self.alpha),
            "knee_range": None if self.knee_range is None else float(self.knee_range),
            "knee_kind": self.knee_kind,
        }

    def as_attrs(self) -> dict:
        return {
            "wohler_k": self.k,
            "wohler_alpha": self.alpha,
            "wohler_knee_range": -1.0 if self.knee_range is None else self.knee_range,
            "wohler_knee_kind": self.knee_kind,
            "pseudo_damage": self.pseudo,
        }

    @classmethod
    def from_attrs(cls, attrs: dict) -> WohlerCurve:
        knee = float(attrs["wohler_knee_range"])
        return cls(
            k=float(attrs["wohler_k"]),
            alpha=float(attrs["wohler_alpha"]),
            knee_range=None if knee < 0 else knee,
            knee_kind=str(attrs["wohler_knee_kind"]),
            pseudo=bool(attrs["pseudo_damage"]),
        )


def pseudo_damage_curve(k: float = PSEUDO_K) -> WohlerCurve:
    """The documented pseudo-damage curve: slope k through (1 MPa, 10⁶ cycles), no knee."""
    return WohlerCurve(
        k=k,
        alpha=PSEUDO_REFERENCE_CYCLES * PSEUDO_REFERENCE_RANGE**k,
        pseudo=True,
    )
