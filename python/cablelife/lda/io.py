"""Damage files (HDF5, written atomically), readable without cablelife.

Layout (every dataset has a ``unit`` attribute)::

    /   attrs: format="cablelife-damage", format_version, cablelife_version, source,
               wohler_k, wohler_alpha (Pa^k), wohler_knee_range (Pa, −1: none),
               wohler_knee_kind, pseudo_damage, n_points, plane_step_deg, section_step,
               residue, hysteresis (Pa), stress_convention="ranges"
    /cables/<name>/section_index   (n_sec,)                 node indices
    /cables/<name>/arc_length      (n_sec,)          m
    /cables/<name>/angle           (n_pts,)          rad    surface angle γ from d1 towards d2
    /cables/<name>/plane           (n_planes,)       rad    plane angle φ from the cable axis
    /cables/<name>/damage_planes   (n_sec, n_pts, n_planes) 1
    /cables/<name>/damage          (n_sec, n_pts)    1      max over planes (the damage map)
    /cables/<name>/critical_plane  (n_sec, n_pts)    rad    plane of the maximum
    /cables/<name>/hot_spots/{arc_length, angle, plane, damage, section_index,
                              nearest_clip, clip_distance}  (largest first)
    /cables/<name>              attrs: outer_radius, inner_radius, poisson_ratio,
                                       from_measured, duration, n_steps,
                                       f_max, samples_per_period (−1: not checked)
    /cables/<name>/clips        attrs: clip name -> arc length (m)
    /cables/<name>/rainflow/{range_edges (R+1,) Pa, mean_edges (M+1,) Pa, counts (R, M) 1}
                                rainflow range–mean matrix of the most damaged series; attrs
                                section_index, arc_length (m), angle, plane (deg); absent
                                when the damage is zero
"""

from __future__ import annotations

import math
import os
from pathlib import Path

import h5py
import numpy as np

from cablelife.h5files import atomic_h5, open_h5, plain
from cablelife.lda.pipeline import CableDamage, DamageAnalysis
from cablelife.lda.rainflow import RainflowMatrix
from cablelife.lda.sampling import SamplingCheck
from cablelife.lda.stress import CircularSection
from cablelife.lda.wohler import WohlerCurve
from cablelife.resultcheck import check_damage_file, check_damage_values

FORMAT = "cablelife-damage"
FORMAT_VERSION = 1
N_HOT_SPOTS = 10


def _put(g: h5py.Group, name: str, data, unit: str) -> None:
    ds = g.create_dataset(name, data=np.asarray(data))
    ds.attrs["unit"] = unit


def save_damage(analysis: DamageAnalysis, path: str | os.PathLike) -> Path:
    """Write ``analysis`` to ``path`` atomically (a temporary file renamed into place)."""
    from cablelife import __version__

    path = Path(path)
    with atomic_h5(path) as f:
        f.attrs["format"] = FORMAT
        f.attrs["format_version"] = FORMAT_VERSION
        f.attrs["cablelife_version"] = __version__
        f.attrs["source"] = analysis.source
        f.attrs["mode"] = analysis.mode
        f.attrs["stress_convention"] = "ranges"
        for k, v in analysis.curve.as_attrs().items():
            f.attrs[k] = v
        for k, v in analysis.settings.items():
            f.attrs[k] = v
        root = f.create_group("cables")
        for name, c in analysis.cables.items():
            g = root.create_group(name)
            _put(g, "section_index", c.section_index, "1")
            _put(g, "arc_length", c.arc_length, "m")
            _put(g, "angle", c.angles, "rad")
            _put(g, "plane", c.planes, "rad")
            _put(g, "damage_planes", c.damage_planes, "1")
            _put(g, "damage", c.damage, "1")
            _put(g, "critical_plane", c.critical_plane, "rad")
            g.attrs["outer_radius"] = c.section.outer_radius
            g.attrs["inner_radius"] = c.section.inner_radius
            g.attrs["poisson_ratio"] = c.section.poisson_ratio
            g.attrs["from_measured"] = c.section.from_measured
            g.attrs["duration"] = c.duration
            g.attrs["n_steps"] = c.n_steps
            g.attrs["f_max"] = -1.0 if c.sampling is None else c.sampling.f_max
            g.attrs["samples_per_period"] = (
                -1.0 if c.sampling is None else min(c.sampling.samples_per_period, 1e300)
            )
            clips = g.create_group("clips")
            for cn, s in c.clips.items():
                clips.attrs[cn] = s
            if c.rainflow is not None:
                _put_rainflow(g.create_group("rainflow"), c.rainflow)
            spots = c.hot_spots(N_HOT_SPOTS)
            h = g.create_group("hot_spots")
            _put(h, "arc_length", [x.arc_length for x in spots], "m")
            _put(h, "angle", [x.angle for x in spots], "deg")
            _put(h, "plane", [x.plane for x in spots], "deg")
            _put(h, "damage", [x.damage for x in spots], "1")
            _put(h, "section_index", [x.section_index for x in spots], "1")
            _put(
                h,
                "nearest_clip",
                np.array([x.nearest_clip or "" for x in spots], dtype=h5py.string_dtype()),
                "1",
            )
            _put(
                h,
                "clip_distance",
                [math.nan if x.clip_distance is None else x.clip_distance for x in spots],
                "m",
            )
    return path


