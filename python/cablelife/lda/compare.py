"""Compare variants: rank damage analyses by their maximum (pseudo-)damage.

Items may be damage files, result files (analysed on the fly with the given LDA settings),
:class:`~cablelife.lda.pipeline.DamageAnalysis` or :class:`~cablelife.results.Result` objects.
Damage values are only comparable with the same Wöhler curve and settings; a mismatch is an
error unless ``check_settings=False``.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from pathlib import Path

from cablelife.lda.io import is_damage_file, load_damage
from cablelife.lda.pipeline import DamageAnalysis, HotSpot, analyse
from cablelife.results import Result

_COMPARED = ("wohler_k", "wohler_alpha", "wohler_knee_range", "wohler_knee_kind")
_SETTINGS = ("n_points", "plane_step_deg", "residue", "hysteresis")


@dataclass(frozen=True)
class Variant:
    label: str
    max_damage: float
    ratio: float  # max_damage / best max_damage (1 for the best)
    hot_spots: list[HotSpot]
    analysis: DamageAnalysis


@dataclass(frozen=True)
class Comparison:
    """Variants sorted by maximum damage, best (lowest) first."""

    variants: list[Variant]

    @property
    def best(self) -> Variant:
        return self.variants[0]

    def table(self, n_hot_spots: int = 1) -> str:
        """Plain-text ranking: rank, label, max damage, ratio to the best, hot spots."""
        width = max([7] + [len(v.label) for v in self.variants])
        kind = "pseudo-D" if all(v.analysis.curve.pseudo for v in self.variants) else "D"
        lines = [f"{'rank':>4}  {'variant':<{width}}  {'max ' + kind:>12}  {'ratio':>7}  hot spot"]
        for i, v in enumerate(self.variants, 1):
            spots = v.hot_spots[:n_hot_spots] or [None]
            for j, h in enumerate(spots):
                where = "" if h is None else h.describe()
                if j == 0:
                    lines.append(
                        f"{i:>4}  {v.label:<{width}}  {v.max_damage:>12.4g}  "
                        f"{v.ratio:>7.3g}  {where}"
                    )
                else:
                    lines.append(f"{'':>4}  {'':<{width}}  {'':>12}  {'':>7}  {where}")
        return "\n".join(lines)


def _label(p: Path) -> str:
    """A run's label from its file: the stem, or the folder for the generic names of a study
    or the demo (variants/<run>/damage.h5)."""
    stem = p.stem.removesuffix(".damage")
    return p.parent.name if stem in ("damage", "result") and p.parent.name else stem


def _load(item, lda_kwargs) -> tuple[str, DamageAnalysis]:
    if isinstance(item, DamageAnalysis):
        return (_label(Path(item.source)) if item.source else "variant"), item
    if isinstance(item, Result):
        return "variant", analyse(item, **lda_kwargs)
    if isinstance(item, str | os.PathLike):
        p = Path(item)
        if not p.exists():
            raise FileNotFoundError(f"{str(p)!r} does not exist")
        if is_damage_file(p):
            return _label(p), load_damage(p)
        return _label(p), analyse(p, **lda_kwargs)
    raise TypeError(
        f"cannot compare {type(item).__name__}: give damage/result file paths, DamageAnalysis "
        "or Result objects"
    )


def _signature(a: DamageAnalysis) -> dict:
    attrs = a.curve.as_attrs()
    sig = {k: attrs[k] for k in _COMPARED}
    sig.update({k: a.settings.get(k) for k in _SETTINGS})
    return sig


def compare(
    items,
    labels: list[str] | None = None,
    *,
    check_settings: bool = True,
    check_modes: bool = True,
    n_hot_spots: int = 3,
    **lda_kwargs,
) -> Comparison:
    """Rank variants by maximum damage; ratios are relative to the best (lowest) variant.
    Runs of different analysis modes (quasistatic vs dynamic) are not ranked together unless
    ``check_modes=False``: their ratio is the inertia factor, not a variant's merit."""
    items = list(items)
    if len(items) == 0:
        raise ValueError("compare needs at least one variant")
    if labels is not None and len(labels) != len(items):
        raise ValueError(f"{len(labels)} labels for {len(items)} variants: give one label each")
    loaded = [_load(it, lda_kwargs) for it in items]
    names = list(labels) if labels is not None else [n for n, _ in loaded]
    if len(set(names)) < len(names):
        names = [f"{n} [{i + 1}]" for i, n in enumerate(names)]
    modes = {n: a.mode for n, (_, a) in zip(names, loaded, strict=True) if a.mode}
    if check_modes and len(set(modes.values())) > 1:
        raise ValueError(
            "the runs were simulated in different modes ("
            + ", ".join(f"{n}: {m}" for n, m in modes.items())
            + "): rank the variants within one mode (their dynamic/quasistatic ratio is the "
            "inertia factor); cablelife compare --force (check_modes=False) ranks them anyway"
        )
    if check_settings:
        ref = _signature(loaded[0][1])
        for name, (_, a) in zip(names[1:], loaded[1:], strict=True):
            sig = _signature(a)
            diff = {k: (ref[k], sig[k]) for k in ref if ref[k] != sig[k]}
            if diff:
                raise ValueError(
                    f"variant {name!r} was analysed with other settings than {names[0]!r}: "
                    + ", ".join(f"{k} {a_!r} vs {b_!r}" for k, (a_, b_) in diff.items())
                    + "; damage values are not comparable (check_settings=False to override)"
                )
    best = min(a.max_damage for _, a in loaded)
    variants = []
    for name, (_, a) in zip(names, loaded, strict=True):
        d = a.max_damage
        ratio = d / best if best > 0 else (1.0 if d == 0 else math.inf)
        variants.append(Variant(name, d, ratio, a.hot_spots(n_hot_spots), a))
    variants.sort(key=lambda v: v.max_damage)
    return Comparison(variants)
