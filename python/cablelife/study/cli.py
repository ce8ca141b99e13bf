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


def tls_security(scheduler: str | None, ca_file, cert, key):
    """A ``distributed.security.Security`` for a ``tls://`` scheduler from the TLS options
    (None without them: Dask's configuration applies, e.g. DASK_DISTRIBUTED__COMM__TLS__…)."""
    from cablelife.study.spec import StudyError

    given = {"--tls-ca-file": ca_file, "--tls-cert": cert, "--tls-key": key}
    if all(v is None for v in given.values()):
        return None
    if scheduler is None or not scheduler.startswith("tls://"):
        raise StudyError(
            f"{', '.join(k for k, v in given.items() if v is not None)} need a tls:// scheduler "
            f"address; --scheduler is {scheduler!r}"
        )
    for option, path in given.items():
        if path is not None and not Path(path).is_file():
            raise StudyError(f"{option} {str(path)!r}: no such file")
    if cert is None:
        raise StudyError("--tls-cert is required with TLS options (the client's certificate)")
    from distributed.security import Security

    return Security(
        tls_ca_file=str(ca_file) if ca_file else None,
        tls_client_cert=str(cert),
        tls_client_key=str(key) if key else None,
        require_encryption=True,
    )


HEADERS = {
    "rank": "#",
    "max_damage": "max D",
    "ratio_to_best": "ratio",
    "hot_spot_s_m": "spot (m)",
    "hot_spot_clip": "near",
    "motion_volume_l": "vol (l)",
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
    tls_ca_file: Annotated[
        Path | None,
        typer.Option(help="TLS: CA certificate of the cluster (with a tls:// --scheduler)."),
    ] = None,
    tls_cert: Annotated[
        Path | None, typer.Option(help="TLS: this client's certificate (PEM).")
    ] = None,
    tls_key: Annotated[
        Path | None, typer.Option(help="TLS: this client's private key (PEM) [in --tls-cert].")
    ] = None,
    allow_outside_files: Annotated[
        bool,
        typer.Option(
            "--allow-outside-files",
            help="read files named in the scene also outside the scene's folder",
        ),
    ] = False,
) -> None:
    """Run a variant study on Dask: simulate, LDA and summary per variant, ranked by damage.

    A re-run skips finished variants; failed ones are reported and computed again next time.
    """
    from rich import box
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn
    from rich.table import Table

    from cablelife.clitext import console as make_console
    from cablelife.clitext import escape, print_error
    from cablelife.study.runner import run_study
    from cablelife.study.spec import StudyError

    console = make_console()
    err = make_console(stderr=True)
    columns = (
        TextColumn("variants"),
        BarColumn(),
        MofNCompleteColumn(),
        TimeElapsedColumn(),
        TextColumn("{task.description}"),
    )
    try:
        if workers is not None and workers < 1:
            raise StudyError(f"--workers = {workers}: allowed: 1 or more")
        with Progress(*columns, console=console, transient=True) as bar:
            task = bar.add_task("", total=None)

            def progress(done: int, total: int, row: dict) -> None:
                last = row.get("variant", "")
                if row.get("status") == "failed":
                    console.print(
                        f"[red]{escape(f'variant {last} failed:')}[/] "
                        f"{escape(str(row.get('error', '')))}"
                    )
                bar.update(task, completed=done, total=total, description=escape(str(last)))

            outcome = run_study(
                study,
                output,
                scheduler=scheduler,
                workers=workers,
                progress=progress,
                security=tls_security(scheduler, tls_ca_file, tls_cert, tls_key),
                allow_outside_files=allow_outside_files,
            )
    except KeyboardInterrupt:
        from cablelife.interrupt import interrupted

        raise interrupted(
            "finished variants are kept; the same command computes the others"
        ) from None
    except (StudyError, ConnectionError, FileNotFoundError, OSError) as e:
        print_error(err, e)
        raise typer.Exit(2) from None
    frame = outcome.table
    t = Table(
        title=escape(f"study {outcome.out_dir}"),
        title_justify="left",
        box=box.SIMPLE_HEAD,
        pad_edge=False,  # 80 columns
    )
    shown = ["rank", "variant", *outcome.parameters, "max_damage", "ratio_to_best"]
    shown += ["hot_spot_s_m", "hot_spot_clip", "motion_volume_l", "status"]
    shown = [c for c in shown if c in frame]
    if "status" in shown and frame["status"].eq("ok").all():
        shown.remove("status")  # fits 80 columns; the failures are listed below
    if outcome.parameters and "variant" in shown:
        # the parameter columns name the variant (its folder name is "p1=v1_p2=v2", in the
        # CSV): at 80 columns that name squeezed into one character per line
        shown.remove("variant")
    for c in shown:  # short headers; text cells wrap instead of turning into "body…"
        text = c in ("variant", "hot_spot_clip", "status")
        longest = max((len(str(v)) for v in frame[c]), default=1) if text else 1
        t.add_column(
            escape(HEADERS.get(c, c)),
            justify="left" if text else "right",
            overflow="fold" if text else "ellipsis",
            no_wrap=not text,
            min_width=min(longest, 16) if text else None,
        )
    for _, r in frame.head(20).iterrows():
        t.add_row(
            *[
                escape(_fmt(r[c]) if c not in ("variant", "hot_spot_clip", "status") else str(r[c]))
                for c in shown
            ]
        )
    console.print(t)
    if len(frame) > 20:
        console.print(escape(f"… {len(frame) - 20} more in {outcome.csv}"))
    console.print(
        f"{len(outcome.computed)} computed, {len(outcome.skipped)} already finished, "
        f"{len(outcome.failed)} failed"
    )
    for name, e in outcome.failed.items():
        console.print(f"[red]failed[/] {escape(f'{name}: {e}')}", highlight=False)
    # paths whole on one line (the terminal wraps them; folded, they cannot be copied)
    console.print(escape(f"summary: {outcome.csv}, {outcome.parquet}"), soft_wrap=True)
    if outcome.plot is not None:
        console.print(escape(f"plot: {outcome.plot}"), soft_wrap=True)
    if outcome.failed:
        raise typer.Exit(1)
