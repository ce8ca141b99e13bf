"""The application example end to end (paper §4): two mounting variants of a cable, the same
random engine excitation, dynamic and quasistatic runs, the fatigue analysis, the ranking and
the HTML report — ``cablelife demo``."""

from __future__ import annotations

import copy
import dataclasses
import math
import os
import time
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path

import cablelife
from cablelife import interrupt
from cablelife.study.spec import StudyError, load_study
from cablelife.study.task import run_variant, variant_dir
from cablelife.study.variants import Variant, expand

MODES = ("dynamic", "quasistatic")


def example_dir() -> Path:
    """``examples/clip-variants`` of the source checkout cablelife runs from."""
    here = Path(cablelife.__file__).resolve().parents[2] / "examples" / "clip-variants"
    if not (here / "variants.toml").is_file():
        raise StudyError(
            f"the demo's example folder {str(here)!r} is missing (cablelife is not run from its "
            "source checkout); give the folder with --example"
        )
    return here


def reseed(scene: dict, seed: int) -> dict:
    """A copy of ``scene`` whose random (PSD) signals use seeds seed, seed + 1, … in order."""
    scene = copy.deepcopy(scene)
    k = seed
    for body in scene.get("bodies", []):
        for m in body.get("motion", []):
            if m["signal"].get("type") == "psd":
                m["signal"]["seed"] = k
                k += 1
    return scene


@dataclass
class DemoOutcome:
    """Everything the demo produced."""

    out_dir: Path
    rows: dict[str, dict]  # run label -> summary row
    comparison: object  # cablelife.lda.compare.Comparison of the dynamic runs
    quasistatic: object | None  # the same for the quasistatic runs
    report: Path | None
    stage_times: dict[str, float] = field(default_factory=dict)
    #: run label -> :func:`cablelife.surroundings.summary.clearance_summary` of its cable
    #: (dynamic runs first; empty without geometry in the scene)
    clearances: dict[str, dict] = field(default_factory=dict)

    @property
    def preferred(self) -> str:
        return self.comparison.best.label


def demo_runs(
    example: Path | None = None,
    *,
    seed: int | None = None,
    duration: float | None = None,
    quasistatic: bool = True,
) -> list[Variant]:
    """The runs of the demo: every variant of ``variants.toml`` dynamically and (optionally)
    quasistatically, labelled ``<variant>-<mode>``."""
    study, study_dir = load_study((example or example_dir()) / "variants.toml")
    return _runs(study, study_dir, seed, duration, quasistatic)


def _runs(
    study, study_dir: Path, seed, duration, quasistatic, allow_outside_files: bool = False
) -> list[Variant]:
    if duration is not None and not (math.isfinite(duration) and duration > 0):
        raise StudyError(f"duration = {duration!r}: allowed: a finite number of seconds > 0")
    runs = []
    for v in expand(study, study_dir, allow_outside_files):
        for mode in MODES if quasistatic else MODES[:1]:
            scene = reseed(v.scene, seed) if seed is not None else copy.deepcopy(v.scene)
            scene["simulation"]["mode"] = mode
            if duration is not None:
                scene["simulation"]["duration"] = duration
            runs.append(dataclasses.replace(v, name=f"{v.name}-{mode}", scene=scene, mode=mode))
    return runs


