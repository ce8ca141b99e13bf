"""``cablelife study STUDY.toml [-o DIR] [--scheduler ADDRESS]``."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer


def _fmt(x, spec: str = ".4g") -> str:
    try:
        return format(float(x), spec)
    except (TypeError, ValueError):
        return "" if x is None else str(x)


HEADERS = {
    "rank": "#",
    "max_damage": "max D",
    "ratio_to_best": "ratio",
    "hot_spot_s_m": "spot s (m)",
    "hot_spot_clip": "near clip",
    "motion_volume_l": "vol. (l)",
}


def study_command(
    study: Annotated[Path, typer.Argument(help="Study file (TOML): base scene + parameters.")],
    output: Annotated[
        Path | None, typer.Option("--output", "-o", help="Output folder [out/<study name>].")
    ] = None,
    scheduler: Annotated[
        str | None,
        typer.Option(help="Address of a running Dask scheduler [a local cluster is started]."),
    ] = None,
    workers: Annotated[
        int | None, typer.Option(help="Worker processes of the local cluster [one per core].")
    ] = None,
) -> None:
    """Run a variant study on Dask: simulate, LDA and summary per variant, ranked by damage.

    A re-run skips finished variants; failed ones are reported and computed again next time.
    """
    from rich import box
    from rich.console import Console
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn
    from rich.table import Table

    from cablelife.study.runner import run_study
    from cablelife.study.spec import StudyError

    console = Console()
    err = Console(stderr=True)
    columns = (
        TextColumn("variants"),
        BarColumn(),
        MofNCompleteColumn(),
        TimeElapsedColumn(),
        TextColumn("{task.description}"),
    )
    try:
        with Progress(*columns, console=console, transient=True) as bar:
            task = bar.add_task("", total=None)

            def progress(done: int, total: int, row: dict) -> None:
                last = row.get("variant", "")
                if row.get("status") == "failed":
                    console.print(f"[red]variant {last} failed:[/] {row.get('error', '')}")
                bar.update(task, completed=done, total=total, description=last)

            outcome = run_study(
                study, output, scheduler=scheduler, workers=workers, progress=progress
            )
    except (StudyError, ConnectionError, FileNotFoundError) as e:
        err.print(f"[bold red]error:[/] {e}", highlight=False, soft_wrap=True)
        raise typer.Exit(2) from None
    frame = outcome.table
    t = Table(title=f"study {outcome.out_dir}", title_justify="left", box=box.SIMPLE_HEAD)
    shown = ["rank", "variant", *outcome.parameters, "max_damage", "ratio_to_best"]
    shown += ["hot_spot_s_m", "hot_spot_clip", "motion_volume_l", "status"]
    shown = [c for c in shown if c in frame]
    if "status" in shown and frame["status"].eq("ok").all():
        shown.remove("status")  # fits 80 columns; the failures are listed below
    for c in shown:  # short headers; text cells wrap instead of turning into "body…"
        text = c in ("variant", "hot_spot_clip", "status")
        t.add_column(
            HEADERS.get(c, c),
            justify="left" if text else "right",
            overflow="fold" if text else "ellipsis",
            no_wrap=not text,
        )
    for _, r in frame.head(20).iterrows():
        t.add_row(
            *[
                _fmt(r[c]) if c not in ("variant", "hot_spot_clip", "status") else str(r[c])
                for c in shown
            ]
        )
    console.print(t)
    if len(frame) > 20:
        console.print(f"… {len(frame) - 20} more in {outcome.csv}")
    console.print(
        f"{len(outcome.computed)} computed, {len(outcome.skipped)} already finished, "
        f"{len(outcome.failed)} failed"
    )
    for name, e in outcome.failed.items():
        console.print(f"[red]failed[/] {name}: {e}", highlight=False)
    console.print(f"summary: {outcome.csv}, {outcome.parquet}")
    if outcome.plot is not None:
        console.print(f"plot: {outcome.plot}")
    if outcome.failed:
        raise typer.Exit(1)