def _put_rainflow(g: h5py.Group, m: RainflowMatrix) -> None:
    _put(g, "range_edges", m.range_edges, m.unit)
    _put(g, "mean_edges", m.mean_edges, m.unit)
    _put(g, "counts", m.counts, "1")
    g.attrs["section_index"] = m.section_index
    g.attrs["arc_length"] = m.arc_length
    g.attrs["angle"] = m.angle
    g.attrs["plane"] = m.plane


def _get_rainflow(g: h5py.Group, cable: str) -> RainflowMatrix:
    a = {k: plain(v) for k, v in g.attrs.items()}
    return RainflowMatrix(
        g["range_edges"][()],
        g["mean_edges"][()],
        g["counts"][()],
        unit=str(plain(g["range_edges"].attrs.get("unit", "Pa"))),
        label=cable,
        section_index=int(a["section_index"]),
        arc_length=float(a["arc_length"]),
        angle=float(a["angle"]),
        plane=float(a["plane"]),
    )


def is_damage_file(path: str | os.PathLike) -> bool:
    try:
        with h5py.File(path, "r") as f:
            return f.attrs.get("format") == FORMAT
    except OSError:
        return False


def load_damage(path: str | os.PathLike) -> DamageAnalysis:
    """Read a damage file written by :func:`save_damage`."""
    with open_h5(path, FORMAT, "damage") as f:
        check_damage_file(f, path)  # shapes and sizes before reading
        a = {k: plain(v) for k, v in f.attrs.items()}
        curve = WohlerCurve.from_attrs(a)
        settings = {
            k: a[k] for k in ("n_points", "plane_step_deg", "section_step", "residue", "hysteresis")
        }
        cables = {}
        for name, g in f["cables"].items():
            ga = {k: plain(v) for k, v in g.attrs.items()}
            spp = float(ga["samples_per_period"])
            sampling = (
                None
                if spp < 0
                else SamplingCheck(
                    f_max=float(ga["f_max"]),
                    samples_per_period=spp,
                    sample_rate=math.nan,
                )
            )
            cables[name] = CableDamage(
                cable=name,
                section_index=g["section_index"][()],
                arc_length=g["arc_length"][()],
                angles=g["angle"][()],
                planes=g["plane"][()],
                damage_planes=g["damage_planes"][()],
                section=CircularSection(
                    outer_radius=float(ga["outer_radius"]),
                    inner_radius=float(ga["inner_radius"]),
                    poisson_ratio=float(ga["poisson_ratio"]),
                    from_measured=bool(ga["from_measured"]),
                ),
                clips={k: float(v) for k, v in g["clips"].attrs.items()},
                duration=float(ga["duration"]),
                n_steps=int(ga["n_steps"]),
                sampling=sampling,
                rainflow=_get_rainflow(g["rainflow"], name) if "rainflow" in g else None,
            )
    analysis = DamageAnalysis(
        cables=cables,
        curve=curve,
        settings=settings,
        source=str(a["source"]),
        mode=str(a.get("mode", "")),
    )
    check_damage_values(analysis, path)
    return analysis
