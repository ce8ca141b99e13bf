"""Run a study's variants as Dask tasks: on a local cluster (one worker process per core) or
on an existing cluster (``scheduler`` address). Finished variants are skipped, a failing
variant is reported and does not stop the others, a lost worker's tasks are retried by Dask
on the remaining workers."""

from __future__ import annotations

import os
import uuid
from collections.abc import Callable
from contextlib import suppress
from dataclasses import dataclass, field
from pathlib import Path

import pandas as pd

from cablelife.atomic import write_atomic
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


def _client(scheduler: str | None, workers: int | None, security=None):
    import dask
    from distributed import Client, LocalCluster

    dask.config.set({"distributed.scheduler.allowed-failures": ALLOWED_FAILURES})
    if scheduler is not None:
        try:
            return Client(scheduler, timeout="20s", security=security), None
        except (OSError, TypeError, ValueError) as err:  # TypeError: tls:// without TLS set-up
            hint = ""
            if scheduler.startswith("tls://") and security is None:
                hint = "; a tls:// scheduler needs --tls-ca-file, --tls-cert and --tls-key"
            raise ConnectionError(
                f"--scheduler {scheduler!r}: no Dask scheduler answers there ({err}){hint}"
            ) from None
    n = workers or os.cpu_count() or 1
    # No HTTP server anywhere (Dask starts unauthenticated ones even without a dashboard: the
    # scheduler's on port 8787, each worker's on a random port): no routes, and stopped.
    dask.config.set({"distributed.scheduler.http.routes": [], "distributed.worker.http.routes": []})
    cluster = LocalCluster(
        n_workers=n,
        threads_per_worker=1,
        processes=True,
        host="127.0.0.1",
        dashboard_address=None,
        worker_dashboard_address=None,
        scheduler_kwargs={"dashboard": False, "dashboard_address": "127.0.0.1:0"},
        preload=["cablelife.study.worker_setup"],
        silence_logs=40,
    )
    cluster.sync(_stop_http_server, cluster.scheduler)
    return Client(cluster), cluster


async def _stop_http_server(node) -> None:
    server = getattr(node, "http_server", None)
    if server is not None:
        server.stop()


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
    security=None,
    allow_outside_files: bool = False,
) -> StudyOutcome:
    """Runs every unfinished variant of the study and writes the summary table and plot.

    ``progress(done, total, row)`` is called after each variant (finished ones count at once).
    ``security``: a ``distributed.security.Security`` for a ``tls://`` scheduler address.
    """
    study, study_dir = load_study(study_path)
    variants = expand(study, study_dir, allow_outside_files)
    out = Path(out_dir) if out_dir is not None else default_out_dir(study_path, study)
    out.mkdir(parents=True, exist_ok=True)
    write_atomic(out / "study.toml", lambda f: f.write(Path(study_path).read_bytes()))
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
        client, cluster = _client(scheduler, workers, security)
        _run_pending(client, cluster, pending, out, study, rows, total, progress)
    return _finish(study, variants, rows, out, skipped)


def _run_pending(client, cluster, pending, out, study, rows, total, progress) -> None:
    from distributed import as_completed

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
    except BaseException as err:
        if isinstance(err, KeyboardInterrupt):
            _quiet_shutdown()
        for fut in futures:
            fut.cancel()
        if cluster is not None:
            _stop_local_workers(cluster)
        raise
    finally:
        client.close()
        if cluster is not None:
            cluster.close()


def _stop_local_workers(cluster) -> None:
    """Ends the local workers at once: a graceful close would let each finish its running
    variant first (minutes, and a study that goes on after Ctrl-C). Their nannies are told not
    to restart them. The variants they ran are computed on the next run."""
    import signal

    for nanny in list(cluster.workers.values()):
        with suppress(Exception):
            nanny.close_gracefully(reason="cablelife study interrupted")
        pid = getattr(nanny, "pid", None)
        if pid:
            with suppress(OSError):
                os.kill(pid, signal.SIGKILL)


def _quiet_shutdown() -> None:
    """Ctrl-C: the cluster is closed under running variants, and Dask logs the closed
    connections (CommClosedError, …) of that on purpose; nothing of it is news to the user."""
    import logging

    for name in ("distributed", "tornado", "asyncio"):
        logging.getLogger(name).setLevel(logging.CRITICAL + 1)


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
