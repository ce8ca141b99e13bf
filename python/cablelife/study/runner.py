"""Run a study's variants as Dask tasks: on a local cluster (one worker process per core) or
on an existing cluster (``scheduler`` address). Finished variants are skipped, a failing
variant is reported and does not stop the others, a lost worker's tasks are retried by Dask
on the remaining workers."""

from __future__ import annotations

import os
import shutil
import uuid
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import pandas as pd

from cablelife.study.spec import StudyFile, load_study
from cablelife.study.table import plot_damage_over_parameters, save_tables, summary_frame
from cablelife.study.task import finished_row, run_variant, task_settings
from cablelife.study.variants import Variant, expand

#: Times Dask may lose a worker while it runs one variant before giving the variant up.
ALLOWED_FAILURES = 3


@dataclass
class StudyOutcome:
    """What a study run produced: the summary table and where its files are."""

    out_dir: Path
    table: pd.DataFrame
    csv: Path
    parquet: Path
    plot: Path | None
    parameters: list[str] = field(default_factory=list)
    computed: list[str] = field(default_factory=list)
    skipped: list[str] = field(default_factory=list)
    failed: dict[str, str] = field(default_factory=dict)


def default_out_dir(study_path: str | Path, study: StudyFile) -> Path:
    return Path("out") / (study.study.name or Path(study_path).stem)


def _client(scheduler: str | None, workers: int | None):
    import dask
    from distributed import Client, LocalCluster

    dask.config.set({"distributed.scheduler.allowed-failures": ALLOWED_FAILURES})
    if scheduler is not None:
        try:
            return Client(scheduler, timeout="20s"), None
        except OSError as err:
            raise ConnectionError(
                f"--scheduler {scheduler!r}: no Dask scheduler answers there ({err})"
            ) from None
    n = workers or os.cpu_count() or 1
    cluster = LocalCluster(
        n_workers=n,
        threads_per_worker=1,
        processes=True,
        dashboard_address=None,
        silence_logs=40,
    )
    return Client(cluster), cluster


def _failed_row(variant: Variant, error: BaseException) -> dict:
    return variant.row() | {
        "status": "failed",
        "stage": "worker",
        "error": f"{type(error).__name__}: {error}",
    }


def run_study(
    study_path: str | Path,
    out_dir: str | Path | None = None,
    *,
    scheduler: str | None = None,
    workers: int | None = None,
    progress: Callable[[int, int, dict], None] | None = None,
) -> StudyOutcome:
    """Runs every unfinished variant of the study and writes the summary table and plot.

    ``progress(done, total, row)`` is called after each variant (finished ones count at once).
    """
    study, study_dir = load_study(study_path)
    variants = expand(study, study_dir)
    out = Path(out_dir) if out_dir is not None else default_out_dir(study_path, study)
    out.mkdir(parents=True, exist_ok=True)
    shutil.copyfile(study_path, out / "study.toml")
    settings = task_settings(study.lda, study.volume, study.study.threads)
    rows: dict[str, dict] = {}
    skipped = []
    for v in variants:
        row = finished_row(out, v, settings)
        if row is not None:
            rows[v.name] = row
            skipped.append(v.name)
    pending = [v for v in variants if v.name not in rows]
    total = len(variants)
    if progress is not None:
        progress(len(rows), total, {})
    if pending:
        _run_pending(pending, out, study, rows, total, scheduler, workers, progress)
    return _finish(study, variants, rows, out, skipped)


def _run_pending(pending, out, study, rows, total, scheduler, workers, progress) -> None:
    from distributed import as_completed

    client, cluster = _client(scheduler, workers)
    futures = {}
    try:
        for v in pending:
            fut = client.submit(
                run_variant,
                v,
                str(out.resolve()),
                study.lda,
                study.volume,
                study.study.threads,
                key=f"variant-{v.name}-{uuid.uuid4().hex[:12]}",
                pure=False,
            )
            futures[fut] = v
        for fut in as_completed(futures):
            v = futures[fut]
            try:
                row = fut.result()
            except Exception as err:  # noqa: BLE001 — e.g. KilledWorker: report, go on
                row = _failed_row(v, err)
            rows[v.name] = row
            if progress is not None:
                progress(len(rows), total, row)
    except BaseException:
        for fut in futures:
            fut.cancel()
        raise
    finally:
        client.close()
        if cluster is not None:
            cluster.close()


def _finish(study: StudyFile, variants: list[Variant], rows, out: Path, skipped) -> StudyOutcome:
    params = [p.name for p in study.parameters]
    frame = summary_frame([rows[v.name] for v in variants if v.name in rows], params)
    csv, parquet = save_tables(frame, out)
    plot = None
    if frame["status"].eq("ok").any():
        from cablelife.plots.figure import save_png
        from cablelife.study.parameters import parameter_axis

        labels = {p.name: parameter_axis(p) for p in study.parameters}
        plot = save_png(plot_damage_over_parameters(frame, params, labels), out / "damage.png")
    failed = {r["variant"]: r.get("error", "") for r in rows.values() if r.get("status") != "ok"}
    computed = [v.name for v in variants if v.name in rows and v.name not in skipped]
    return StudyOutcome(out, frame, csv, parquet, plot, params, computed, list(skipped), failed)
