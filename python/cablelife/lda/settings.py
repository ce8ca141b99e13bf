"""The settings of one load data analysis, as a validated model: the `[lda]` table of study
files, the demo and the ``cablelife lda`` options all go through it."""

from __future__ import annotations

from typing import Annotated, Literal

from pydantic import BaseModel, ConfigDict, Field, Strict, ValidationError

from cablelife.lda.pipeline import DEFAULT_POINTS
from cablelife.lda.planes import DEFAULT_PLANE_STEP_DEG
from cablelife.lda.wohler import PSEUDO_K, WohlerCurve, pseudo_damage_curve
from cablelife.scene_types import NonNegativeFloat, PositiveFloat, PositiveInt


class LdaSettings(BaseModel):
    """Wöhler curve (ranges, Pa) and the analysis resolution; defaults as ``cablelife lda``."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    wohler_k: PositiveFloat = PSEUDO_K
    wohler_alpha: PositiveFloat | None = None  # Pa^k; None: pseudo-damage curve
    knee_range: PositiveFloat | None = None  # Pa
    knee_kind: Literal["haibach", "cutoff"] = "haibach"
    points: Annotated[int, Strict(), Field(ge=4)] = DEFAULT_POINTS
    plane_step: Annotated[float, Strict(), Field(gt=0.0, le=90.0)] = DEFAULT_PLANE_STEP_DEG
    section_step: PositiveInt = 1
    residue: Literal["half", "discard", "full", "repeated"] = "half"
    hysteresis: NonNegativeFloat = 0.0  # Pa

    @classmethod
    def from_options(cls, **options) -> LdaSettings:
        """Settings from command-line options; a bad value is a ValueError naming the option
        (``--wohler-k = -1.0: ...``)."""
        try:
            return cls(**options)
        except ValidationError as err:
            lines = [
                f"--{'.'.join(map(str, e['loc'])).replace('_', '-')} = {e.get('input')!r}: "
                + e["msg"].removeprefix("Value error, ")
                for e in err.errors()
            ]
            raise ValueError("; ".join(lines)) from None

    def curve(self) -> WohlerCurve:
        """The Wöhler curve these settings describe."""
        base = (
            pseudo_damage_curve(self.wohler_k)
            if self.wohler_alpha is None
            else WohlerCurve(k=self.wohler_k, alpha=self.wohler_alpha)
        )
        if self.knee_range is None:
            return base
        return WohlerCurve(
            k=base.k,
            alpha=base.alpha,
            knee_range=self.knee_range,
            knee_kind=self.knee_kind,
            pseudo=base.pseudo,
        )

    def analyse_kwargs(self) -> dict:
        """Keyword arguments of :func:`cablelife.lda.pipeline.analyse`."""
        return {
            "curve": self.curve(),
            "n_points": self.points,
            "plane_step_deg": self.plane_step,
            "section_step": self.section_step,
            "residue": self.residue,
            "hysteresis": self.hysteresis,
        }
