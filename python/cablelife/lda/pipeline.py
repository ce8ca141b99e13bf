"""The LDA pipeline: section loads → surface stresses → critical planes → rainflow + Miner.

For every analysed cross section (node) the six section loads (T, 6) map to all
comparison-stress series of its surface points and planes through one weight matrix W
(n_points · n_planes, 6) (:mod:`cablelife.lda.planes`). The Rust kernel evaluates W @ loadsᵀ
row by row while counting, so the series are never stored; sections are processed in chunks
(progress callback between chunks, Ctrl-C works).
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from cablelife import interrupt
from cablelife.lda.damage import damage_combined, equivalent_range_from_damage
from cablelife.lda.planes import DEFAULT_PLANE_STEP_DEG, plane_angles, plane_weights
from cablelife.lda.rainflow import RainflowMatrix, check_residue, rainflow_cycles
from cablelife.lda.sampling import SamplingCheck, check_sampling
from cablelife.lda.stations import section_loads
from cablelife.lda.stress import CircularSection, surface_angles
from cablelife.lda.wohler import WohlerCurve, pseudo_damage_curve
from cablelife.results import CableResult, Result, load_result

DEFAULT_POINTS = 16
#: Range and mean bins of the stored rainflow matrix.
RAINFLOW_BINS = 32


@dataclass(frozen=True)
class HotSpot:
    """A local maximum of the damage along the cable."""

    cable: str
    arc_length: float  # m
    angle: float  # surface angle γ, degrees from d1 towards d2
    plane: float  # critical plane angle φ, degrees from the cable axis
    damage: float
    section_index: int  # node index
    nearest_clip: str | None
    clip_distance: float | None  # m, |s − s_clip|

    def describe(self) -> str:
        clip = (
            f", {self.clip_distance * 1000:.0f} mm from clip {self.nearest_clip!r}"
            if self.nearest_clip is not None
            else ""
        )
        return (
            f"{self.cable}: D = {self.damage:.4g} at s = {self.arc_length:.4g} m, "
            f"γ = {self.angle:.4g}°, plane φ = {self.plane:.4g}°{clip}"
        )


@dataclass
class CableDamage:
    """Damage of one cable: per section × surface point × plane."""

    cable: str
    section_index: np.ndarray  # (n_sec,) node indices
    arc_length: np.ndarray  # (n_sec,) m
    angles: np.ndarray  # (n_pts,) rad
    planes: np.ndarray  # (n_planes,) rad
    damage_planes: np.ndarray  # (n_sec, n_pts, n_planes)
    section: CircularSection
    clips: dict[str, float] = field(default_factory=dict)  # name -> arc length
    duration: float = 0.0  # s, analysed time span
    n_steps: int = 0
    sampling: SamplingCheck | None = None
    rainflow: RainflowMatrix | None = None  # of the most damaged series (None: no damage)

    @property
    def damage(self) -> np.ndarray:
        """Damage map (n_sec, n_pts): maximum over the planes."""
        return self.damage_planes.max(axis=2)

    @property
    def critical_plane(self) -> np.ndarray:
        """Plane angle φ (rad) of the maximum, (n_sec, n_pts)."""
        return self.planes[self.damage_planes.argmax(axis=2)]

    @property
    def max_damage(self) -> float:
        return float(self.damage_planes.max()) if self.damage_planes.size else 0.0

    def hot_spots(self, n: int = 5) -> list[HotSpot]:
        """Up to ``n`` local maxima (> 0) of the section damage along s, largest first."""
        dmap = self.damage
        if dmap.size == 0:
            return []
        prof = dmap.max(axis=1)
        left = np.concatenate([[-np.inf], prof[:-1]])
        right = np.concatenate([prof[1:], [-np.inf]])
        peaks = np.flatnonzero((prof >= left) & (prof > right) & (prof > 0))
        peaks = peaks[np.argsort(-prof[peaks], kind="stable")][:n]
        spots = []
        for i in peaks:
            p = int(dmap[i].argmax())
            q = int(self.damage_planes[i, p].argmax())
            s = float(self.arc_length[i])
            clip, dist = None, None
            if self.clips:
                clip, s_clip = min(self.clips.items(), key=lambda kv: abs(kv[1] - s))
                dist = abs(s_clip - s)
            spots.append(
                HotSpot(
                    cable=self.cable,
                    arc_length=s,
                    angle=math.degrees(self.angles[p]),
                    plane=math.degrees(self.planes[q]),
                    damage=float(dmap[i, p]),
                    section_index=int(self.section_index[i]),
                    nearest_clip=clip,
                    clip_distance=dist,
                )
            )
        return spots


@dataclass
class DamageAnalysis:
    """Result of :func:`analyse`: one :class:`CableDamage` per cable plus the settings."""

    cables: dict[str, CableDamage]
    curve: WohlerCurve
    settings: dict
    source: str = ""
    mode: str = ""  # the analysis mode of the run (static, quasistatic, dynamic; "" unknown)

    @property
    def max_damage(self) -> float:
        return max((c.max_damage for c in self.cables.values()), default=0.0)

    @property
    def life(self) -> float:
        """Repeats of the analysed history to failure, 1/max D (meaningful for a measured curve)."""
        d = self.max_damage
        return math.inf if d == 0 else 1.0 / d

    def hot_spots(self, n: int = 5) -> list[HotSpot]:
        spots = [h for c in self.cables.values() for h in c.hot_spots(n)]
        return sorted(spots, key=lambda h: -h.damage)[:n]

    def equivalent_range(self, n_ref: float = 1e6) -> dict[str, np.ndarray]:
        """Damage-equivalent stress range (Pa) per cable, (n_sec, n_pts) on the critical plane,
        for ``n_ref`` cycles (curve without knee only)."""
        return {
            name: equivalent_range_from_damage(c.damage, self.curve, n_ref)
            for name, c in self.cables.items()
        }

    def save(self, path: str | os.PathLike) -> Path:
        from cablelife.lda.io import save_damage

        return save_damage(self, path)

    def summary(self, n_hot_spots: int = 3) -> str:
        kind = "pseudo-damage" if self.curve.pseudo else "damage"
        lines = [
            f"{kind}: max {self.max_damage:.4g}"
            + ("" if self.curve.pseudo else f", life {self.life:.4g} repeats of the history"),
            f"Wöhler curve (ranges): k = {self.curve.k:g}, alpha = {self.curve.alpha:.4g} Pa^k"
            + (
                ""
                if self.curve.knee_range is None
                else f", knee {self.curve.knee_range:.4g} Pa ({self.curve.knee_kind})"
            ),
        ]
        for c in self.cables.values():
            if c.section.from_measured:
                lines.append(
                    f"{c.cable}: given by measured stiffnesses; stresses are those of the "
                    f"equivalent homogeneous circle of radius {c.section.outer_radius:g} m "
                    f"(ν = {c.section.poisson_ratio:.3g})"
                )
            if c.sampling is not None and not c.sampling.ok:
                lines.append(
                    f"{c.cable}: only {c.sampling.samples_per_period:.1f} samples per period of "
                    f"{c.sampling.f_max:.3g} Hz: damage is undercounted"
                )
        lines += ["hot spots:"] + [f"  {h.describe()}" for h in self.hot_spots(n_hot_spots)]
        return "\n".join(lines)


def _chunk_sections(n_series: int, n_steps: int, target: int = 4_000_000) -> int:
    """Sections per kernel call: about ``target`` samples of series work per call."""
    return max(1, target // max(1, n_series * n_steps))


def analyse_cable(
    cable: CableResult,
    *,
    curve: WohlerCurve | None = None,
    section: CircularSection | None = None,
    n_points: int = DEFAULT_POINTS,
    plane_step_deg: float = DEFAULT_PLANE_STEP_DEG,
    section_step: int = 1,
    sections=None,
    residue: str = "half",
    hysteresis: float = 0.0,
    threads: int | None = None,
    progress: Callable[[int, int], None] | None = None,
    sampling_check: bool = True,
) -> CableDamage:
    """Damage of one cable of a result (see :func:`analyse` for the parameters)."""
    curve = curve or pseudo_damage_curve()
    check_residue(residue)
    section = section or CircularSection.from_attrs(cable.section)
    angles = surface_angles(n_points)
    planes = plane_angles(plane_step_deg)
    weights = plane_weights(section, angles, planes)
    idx, s, loads = section_loads(cable, section_step, sections)
    n_sec, n_steps = loads.shape[0], loads.shape[1]
    if n_steps == 0:
        raise ValueError(f"cable {cable.name!r} has no time steps")
    if not np.all(np.isfinite(loads)):
        bad = np.argwhere(~np.isfinite(loads))[0]
        raise ValueError(
            f"cable {cable.name!r}: non-finite section load at node {idx[bad[0]]}, step "
            f"{bad[1]}, channel {'F1 F2 F3 M1 M2 M3'.split()[bad[2]]}"
        )
    sampling = (
        check_sampling(loads, cable.time, section, label=f"cable {cable.name!r}")
        if sampling_check
        else None
    )
    out = np.empty((n_sec, weights.shape[0]))
    chunk = _chunk_sections(weights.shape[0], n_steps)
    for start in range(0, n_sec, chunk):
        interrupt.check()  # Ctrl-C seen by another thread (cablelife demo)
        stop = min(n_sec, start + chunk)
        out[start:stop] = damage_combined(
            loads[start:stop],
            weights,
            curve,
            residue=residue,
            hysteresis=hysteresis,
            threads=threads,
        )
        if progress is not None:
            progress(stop, n_sec)
    time = np.asarray(cable.time, float)
    rainflow = None
    if out.size and out.max() > 0:
        i, row = np.unravel_index(int(out.argmax()), out.shape)
        p, q = divmod(int(row), planes.size)
        series = weights[row] @ loads[i].T  # the critical comparison-stress series
        rainflow = RainflowMatrix.of_cycles(
            rainflow_cycles(series, residue=residue, hysteresis=hysteresis),
            RAINFLOW_BINS,
            unit="Pa",
            label=cable.name,
            section_index=int(idx[i]),
            arc_length=float(s[i]),
            angle=math.degrees(angles[p]),
            plane=math.degrees(planes[q]),
        )
    return CableDamage(
        cable=cable.name,
        section_index=idx,
        arc_length=s,
        angles=angles,
        planes=planes,
        damage_planes=out.reshape(n_sec, angles.size, planes.size),
        section=section,
        clips={name: float(c.s) for name, c in cable.clips.items()},
        duration=float(time[-1] - time[0]) if time.size else 0.0,
        n_steps=int(n_steps),
        sampling=sampling,
        rainflow=rainflow,
    )


def analyse(
    result: Result | str | os.PathLike,
    *,
    cables: list[str] | None = None,
    curve: WohlerCurve | None = None,
    n_points: int = DEFAULT_POINTS,
    plane_step_deg: float = DEFAULT_PLANE_STEP_DEG,
    section_step: int = 1,
    sections=None,
    residue: str = "half",
    hysteresis: float = 0.0,
    threads: int | None = None,
    progress: Callable[[str, int, int], None] | None = None,
    sampling_check: bool = True,
) -> DamageAnalysis:
    """Comparative load data analysis of a result (object or HDF5 path).

    - ``curve``: Wöhler curve in ranges; default :func:`pseudo_damage_curve` (k = 5).
    - ``n_points``: surface points per section (angles γ = 2πi/n); ``plane_step_deg``:
      critical-plane step (180 must be a multiple).
    - ``section_step``: analyse every k-th node (plus the last); ``sections``: explicit nodes.
    - ``residue``: "half" (ASTM), "discard", "full", "repeated"; ``hysteresis``: gate in Pa.
    - ``threads``: kernel threads (None: all cores); ``progress(cable, done, total)``.
    - ``sampling_check``: warn (SamplingWarning) when the output step is too coarse.
    """
    source = ""
    if not isinstance(result, Result):
        source = str(result)
        result = load_result(result)
    names = list(result.cables) if cables is None else list(cables)
    unknown = [n for n in names if n not in result.cables]
    if unknown:
        raise ValueError(f"cables {unknown} are not in the result; it has {list(result.cables)}")
    curve = curve or pseudo_damage_curve()
    out = {}
    for name in names:
        cb = None if progress is None else (lambda d, t, _n=name: progress(_n, d, t))
        out[name] = analyse_cable(
            result.cables[name],
            curve=curve,
            n_points=n_points,
            plane_step_deg=plane_step_deg,
            section_step=section_step,
            sections=sections,
            residue=residue,
            hysteresis=hysteresis,
            threads=threads,
            progress=cb,
            sampling_check=sampling_check,
        )
    settings = {
        "n_points": int(n_points),
        "plane_step_deg": float(plane_step_deg),
        "section_step": int(section_step),
        "residue": residue,
        "hysteresis": float(hysteresis),
    }
    return DamageAnalysis(
        cables=out, curve=curve, settings=settings, source=source, mode=result.mode
    )


def default_damage_path(result_path: str | os.PathLike) -> Path:
    """``RESULT.damage.h5`` next to ``RESULT.h5``."""
    p = Path(result_path)
    return p.with_name(p.stem + ".damage.h5")
