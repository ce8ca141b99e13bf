"""CLI functions ``lda`` and ``compare`` (typer-compatible; registered by cablelife.cli)."""

from __future__ import annotations

import warnings
from pathlib import Path
from typing import Annotated

import typer

from cablelife.lda.defaults import DEFAULT_PLANE_STEP_DEG


def lda_command(
    result: Annotated[Path, typer.Argument(help="Result file (HDF5) of a run.")],
    output: Annotated[
        Path | None, typer.Option("--output", "-o", help="Damage file [RESULT.damage.h5].")
    ] = None,
    wohler_k: Annotated[float, typer.Option(help="Wöhler slope k (curve in RANGES).")] = 5.0,
    wohler_alpha: Annotated[
        float | None,
        typer.Option(help="Wöhler constant α in Pa^k for absolute damage [pseudo-damage]."),
    ] = None,
    knee_range: Annotated[
        float | None, typer.Option(help="Knee stress range ΔS_D in Pa [no knee].")
    ] = None,
    knee_kind: Annotated[str, typer.Option(help="Below the knee: haibach | cutoff.")] = "haibach",
    points: Annotated[int, typer.Option(help="Surface points per section.")] = 16,
    plane_step: Annotated[
        float, typer.Option(help="Critical-plane step in degrees.")
    ] = DEFAULT_PLANE_STEP_DEG,
    section_step: Annotated[int, typer.Option(help="Analyse every k-th node.")] = 1,
    residue: Annotated[
        str, typer.Option(help="Residue: half (ASTM) | discard | full | repeated.")
    ] = "half",
    hysteresis: Annotated[float, typer.Option(help="Hysteresis gate in Pa.")] = 0.0,
    threads: Annotated[int | None, typer.Option(help="Threads [all cores].")] = None,
    hot_spots: Annotated[int, typer.Option(help="Hot spots to list.")] = 5,
) -> None:
    """Comparative load data analysis: pseudo-damage map of a result."""
    from rich.progress import Progress

    from cablelife.clitext import console as make_console
    from cablelife.clitext import escape, print_error, print_warning
    from cablelife.lda.pipeline import analyse, default_damage_path
    from cablelife.lda.settings import LdaSettings

    console = make_console()
    try:
        if hot_spots < 0:
            raise ValueError(f"--hot-spots = {hot_spots}: allowed: 0 or more")
        settings = LdaSettings.from_options(
            wohler_k=wohler_k,
            wohler_alpha=wohler_alpha,
            knee_range=knee_range,
            knee_kind=knee_kind,
            points=points,
            plane_step=plane_step,
            section_step=section_step,
            residue=residue,
            hysteresis=hysteresis,
        )
        with (
            Progress(console=console, transient=True) as bar,
            warnings.catch_warnings(record=True) as caught,
        ):
            warnings.simplefilter("always")  # sampling, partial results
            tasks = {}

            def progress(cable, done, total):
                if cable not in tasks:
                    tasks[cable] = bar.add_task(escape(f"LDA {cable}"), total=total)
                bar.update(tasks[cable], completed=done)

            analysis = analyse(
                result, threads=threads, progress=progress, **settings.analyse_kwargs()
            )
        for w in caught:
            print_warning(console, w.message)
        path = analysis.save(output or default_damage_path(result))
    except KeyboardInterrupt:
        from cablelife.interrupt import interrupted

        raise interrupted("no damage file written") from None
    except (ValueError, FileNotFoundError, OSError) as e:
        print_error(console, e)
        raise typer.Exit(2) from None
    console.print(escape(analysis.summary(hot_spots)), soft_wrap=True, highlight=False)
    console.print(escape(f"damage file: {path}"))


def compare_command(
    files: Annotated[list[Path], typer.Argument(help="Damage files (or result files).")],
    labels: Annotated[str | None, typer.Option(help="Comma-separated labels [file names].")] = None,
    hot_spots: Annotated[int, typer.Option(help="Hot spots per variant.")] = 1,
    force: Annotated[
        bool,
        typer.Option(help="Compare even if the Wöhler curves, settings or run modes differ."),
    ] = False,
) -> None:
    """Rank variants by maximum pseudo-damage, with ratios to the best and hot spots."""
    from cablelife.clitext import console as make_console
    from cablelife.clitext import escape, print_error, printed_warnings
    from cablelife.lda.compare import compare

    console = make_console()
    try:
        if hot_spots < 0:
            raise ValueError(f"--hot-spots = {hot_spots}: allowed: 0 or more")
        names = None if labels is None else [s.strip() for s in labels.split(",")]
        with printed_warnings(console):  # partial results, sampling
            cmp = compare(
                files, names, check_settings=not force, check_modes=not force, n_hot_spots=hot_spots
            )
    except (ValueError, FileNotFoundError, TypeError, OSError) as e:
        print_error(console, e)
        raise typer.Exit(2) from None
    console.print(escape(cmp.table(hot_spots)), soft_wrap=True, highlight=False)
    console.print(escape(f"best: {cmp.best.label}"))
