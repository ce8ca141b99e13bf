"""Runs to plot: a cable's result with a label and the simulation mode that sets its line
style (quasistatic dashed, dynamic solid, static dotted)."""

from __future__ import annotations

import os
import re
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from cablelife.results import CableResult, Result, load_result

LINESTYLE = {"quasistatic": "--", "dynamic": "-", "static": ":"}


@dataclass
class Run:
    """One cable of one run, as plotted."""

    label: str
    cable: CableResult
    mode: str = "dynamic"
    color: str | None = None  # default: the k-th colour of the cycle

    def colour(self, k: int) -> str:
        """This run's colour (one per variant in the report), else the k-th of the cycle."""
        return self.color or f"C{k % 10}"

    @property
    def legend(self) -> str:
        """Legend text: the label and, when it differs, the mode."""
        return self.label if self.label == self.mode else f"{self.label} ({self.mode})"

    @property
    def linestyle(self) -> str:
        return LINESTYLE.get(self.mode, "-")


def variant_of(label: str, mode: str) -> str:
    """The variant a run belongs to: its label without the mode ("A-dynamic" → "A")."""
    v = re.sub(rf"[\s_\-(]*{mode}\)?$", "", label).strip()
    return v or label


def variant_colours(runs: Sequence[Run]) -> list[str]:
    """A colour per run: its own, else one of the cycle per variant (the quasistatic and
    dynamic runs of a variant share it)."""
    seen: dict[str, int] = {}
    out = []
    for r in runs:
        k = seen.setdefault(variant_of(r.label, r.mode), len(seen))
        out.append(r.colour(k))
    return out


def as_runs(items, cable: str | None = None) -> list[Run]:
    """Runs from a :class:`Run`, :class:`Result`, :class:`CableResult`, a result file path,
    or a sequence of these. A result with several cables gives one run per cable unless
    ``cable`` names one."""
    if isinstance(items, (Run, Result, CableResult, str, os.PathLike)):
        items = [items]
    runs: list[Run] = []
    for item in items:
        if isinstance(item, Run):
            runs.append(item)
            continue
        label = None
        if isinstance(item, (str, os.PathLike)):
            label = Path(item).stem
            item = load_result(item)
        if isinstance(item, CableResult):
            runs.append(Run(label or item.name, item))
            continue
        if not isinstance(item, Result):
            raise TypeError(f"cannot plot {type(item).__name__}: give a Result, path or Run")
        names = [cable] if cable is not None else list(item.cables)
        for name in names:
            if name not in item.cables:
                raise ValueError(f"cable = {name!r}: the result has {', '.join(item.cables)}")
            tag = label or item.mode
            runs.append(
                Run(tag if len(names) == 1 else f"{tag}: {name}", item.cables[name], item.mode)
            )
    if not runs:
        raise ValueError("no runs to plot")
    return runs


# Quantities: name -> (label, unit, where, function of a cable giving (T, n) values)
def _shear(c: CableResult) -> np.ndarray:
    return np.hypot(c.forces[..., 0], c.forces[..., 1])


def _bending(c: CableResult) -> np.ndarray:
    return np.hypot(c.moments[..., 0], c.moments[..., 1])


QUANTITIES = {
    "shear": ("shear force |F1, F2|", "N", "edges", _shear),
    "tension": ("tension F3", "N", "edges", lambda c: c.forces[..., 2]),
    "bending": ("bending moment |M1, M2|", "N m", "nodes", _bending),
    "torsion": ("torsion M3", "N m", "nodes", lambda c: c.moments[..., 2]),
}


def quantity(c: CableResult, name: str) -> tuple[np.ndarray, np.ndarray]:
    """(arc length (n,), values (T, n)) of a quantity: edges at their midpoints."""
    if name not in QUANTITIES:
        raise ValueError(f"quantity = {name!r}: allowed are {', '.join(QUANTITIES)}")
    _, _, where, f = QUANTITIES[name]
    s = c.arc_length
    return (0.5 * (s[1:] + s[:-1]) if where == "edges" else s), f(c)


def extreme_along(values: np.ndarray) -> np.ndarray:
    """Per time step, the value of largest magnitude along the cable (sign kept), (T,)."""
    i = np.argmax(np.abs(values), axis=1)
    return np.take_along_axis(values, i[:, None], axis=1)[:, 0]


def check_runs(runs: Sequence[Run]) -> None:
    for r in runs:
        if r.cable.n_steps == 0:
            raise ValueError(f"run {r.label!r} has no saved steps")
