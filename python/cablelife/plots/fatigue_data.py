"""The inputs the pictures take from the fatigue analysis (LDA): a pseudo-damage map on the
cable surface and a rainflow range–mean matrix. Plain arrays, so any analysis can feed them.

A damage file (HDF5) is read by :func:`load_damage` when it holds, either at the root or in
``/cables/<name>/`` (one map per cable)::

    arc_length   (S,)    m     stations along the cable (cross sections)
    angle        (G,)    rad   surface angle γ of the sample points (``surface_angle`` too)
    damage       (S, G)  1     damage per station and surface point (max over planes)
    rainflow/range_edges (R+1,), rainflow/mean_edges (M+1,), rainflow/counts (R, M)  optional
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np


@dataclass
class RainflowMatrix:
    """Cycle counts (R, M) in bins of range (edges (R+1,)) and mean (edges (M+1,))."""

    range_edges: np.ndarray
    mean_edges: np.ndarray
    counts: np.ndarray
    unit: str = "MPa"
    label: str = ""

    def __post_init__(self):
        self.range_edges = np.asarray(self.range_edges, dtype=float)
        self.mean_edges = np.asarray(self.mean_edges, dtype=float)
        self.counts = np.asarray(self.counts, dtype=float)
        want = (self.range_edges.size - 1, self.mean_edges.size - 1)
        if self.counts.shape != want:
            raise ValueError(
                f"counts has shape {self.counts.shape}: must be {want} "
                "(len(range_edges) - 1, len(mean_edges) - 1)"
            )


@dataclass
class HotSpot:
    arc_length: float  # m
    angle: float  # rad
    damage: float


@dataclass
class DamageMap:
    """Damage (S, G) over stations ``arc_length`` (S,) m and surface angles ``angle`` (G,) rad."""

    arc_length: np.ndarray
    angle: np.ndarray
    damage: np.ndarray
    label: str = ""

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

    @property
    def along_cable(self) -> np.ndarray:
        """Largest damage around the circumference per station, (S,)."""
        return self.damage.max(axis=1)

    def hot_spots(self, count: int = 3, separation: float = 0.05) -> list[HotSpot]:
        """The ``count`` largest damages at stations at least ``separation`` (m) apart."""
        along = self.along_cable
        spots: list[HotSpot] = []
        for i in np.argsort(along)[::-1]:
            if along[i] <= 0 or len(spots) >= count:
                break
            s = self.arc_length[i]
            if all(abs(s - h.arc_length) >= separation for h in spots):
                j = int(np.argmax(self.damage[i]))
                spots.append(HotSpot(float(s), float(self.angle[j]), float(self.damage[i, j])))
        return spots


def _group_maps(g, label: str) -> tuple[DamageMap, RainflowMatrix | None]:
    angle_key = "angle" if "angle" in g else "surface_angle"
    for key in ("arc_length", angle_key, "damage"):
        if key not in g:
            raise ValueError(f"damage file group {g.name!r} has no dataset {key!r}")
    dm = DamageMap(g["arc_length"][()], g[angle_key][()], g["damage"][()], label)
    rf = None
    if "rainflow" in g:
        r = g["rainflow"]
        rf = RainflowMatrix(r["range_edges"][()], r["mean_edges"][()], r["counts"][()], label=label)
    return dm, rf


def load_damage(path: str | os.PathLike) -> dict[str, tuple[DamageMap, RainflowMatrix | None]]:
    """Damage maps (and rainflow matrices when present) per cable from an HDF5 damage file; a
    file with the datasets at its root gives one entry named after the file."""
    import h5py

    path = Path(path)
    if not path.exists():
        raise FileNotFoundError(f"damage file {str(path)!r} does not exist")
    with h5py.File(path, "r") as f:
        if "cables" in f:
            return {n: _group_maps(g, f"{path.stem}: {n}") for n, g in f["cables"].items()}
        return {path.stem: _group_maps(f, path.stem)}
