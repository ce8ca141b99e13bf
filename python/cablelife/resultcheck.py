"""Validation of result and damage files before they are read (every reader: lda, volume,
paraview, compare, report): the datasets exist, are numeric and have consistent shapes that
agree with the stored scene, their size is bounded, and their values are finite.

A truncated, forged or foreign file gets a :class:`ResultFileError` naming the file, the
dataset, the shape found and the shape expected, instead of an HDF5 traceback or an attempt to
allocate what a forged header declares.
"""

from __future__ import annotations

import math
import tomllib
import warnings

import h5py
import numpy as np

from cablelife import _core
from cablelife.limits import MAX_RUN_BYTES, MIN_SEGMENTS, human_bytes


class ResultFileError(ValueError):
    """A result or damage file that cannot be used; the message names the file and dataset."""


class PartialResultWarning(UserWarning):
    """A result of a run that stopped early (``complete = False``)."""


# Largest file a reader loads into memory (the run-size limit of a simulation, plus room).
MAX_READ_BYTES = 2 * MAX_RUN_BYTES


def _dataset(group: h5py.Group, name: str, where: str) -> h5py.Dataset:
    obj = group.get(name)
    if obj is None:
        raise ResultFileError(f"{where}: dataset {name!r} is missing")
    if not isinstance(obj, h5py.Dataset):
        raise ResultFileError(f"{where}: {name!r} is not a dataset")
    if obj.dtype.kind not in "fiu":
        raise ResultFileError(
            f"{where}: dataset {name!r} holds {obj.dtype} values; expected numbers"
        )
    return obj


def _shape(ds: h5py.Dataset, expected: tuple, where: str, dims: str) -> None:
    """``expected`` has ints, or None for a free size."""
    found = ds.shape
    ok = len(found) == len(expected) and all(
        e is None or f == e for f, e in zip(found, expected, strict=True)
    )
    if not ok:
        shown = "(" + ", ".join("?" if e is None else str(e) for e in expected) + ")"
        raise ResultFileError(
            f"{where}: dataset {ds.name.rsplit('/', 1)[-1]!r} has shape {found}; expected "
            f"{shown} {dims}"
        )


def _group(parent: h5py.Group, name: str, where: str) -> h5py.Group:
    obj = parent.get(name)
    if not isinstance(obj, h5py.Group):
        raise ResultFileError(f"{where}: group {name!r} is missing")
    return obj


def _stored_scene(f: h5py.File, where: str) -> dict:
    text = f.attrs.get("scene_toml", "")
    if isinstance(text, bytes):
        text = text.decode("utf-8", "replace")
    try:
        return tomllib.loads(str(text)) if text else {}
    except (tomllib.TOMLDecodeError, RecursionError):
        raise ResultFileError(f"{where}: attribute 'scene_toml' is not a valid scene") from None


def _expected_steps(scene: dict, mode: str) -> int | None:
    """The largest number of saved steps the stored scene allows (None: unknown)."""
    sim = scene.get("simulation", {}) if isinstance(scene.get("simulation"), dict) else {}
    if mode == "static":
        return 1
    try:
        duration = float(sim["duration"])
        step = float(sim.get("output_step") or sim.get("time_step", 1e-3))
        return int(math.floor(duration / step + 1e-9)) + 1
    except (KeyError, TypeError, ValueError, ZeroDivisionError, OverflowError):
        return None


def _stored_segments(cable: dict) -> int | None:
    """The segments a stored cable asked for (segments, max_segment_length or the default)."""
    seg = cable.get("segments")
    if isinstance(seg, int) and not isinstance(seg, bool):
        return seg
    try:
        if cable.get("max_segment_length") is not None:
            ratio = float(cable["length"]) / float(cable["max_segment_length"])
            return max(MIN_SEGMENTS, math.ceil(ratio))
    except (KeyError, TypeError, ValueError, ZeroDivisionError, OverflowError):
        return None
    return 50


