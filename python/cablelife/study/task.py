"""One variant from scene to summary: simulate → LDA → motion volume → summary row.

This is what a Dask worker runs. Its files go to ``<out>/variants/<name>/``: ``scene.toml``,
``result.h5``, ``damage.h5``, ``summary.json``. ``summary.json`` is written last (atomically)
and marks the variant finished; a failed variant writes ``error.json`` instead, keeping the
partial result, and is computed again on the next run.
"""

from __future__ import annotations

import json
import math
import time
import traceback
import warnings
from collections.abc import Callable
from pathlib import Path

import numpy as np
import tomli_w

from cablelife.atomic import write_text_atomic
from cablelife.lda.settings import LdaSettings
from cablelife.study.spec import VolumeSettings
from cablelife.study.variants import Variant

SUMMARY = "summary.json"
ERROR = "error.json"


def variant_dir(out_dir: str | Path, name: str) -> Path:
    return Path(out_dir) / "variants" / name


def task_settings(lda: LdaSettings, volume: VolumeSettings, threads: int) -> dict:
    """The settings that decide a variant's numbers (part of its fingerprint)."""
    return {"lda": lda.model_dump(), "volume": volume.model_dump(), "threads": threads}


def finished_row(out_dir: str | Path, variant: Variant, settings: dict) -> dict | None:
    """The stored summary row if the variant finished with these very inputs, else None."""
    path = variant_dir(out_dir, variant.name) / SUMMARY
    try:
        row = json.loads(path.read_text())
    except (OSError, ValueError):
        return None
    return row if row.get("fingerprint") == variant.fingerprint(settings) else None


def _volume_steps(n_steps: int, max_steps: int) -> slice:
    return slice(None, None, max(1, math.ceil(n_steps / max_steps)))


def _loads_row(result) -> dict:
    from cablelife.summary import cable_summary

    row: dict = {}
    for name, cable in result.cables.items():
        s = cable_summary(cable)
        prefix = "" if len(result.cables) == 1 else f"{name}."
        row[prefix + "max_tension_N"] = s["max_tension"]
        row[prefix + "max_shear_N"] = s["max_shear"]
        row[prefix + "max_bending_Nm"] = s["max_bending"]
        row[prefix + "max_torsion_Nm"] = s["max_torsion"]
        row[prefix + "min_bend_radius_m"] = s["min_bend_radius"]
        row[prefix + "max_clip_force_N"] = max(
            (c["max_force"] for c in s["clips"].values()), default=0.0
        )
        row[prefix + "newton_iterations_mean"] = s["newton_iterations_mean"]
    return row


def run_variant(
    variant: Variant,
    out_dir: str | Path,
    lda: LdaSettings,
    volume: VolumeSettings,
    threads: int = 1,
    on_stage: Callable[[str], None] | None = None,
) -> dict:
    """Runs one variant and returns its summary row (also stored in ``summary.json``).

    Never raises for a failing variant: the row has ``status = "failed"`` and ``error``.
    ``on_stage(name)`` is told when a stage (simulation, lda, motion volume) begins.
    """
    from cablelife.lda.pipeline import analyse
    from cablelife.simulate import SimulationError, simulate

    settings = task_settings(lda, volume, threads)
    done = finished_row(out_dir, variant, settings)
    if done is not None:
        return done | {"skipped": True}
    folder = variant_dir(out_dir, variant.name)
    folder.mkdir(parents=True, exist_ok=True)
    (folder / ERROR).unlink(missing_ok=True)
    row = variant.row()
    times: dict[str, float] = {}
    stage = "scene"

    def begin(name: str) -> str:
        if on_stage is not None:
            on_stage(name)
        return name

    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            write_text_atomic(folder / "scene.toml", tomli_w.dumps(variant.scene))
            scene = variant.validated()
            stage = begin("simulation")
            t0 = time.perf_counter()
            try:
                result = simulate(scene)
            except SimulationError as err:
                err.result.save(folder / "result.h5")  # keep what was computed
                raise
            result.save(folder / "result.h5")
            times["simulation_s"] = time.perf_counter() - t0
            row.update(_loads_row(result))
            stage = begin("lda")
            t0 = time.perf_counter()
            analysis = analyse(result, threads=threads, **lda.analyse_kwargs())
            analysis.source = str(folder / "result.h5")
            analysis.save(folder / "damage.h5")
            times["lda_s"] = time.perf_counter() - t0
            row["max_damage"] = analysis.max_damage
            row["pseudo_damage"] = analysis.curve.pseudo
            spots = analysis.hot_spots(1)
            if spots:
                h = spots[0]
                row.update(
                    hot_spot_cable=h.cable,
                    hot_spot_s_m=h.arc_length,
                    hot_spot_angle_deg=h.angle,
                    hot_spot_clip=h.nearest_clip or "",
                    hot_spot_clip_distance_m=h.clip_distance
                    if h.clip_distance is not None
                    else float("nan"),
                )
            if volume.voxel > 0:
                from cablelife.volume import motion_volume

                stage = begin("motion volume")
                t0 = time.perf_counter()
                n = next(iter(result.cables.values())).n_steps
                mv = motion_volume(result, volume.voxel, steps=_volume_steps(n, volume.max_steps))
                row["motion_volume_l"] = mv.litres
                times["volume_s"] = time.perf_counter() - t0
        row["warnings"] = sorted({str(w.message) for w in caught})
    except Exception as err:  # noqa: BLE001 — a failing variant must not stop the study
        row.update(status="failed", stage=stage, error=f"{type(err).__name__}: {err}")
        row.update(times)
        detail = row | {"traceback": traceback.format_exc()}
        write_text_atomic(folder / ERROR, json.dumps(_jsonable(detail), indent=1))
        return _jsonable(row)
    row.update(times, status="ok", error="", fingerprint=variant.fingerprint(settings))
    row = _jsonable(row)
    write_text_atomic(folder / SUMMARY, json.dumps(row, indent=1))
    return row


def _jsonable(row: dict) -> dict:
    out = {}
    for k, v in row.items():
        if isinstance(v, np.generic):
            v = v.item()
        out[k] = v
    return out
