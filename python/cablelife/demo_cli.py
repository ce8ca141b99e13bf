"""``cablelife demo [-o DIR]``: the two-variant application example end to end."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer


def demo_command(
    output: Annotated[Path, typer.Option("--output", "-o", help="Output folder.")] = Path(
        "out/demo"
    ),
    seed: Annotated[
        int | None, typer.Option(help="Seed of the random excitation [the scene's seeds].")
    ] = None,
    duration: Annotated[
        float | None, typer.Option(help="Simulated time in s [the scene's 5 s].")
    ] = None,
    example: Annotated[
        Path | None, typer.Option(help="Example folder [examples/clip-variants].")
    ] = None,
    quasistatic: Annotated[
        bool, typer.Option(help="Also run quasistatically, for comparison.")
    ] = True,
    report: Annotated[bool, typer.Option(help="Write the HTML report.")] = True,
    allow_outside_files: Annotated[
        bool,
        typer.Option(
            "--allow-outside-files",
            help="read files named in the scenes also outside the example's folder",
        ),
    ] = False,
) -> None:
    """Two mounting variants, the same engine vibration: simulate, LDA, rank, report."""
    import warnings

    from rich.live import Live
    from rich.table import Table

    from cablelife.clitext import console as make_console
    from cablelife.clitext import escape, print_error
    from cablelife.demo import run_demo
    from cablelife.study.spec import StudyError

    console = make_console()
    state: dict[str, str] = {}

    def view() -> Table:
        t = Table(title="cablelife demo: clip variants", title_justify="left")
        t.add_column("run")
        t.add_column("stage")
        for k, v in state.items():
            t.add_row(escape(k), "[green]done[/]" if v == "ok" else escape(v))
        return t

    try:
        with Live(view(), console=console, transient=False, refresh_per_second=8) as live:

            def on_stage(run: str, stage: str) -> None:
                state[run] = stage
                live.update(view())

            with warnings.catch_warnings():
                warnings.simplefilter("ignore")  # each run's warnings are in its summary
                outcome = run_demo(
                    output,
                    example=example,
                    seed=seed,
                    duration=duration,
                    quasistatic=quasistatic,
                    report=report,
                    on_stage=on_stage,
                    allow_outside_files=allow_outside_files,
                )
            state["report"] = "ok" if report else "skipped"
            live.update(view())
    except KeyboardInterrupt:
        from cablelife.interrupt import interrupted

        raise interrupted(
            f"runs finished so far (and partial results) are kept in {output / 'variants'}"
        ) from None
    except (StudyError, FileNotFoundError, RuntimeError, OSError, ValueError) as e:
        print_error(make_console(stderr=True), e)
        raise typer.Exit(2) from None
    cmp = outcome.comparison
    console.print("\n[bold]Ranking by maximum pseudo-damage (dynamic runs):[/]")
    console.print(escape(cmp.table(2)), soft_wrap=True, highlight=False)
    best, worst = cmp.variants[0], cmp.variants[-1]
    console.print(
        f"\n[bold green]{escape(f'Variant {best.label} is preferred')}[/]: "
        + escape(
            f"its maximum pseudo-damage is {worst.ratio:.2f}× lower than variant {worst.label}'s."
        ),
        highlight=False,
    )
    if outcome.clearances:
        console.print(clearance_table(outcome.clearances), highlight=False)
    if outcome.quasistatic is not None:
        qs = {v.label: v.max_damage for v in outcome.quasistatic.variants}
        parts = [
            f"{v.label}: {v.max_damage / qs[v.label]:.3g}×"
            for v in cmp.variants
            if qs.get(v.label, 0) > 0
        ]
        console.print(
            escape("Dynamic over quasistatic pseudo-damage (inertia): " + ", ".join(parts)),
            highlight=False,
        )
    for name, row in outcome.rows.items():
        for w in row.get("warnings", []):
            console.print(
                f"[yellow]warning[/] {escape(f'({name}): {w}')}", highlight=False, soft_wrap=True
            )
    t = outcome.stage_times
    console.print(
        escape("Wall time: " + ", ".join(f"{k} {v:.2f} s" for k, v in t.items() if ":" not in k)),
        highlight=False,
    )
    console.print(escape(f"Runs, damage files and summaries: {outcome.out_dir / 'variants'}"))
    if outcome.report is not None:
        console.print(f"[bold]Report:[/] {escape(str(outcome.report))}")


def clearance_table(clearances: dict[str, dict]):
    """A Rich table: per run the least clearance of its cable to the surroundings, to which
    part, where and when, and the length closer than min_clearance (the demo's summaries)."""
    from rich.table import Table

    from cablelife.clitext import escape
    from cablelife.demo import least_clearance

    limits = {s["min_clearance"] for s in clearances.values()}
    limit = f"{limits.pop() * 1e3:g} mm" if len(limits) == 1 else "min_clearance"
    t = Table(
        title="Clearance to the surroundings (cable surface, least over time and cable)",
        title_justify="left",
    )
    t.add_column("run", no_wrap=True)
    t.add_column(escape("least [mm]"), justify="right")
    t.add_column("nearest part", no_wrap=True)
    t.add_column(escape("s [m]"), justify="right")
    t.add_column(escape("t [s]"), justify="right")
    t.add_column(escape(f"length < {limit} [m]"), justify="right")
    for run, s in clearances.items():
        near = least_clearance(s)
        cells = ["–"] * 4
        if near is not None:
            v = near[1]
            cells = [f"{v['min'] * 1e3:.1f}", escape(v["part"]), f"{v['s']:.3f}", f"{v['t']:.3f}"]
        t.add_row(escape(run), *cells, f"{s['length_below_min']:.3f}")
    return t