def check_result_file(f: h5py.File, path) -> None:
    """Checks an open result file (format attribute already checked) before it is read."""
    where = repr(str(path))
    mode = f.attrs.get("mode")
    mode = mode.decode() if isinstance(mode, bytes) else mode
    if mode not in ("static", "quasistatic", "dynamic"):
        raise ResultFileError(
            f"{where}: attribute 'mode' is {mode!r}; expected 'static', 'quasistatic' or 'dynamic'"
        )
    scene = _stored_scene(f, where)
    cables = _group(f, "cables", where)
    if len(cables) == 0:
        raise ResultFileError(f"{where}: group 'cables' is empty")
    stored = {c.get("name"): c for c in scene.get("cables", []) if isinstance(c, dict)}
    max_steps = _expected_steps(scene, mode)
    total = 0.0
    for name, g in cables.items():
        w = f"{where}, cable {name!r}"
        if not isinstance(g, h5py.Group):
            raise ResultFileError(f"{w}: not a group")
        if stored and name not in stored:
            raise ResultFileError(
                f"{w}: not a cable of the stored scene (it has {', '.join(map(repr, stored))})"
            )
        time = _dataset(g, "time", w)
        arc = _dataset(g, "arc_length", w)
        _shape(time, (None,), w, "(steps,)")
        _shape(arc, (None,), w, "(nodes,)")
        n_t, n_nodes = time.shape[0], arc.shape[0]
        if n_nodes < 2:
            raise ResultFileError(f"{w}: dataset 'arc_length' has {n_nodes} node(s); expected ≥ 2")
        if max_steps is not None and n_t > max_steps + 1:
            raise ResultFileError(
                f"{w}: dataset 'time' has {n_t} steps; the stored scene ({mode}) gives at most "
                f"{max_steps}"
            )
        spec = stored.get(name, {})
        seg = _stored_segments(spec) if isinstance(spec, dict) and spec else None
        clips = spec.get("clips", []) if isinstance(spec, dict) else []
        loads = spec.get("loads", []) if isinstance(spec, dict) else []
        if isinstance(seg, int) and not isinstance(seg, bool):
            # the mesh adds at most a node at each clip end and load
            most = seg + 2 * len(clips) + len(loads) + 2
            if n_nodes - 1 > most:
                raise ResultFileError(
                    f"{w}: dataset 'arc_length' has {n_nodes} nodes; the stored scene's "
                    f"{seg} segments give at most {most + 1}"
                )
        n = n_nodes - 1
        for key, shape, dims in (
            ("positions", (n_t, n + 1, 3), "(steps, nodes, 3)"),
            ("quaternions", (n_t, n, 4), "(steps, edges, 4)"),
            ("forces", (n_t, n, 3), "(steps, edges, 3)"),
            ("moments", (n_t, n + 1, 3), "(steps, nodes, 3)"),
        ):
            _shape(_dataset(g, key, w), shape, w, dims)
        for key in ("kinetic_energy", "elastic_energy", "dissipated_energy", "load_potential"):
            if key in g:
                _shape(_dataset(g, key, w), (n_t,), w, "(steps,)")
        clip_group = _group(g, "clips", w)
        clip_names = [c.get("name") for c in clips if isinstance(c, dict)]
        if clip_names and sorted(clip_group) != sorted(clip_names):
            raise ResultFileError(
                f"{w}: clips {sorted(clip_group)} differ from the stored scene's {clip_names}"
            )
        for cn, cg in clip_group.items():
            cw = f"{w}, clip {cn!r}"
            if not isinstance(cg, h5py.Group) or "s" not in cg.attrs:
                raise ResultFileError(f"{cw}: not a clip group with an 's' attribute")
            for key in ("reaction_force", "reaction_moment"):
                _shape(_dataset(cg, key, cw), (n_t, 3), cw, "(steps, 3)")
        _group(g, "section", w)
        _group(g, "solver", w)
        total += 8.0 * n_t * (13 * n + 6 + 6 * len(clip_group))
    if total > MAX_READ_BYTES:
        raise ResultFileError(
            f"{where}: its datasets hold {human_bytes(total)}; allowed: at most "
            f"{human_bytes(MAX_READ_BYTES)} (the run-size limit of a simulation)"
        )


def check_finite(a, where: str, cable: str, key: str) -> None:
    """Rejects non-finite values (NaN, inf) in one dataset, naming file, cable, dataset, index."""
    a = np.asarray(a)
    if a.size and a.dtype.kind == "f" and not np.all(np.isfinite(a)):
        idx = tuple(int(i) for i in np.argwhere(~np.isfinite(a))[0])
        raise ResultFileError(
            f"{where}, cable {cable!r}: dataset {key!r} has the non-finite value "
            f"{a[idx]} at index {idx}; a result must hold finite numbers"
        )