def run_demo(
    out_dir: str | Path = "out/demo",
    *,
    example: Path | None = None,
    seed: int | None = None,
    duration: float | None = None,
    quasistatic: bool = True,
    report: bool = True,
    report_frames: int = 24,
    workers: int | None = None,
    on_stage: Callable[[str, str], None] | None = None,
    allow_outside_files: bool = False,
) -> DemoOutcome:
    """Runs the demo into ``out_dir``: simulations and LDA of all runs in parallel (one thread
    each), the comparison, and the report. ``on_stage(run, stage)`` follows the progress."""
    from cablelife.lda.compare import compare

    study, study_dir = load_study((example or example_dir()) / "variants.toml")
    runs = _runs(study, study_dir, seed, duration, quasistatic, allow_outside_files)
    out = Path(out_dir)
    times: dict[str, float] = {}
    t0 = time.perf_counter()
    n = workers or min(len(runs), os.cpu_count() or 1)

    # the report computes the motion volumes it draws: not twice
    volume = study.volume.model_copy(update={"voxel": 0.0}) if report else study.volume

    def one(v: Variant) -> dict:
        cb = None if on_stage is None else (lambda stage, _n=v.name: on_stage(_n, stage))
        row = run_variant(v, out, study.lda, volume, 1, on_stage=cb)
        if on_stage is not None:
            on_stage(v.name, row["status"])
        return row

    with ThreadPoolExecutor(max_workers=n) as pool:
        futures = [pool.submit(one, v) for v in runs]

        def stop() -> None:  # Ctrl-C: the runs keep what they computed (partial result.h5)
            interrupt.request_stop()
            for f in futures:
                f.cancel()

        if interrupt.wait_stopping(futures, stop, stop_on_error=False):
            interrupt.reset()  # every run has ended
            raise KeyboardInterrupt
        rows = {v.name: f.result() for v, f in zip(runs, futures, strict=True)}
    times["simulate + LDA + volume (all runs)"] = time.perf_counter() - t0
    for name, row in rows.items():
        for key in ("simulation_s", "lda_s", "volume_s"):
            if key in row:
                times[f"{name}: {key[:-2].replace('_', ' ')}"] = row[key]
    failed = {k: r["error"] for k, r in rows.items() if r["status"] != "ok"}
    if failed:
        raise RuntimeError("demo runs failed: " + "; ".join(f"{k}: {e}" for k, e in failed.items()))

    def ranking(mode: str):
        names = [v.name for v in runs if v.mode == mode]
        files = [variant_dir(out, k) / "damage.h5" for k in names]
        return compare(files, [k.removesuffix(f"-{mode}") for k in names])

    dynamic = ranking("dynamic")
    qs = ranking("quasistatic") if quasistatic else None
    clearances = _clearances(out, runs)
    path = None
    if report:
        if on_stage is not None:
            on_stage("report", "report")
        t1 = time.perf_counter()
        step = None if on_stage is None else (lambda what: on_stage("report", what))
        path = _write_report(out, runs, report_frames, step)
        times["report"] = time.perf_counter() - t1
    times["total"] = time.perf_counter() - t0
    return DemoOutcome(out, rows, dynamic, qs, path, times, clearances)


def _clearances(out: Path, runs: list[Variant]) -> dict[str, dict]:
    """The clearance summary of every run's cable (dynamic runs first), read from its result
    file; runs without geometry are left out."""
    from cablelife.results import load_result
    from cablelife.surroundings.summary import clearance_summary

    found = {}
    for mode in MODES:
        for v in runs:
            if v.mode != mode:
                continue
            res = load_result(variant_dir(out, v.name) / "result.h5")
            for name, c in res.cables.items():
                if c.surroundings is not None:
                    label = v.name if len(res.cables) == 1 else f"{v.name}: {name}"
                    found[label] = clearance_summary(c)
    return found


def least_clearance(summary: dict) -> tuple[str, dict] | None:
    """The body nearest of all in a clearance summary and its entry (min, s, t, part)."""
    near = [(b, v) for b, v in summary["bodies"].items() if v is not None]
    return min(near, key=lambda bv: bv[1]["min"]) if near else None


def _write_report(out: Path, runs: list[Variant], frames: int, on_step=None) -> Path:
    from cablelife.lda.io import load_damage
    from cablelife.report.html import ReportRun, write_report
    from cablelife.results import load_result

    report_runs = [
        ReportRun(
            v.name,
            load_result(variant_dir(out, v.name) / "result.h5"),
            load_damage(variant_dir(out, v.name) / "damage.h5"),
        )
        for v in runs
    ]
    return write_report(out / "report.html", report_runs, frames=frames, on_step=on_step)
