"""Command line: ``cablelife run``, ``modes``, ``signal``, ``volume``, ``report``, ``paraview``,
``lda``, ``compare``, ``study``, ``demo``, ``schema``."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer
from rich.console import Console
from rich.progress import BarColumn, Progress, TextColumn, TimeRemainingColumn
from rich.table import Table

from cablelife.results import Result
from cablelife.scene import SceneError, json_schema, load_scene
from cablelife.signals.errors import SignalError
from cablelife.simulate import SimulationError, simulate
from cablelife.summary import cable_summary

app = typer.Typer(
    help="cablelife: digital mock-up of cables and hoses (Cosserat rod simulation, fatigue).",
    no_args_is_help=True,
    pretty_exceptions_enable=False,
)
console = Console()
err_console = Console(stderr=True)


def fail(message: str, code: int = 2) -> typer.Exit:
    err_console.print(f"[bold red]error:[/] {message}", highlight=False, soft_wrap=True)
    return typer.Exit(code)


def print_summary(result: Result) -> None:
    """Prints the run summary table of every cable."""
    for name, c in result.cables.items():
        s = cable_summary(c)
        t = Table(
            title=f"cable '{name}' — {result.mode}, {s['steps']} step(s), {s['segments']} segments",
            title_justify="left",
        )
        t.add_column("quantity")
        t.add_column("value", justify="right")
        t.add_row("max tension F3", f"{s['max_tension']:.4g} N")
        t.add_row("min tension F3 (compression < 0)", f"{s['min_tension']:.4g} N")
        t.add_row("max shear force |F1, F2|", f"{s['max_shear']:.4g} N")
        t.add_row("max bending moment |M1, M2|", f"{s['max_bending']:.4g} N m")
        t.add_row("max torsion |M3|", f"{s['max_torsion']:.4g} N m")
        t.add_row(
            "min bend radius",
            f"{s['min_bend_radius']:.4g} m at s = {s['min_bend_radius_s']:.3f} m",
        )
        t.add_row(
            "Newton iterations per step",
            f"mean {s['newton_iterations_mean']:.1f}, max {s['newton_iterations_max']}",
        )
        t.add_row("solver wall time", f"{s['wall_time'] * 1e3:.1f} ms")
        rtf = c.solver.get("real_time_factor")
        if result.mode == "dynamic" and rtf is not None:
            t.add_row("real-time factor (wall / simulated)", f"{rtf:.3f}")
            tau = c.solver.get("tau_bend")
            if c.solver.get("damping_source") == "ratio":
                w1 = c.solver["omega1"]
                t.add_row(
                    "damping",
                    f"ζ = {c.solver['damping_ratio']:g} of critical on mode 1 "
                    f"(ω₁ = {w1:.4g} rad/s, f₁ = {w1 / 6.283185307:.4g} Hz) → τ = {tau[0]:.4g} s",
                )
            else:
                t.add_row("damping", f"τ = {tau[0]:.4g} s (given)")
        console.print(t)
        ct = Table(title="clip reactions (max over time)", title_justify="left")
        ct.add_column("clip")
        ct.add_column("s [m]", justify="right")
        ct.add_column("|force| [N]", justify="right")
        ct.add_column("|moment| [N m]", justify="right")
        for clip, v in s["clips"].items():
            ct.add_row(clip, f"{v['s']:.3f}", f"{v['max_force']:.4g}", f"{v['max_moment']:.4g}")
        console.print(ct)
        if c.surroundings is not None:
            from cablelife.surroundings.summary import clearance_tables

            for table in clearance_tables(c):
                console.print(table)


@app.command()
def run(
    scene: Annotated[Path, typer.Argument(help="scene TOML file")],
    mode: Annotated[
        str | None, typer.Option(help="static | quasistatic | dynamic (overrides the scene)")
    ] = None,
    output: Annotated[Path | None, typer.Option("-o", "--output", help="result HDF5 file")] = None,
    quiet: Annotated[bool, typer.Option("--quiet", "-q", help="no progress bar")] = False,
) -> None:
    """Simulate a scene and print a summary; with -o, save the result (HDF5)."""
    try:
        sc = load_scene(scene)
    except SceneError as err:
        raise fail(str(err)) from None
    progress = Progress(
        TextColumn("{task.description}"),
        BarColumn(),
        TextColumn("{task.completed}/{task.total} steps"),
        TimeRemainingColumn(),
        console=err_console,
        disable=quiet,
    )
    tasks: dict[str, int] = {}

    def on_progress(cable: str, done: int, total: int) -> None:
        if cable not in tasks:
            tasks[cable] = progress.add_task(f"cable '{cable}'", total=total)
        progress.update(tasks[cable], completed=done)

    try:
        with progress:
            result = simulate(sc, mode=mode, progress=on_progress)
    except (SceneError, SignalError) as err:
        raise fail(str(err)) from None
    except SimulationError as err:
        if output is not None:
            err.result.save(output)
            err_console.print(f"partial result (steps before the failure) saved to {output}")
        raise fail(str(err), code=1) from None
    print_summary(result)
    if output is not None:
        result.save(output)
        console.print(f"result saved to {output}")


@app.command()
def modes(
    scene: Annotated[Path, typer.Argument(help="scene TOML file")],
    count: Annotated[int, typer.Option("--count", "-n", help="number of modes")] = 6,
) -> None:
    """Natural frequencies of each mounted cable about its static equilibrium."""
    from cablelife.modal import modes as compute_modes

    try:
        sc = load_scene(scene)
        found = compute_modes(sc, count)
    except (SceneError, SignalError) as err:
        raise fail(str(err)) from None
    for name, m in found.items():
        t = Table(title=f"cable '{name}': natural frequencies", title_justify="left")
        t.add_column("mode", justify="right")
        t.add_column("f [Hz]", justify="right")
        t.add_column("ω [rad/s]", justify="right")
        for i, (f, w) in enumerate(zip(m.frequencies, m.omega, strict=True), start=1):
            t.add_row(str(i), f"{f:.4g}", f"{w:.4g}")
        console.print(t)


@app.command()
def schema(
    output: Annotated[Path | None, typer.Option("-o", "--output", help="write here")] = None,
) -> None:
    """Print (or write) the JSON schema of the scene format."""
    import json

    text = json.dumps(json_schema(), indent=2)
    if output is None:
        console.print_json(text)
    else:
        output.write_text(text + "\n")


def _register_optional() -> None:
    """Commands of the signal generator and the fatigue analysis (in their own packages)."""
    try:
        from cablelife.signals.cli import signal_command

        app.command(name="signal")(signal_command)
    except ImportError:  # pragma: no cover - package always ships signals
        pass
    from cablelife.export.cli import paraview_command
    from cablelife.report.cli import report_command
    from cablelife.volume.cli import volume_command

    app.command(name="volume")(volume_command)
    app.command(name="report")(report_command)
    app.command(name="paraview")(paraview_command)
    try:
        from cablelife.lda.cli import compare_command, lda_command

        app.command(name="lda")(lda_command)
        app.command(name="compare")(compare_command)
    except ImportError:
        pass
    from cablelife.demo_cli import demo_command
    from cablelife.study.cli import study_command

    app.command(name="study")(study_command)
    app.command(name="demo")(demo_command)


_register_optional()


def main() -> None:  # pragma: no cover
    app()


if __name__ == "__main__":  # pragma: no cover
    main()