def check_result_values(result, path) -> None:
    """Rejects non-finite values (NaN, inf) in the arrays of a loaded result that are in memory;
    the histories read on first use (``results.Deferred``) are checked when they are read."""
    where = repr(str(path))
    for name, c in result.cables.items():
        arrays = {"time": c.time, "arc_length": c.arc_length, **c.energies}
        for key in ("positions", "quaternions", "forces", "moments"):
            arrays[key] = c.__dict__.get("_" + key)
        for cn, clip in c.clips.items():
            arrays[f"clips/{cn}/reaction_force"] = clip.__dict__.get("_force")
            arrays[f"clips/{cn}/reaction_moment"] = clip.__dict__.get("_moment")
        for key, a in arrays.items():
            if isinstance(a, np.ndarray):
                check_finite(a, where, name, key)


def warn_partial(result, path) -> None:
    """A warning when the result is of a run that stopped early."""
    if not getattr(result, "complete", True):
        message = result.message or ""
        # "interrupted: …" says itself what is missing (the clearance); else the run stopped
        why = (
            message
            if message.startswith(f"{_core.INTERRUPTED}: ")
            else "the run stopped early" + (f": {message}" if message else "")
        )
        warnings.warn(
            f"{str(path)!r} is a partial result ({why}); the analysis covers only the saved steps",
            PartialResultWarning,
            stacklevel=3,
        )


def check_damage_file(f: h5py.File, path) -> None:
    """Checks an open damage file (format attribute already checked) before it is read."""
    where = repr(str(path))
    missing = [
        k
        for k in (
            "source",
            "n_points",
            "plane_step_deg",
            "section_step",
            "residue",
            "hysteresis",
            "wohler_k",
        )
        if k not in f.attrs
    ]
    if missing:
        raise ResultFileError(f"{where}: attributes {missing} are missing")
    cables = _group(f, "cables", where)
    if len(cables) == 0:
        raise ResultFileError(f"{where}: group 'cables' is empty")
    total = 0.0
    for name, g in cables.items():
        w = f"{where}, cable {name!r}"
        if not isinstance(g, h5py.Group):
            raise ResultFileError(f"{w}: not a group")
        idx = _dataset(g, "section_index", w)
        _shape(idx, (None,), w, "(sections,)")
        n_sec = idx.shape[0]
        ang = _dataset(g, "angle", w)
        pl = _dataset(g, "plane", w)
        _shape(ang, (None,), w, "(points,)")
        _shape(pl, (None,), w, "(planes,)")
        n_pts, n_pl = ang.shape[0], pl.shape[0]
        _shape(_dataset(g, "arc_length", w), (n_sec,), w, "(sections,)")
        _shape(
            _dataset(g, "damage_planes", w), (n_sec, n_pts, n_pl), w, "(sections, points, planes)"
        )
        for key in ("damage", "critical_plane"):
            if key in g:
                _shape(_dataset(g, key, w), (n_sec, n_pts), w, "(sections, points)")
        for key in (
            "outer_radius",
            "inner_radius",
            "poisson_ratio",
            "from_measured",
            "duration",
            "n_steps",
            "f_max",
            "samples_per_period",
        ):
            if key not in g.attrs:
                raise ResultFileError(f"{w}: attribute {key!r} is missing")
        _group(g, "clips", w)
        total += 8.0 * n_sec * n_pts * (n_pl + 2)
    if total > MAX_READ_BYTES:
        raise ResultFileError(
            f"{where}: its datasets hold {human_bytes(total)}; allowed: at most "
            f"{human_bytes(MAX_READ_BYTES)}"
        )


def check_damage_values(analysis, path) -> None:
    """Rejects negative or non-finite damage in a loaded damage file."""
    where = repr(str(path))
    for name, c in analysis.cables.items():
        for key, a in (
            ("arc_length", c.arc_length),
            ("angle", c.angles),
            ("plane", c.planes),
            ("damage_planes", c.damage_planes),
        ):
            a = np.asarray(a, dtype=float)
            if a.size and not np.all(np.isfinite(a)):
                i = tuple(int(x) for x in np.argwhere(~np.isfinite(a))[0])
                raise ResultFileError(
                    f"{where}, cable {name!r}: dataset {key!r} has the non-finite value {a[i]} "
                    f"at index {i}; a damage file must hold finite numbers"
                )
        if np.any(np.asarray(c.damage_planes) < 0):
            raise ResultFileError(
                f"{where}, cable {name!r}: dataset 'damage_planes' has negative damage; "
                "allowed: damage >= 0"
            )
