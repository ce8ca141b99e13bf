"""Command line: ``cablelife run``, ``modes``, ``signal``, ``volume``, ``report``, ``paraview``,
``lda``, ``compare``, ``study``, ``demo``, ``workbench``, ``schema``."""

from __future__ import annotations

import warnings
from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer
from rich.console import Console
from rich.markup import escape

from cablelife.paths import ALLOW_OUTSIDE_HELP

if TYPE_CHECKING:
    from cablelife.results import Result

# Heavy modules (numpy, pydantic, h5py, scipy, matplotlib, plotly, pandas, dask) are imported
# inside the commands that use them: `cablelife --help` stays fast (benchmarks/bench_startup.py).

app = typer.Typer(
    help="cablelife: digital mock-up of cables and hoses (Cosserat rod simulation, fatigue).",
    no_args_is_help=True,
    pretty_exceptions_enable=False,
    rich_markup_mode=None,  # help texts as written: "[pseudo-damage]", "s [m]" stay visible
)
console = Console(emoji=False, highlight=False)
err_console = Console(stderr=True, emoji=False, highlight=False)


def fail(message: str, code: int = 2) -> typer.Exit:
    err_console.print(f"[bold red]error:[/] {escape(message)}", highlight=False, soft_wrap=True)
    return typer.Exit(code)


def print_summary(result: Result) -> None:
    """Prints the run summary table of every cable."""
    from rich.table import Table

    from cablelife.summary import VISCOUS_SHARE_WARNING, cable_summary

    for name, c in result.cables.items():
        s = cable_summary(c)
        t = Table(
            title=escape(
                f"cable '{name}' — {result.mode}, {s['steps']} step(s), {s['segments']} segments"
            ),
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
        for key, label in (
            ("max_axial_strain", "max axial strain Γ3"),
            ("max_shear_strain", "max shear strain |Γ1, Γ2|"),
        ):
            v = s[key]
            t.add_row(label, f"{100 * v['value']:.3g} % at s = {v['s']:.3f} m, t = {v['t']:.4g} s")
        if s["prestrain"] > 0:
            t.add_row(
                "span pre-strain (clips farther apart than the cable)",
                f"{100 * s['prestrain']:.3g} %",
            )
        if s["unstable_steps"]:
            t.add_row("unstable static states", f"{s['unstable_steps']}")
        for snap in s["snap_throughs"]:
            t.add_row(
                "snap-through",
                f"t = {snap['t']:.4g} s, jump {snap['jump']:.3g} m at s = {snap['s']:.3f} m",
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
            ts = c.solver.get("tau_shear")
            if ts is not None and tau is not None:
                t.add_row(
                    "τ extension, shear, torsion",
                    f"{ts[2]:.3g} s, {ts[0]:.3g} s, {tau[2]:.3g} s",
                )
        share = s.get("viscous_share")
        if share is not None:
            t.add_row(
                "viscous share of peak F3, |F1,F2|, |M1,M2|, M3",
                ", ".join(f"{100 * v:.0f} %" for v in share),
            )
        console.print(t)
        if share is not None and share.max() > VISCOUS_SHARE_WARNING:
            names = ("tension", "shear force", "bending moment", "torsion")
            big = ", ".join(
                f"{n} {100 * v:.0f} %"
                for n, v in zip(names, share, strict=True)
                if v > VISCOUS_SHARE_WARNING
            )
            console.print(
                f"[yellow]warning:[/yellow] cable '{escape(name)}': the viscous damping part "
                f"of the peak section loads is large ({big} > "
                f"{100 * VISCOUS_SHARE_WARNING:.0f} %): the damping model sets these loads "
                "(and the fatigue result); check the damping (docs/dynamics.md)"
            )
        ct = Table(title="clip reactions (max over time)", title_justify="left")
        ct.add_column("clip")
        ct.add_column(escape("s [m]"), justify="right")
        ct.add_column(escape("|force| [N]"), justify="right")
        ct.add_column(escape("|moment| [N m]"), justify="right")
        for clip, v in s["clips"].items():
            ct.add_row(
                escape(clip), f"{v['s']:.3f}", f"{v['max_force']:.4g}", f"{v['max_moment']:.4g}"
            )
        console.print(ct)
        if c.surroundings is not None:
            from cablelife.surroundings.summary import clearance_tables

            for table in clearance_tables(c):
                console.print(table)
    if result.junctions:
        from cablelife.harness import junction_table

        console.print(junction_table(result))


def _progress_bar():
    """A progress bar of the steps of each cable (on stderr) and its callback for
    :func:`cablelife.simulate.simulate`; not imported with --quiet (start-up time)."""
    from rich.progress import BarColumn, Progress, TextColumn, TimeRemainingColumn

    from cablelife.surroundings.clearance import CLEARANCE_LABEL

    progress = Progress(
        TextColumn("{task.description}"),
        BarColumn(),
        TextColumn("{task.completed}/{task.total} steps"),
        TimeRemainingColumn(),
        console=err_console,
    )
    tasks: dict[str, int] = {}

    def on_progress(cable: str, done: int, total: int) -> None:
        if cable not in tasks:
            # a cable's steps, or the clearance of a cable ("clearance of <cable>")
            what = cable if cable.startswith(CLEARANCE_LABEL) else f"cable '{cable}'"
            tasks[cable] = progress.add_task(escape(what), total=total)
        progress.update(tasks[cable], completed=done)

    return progress, on_progress


@app.command()
def run(
    scene: Annotated[Path, typer.Argument(help="scene TOML file")],
    mode: Annotated[
        str | None, typer.Option(help="static | quasistatic | dynamic (overrides the scene)")
    ] = None,
    output: Annotated[Path | None, typer.Option("-o", "--output", help="result HDF5 file")] = None,
    quiet: Annotated[bool, typer.Option("--quiet", "-q", help="no progress bar")] = False,
    allow_outside_files: Annotated[
        bool, typer.Option("--allow-outside-files", help=ALLOW_OUTSIDE_HELP)
    ] = False,
    precision: Annotated[
        str | None,
        typer.Option(help="float64 | float32: saved histories (overrides the scene)"),
    ] = None,
) -> None:
    """Simulate a scene and print a summary; with -o, save the result (HDF5)."""
    from contextlib import nullcontext

    from cablelife.clitext import print_warning
    from cablelife.interrupt import interrupted
    from cablelife.scene import SceneError, load_scene
    from cablelife.signals.errors import SignalError
    from cablelife.simulate import SimulationError, simulate

    if precision not in (None, "float64", "float32"):
        raise fail(f"--precision {precision!r}: allowed are float64, float32")
    try:
        sc = load_scene(scene)
    except SceneError as err:
        raise fail(str(err)) from None
    if allow_outside_files:
        sc.files.allow_outside = True
    if output is not None and (output.is_dir() or not output.parent.is_dir()):
        why = "is a directory" if output.is_dir() else "is in a folder that does not exist"
        raise fail(f"--output {str(output)!r} {why}; give a file in an existing folder")
    if precision is not None:
        sc.simulation.output_precision = precision
    progress, on_progress = (nullcontext(), None) if quiet else _progress_bar()
    try:
        with progress, warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            try:
                result = simulate(sc, mode=mode, progress=on_progress)
            finally:
                for message in dict.fromkeys(str(w.message) for w in caught):
                    print_warning(err_console, message)  # one line each, no source line
    except (SceneError, SignalError) as err:
        raise fail(str(err)) from None
    except SimulationError as err:
        what = "interruption" if err.interrupted else "failure"
        kept = err.kept or f"steps before the {what}"
        if output is not None:
            err.result.save(output)
            err_console.print(escape(f"partial result ({kept}) saved to {output}"))
        if err.interrupted:
            raise interrupted(
                ("the clearance was not computed" if err.kept else "the run stopped early")
                + ("" if output else " (nothing saved)")
            ) from None
        raise fail(str(err), code=1) from None
    if output is not None:  # saved first: a summary that cannot be printed loses nothing
        try:
            result.save(output)
        except OSError as err:
            print_summary(result)
            raise fail(f"--output {str(output)!r} cannot be written ({err})") from None
    from cablelife.hints import run_hints

    for message in run_hints(sc, result):
        print_warning(err_console, message)
    print_summary(result)
    if output is not None:
        console.print(escape(f"result saved to {output}"))


@app.command()
def modes(
    scene: Annotated[Path, typer.Argument(help="scene TOML file")],
    count: Annotated[int, typer.Option("--count", "-n", help="number of modes")] = 6,
) -> None:
    """Natural frequencies of each mounted cable (of the whole harness if the scene has
    junctions) about its static equilibrium."""
    from rich.table import Table

    from cablelife.modal import modes as compute_modes
    from cablelife.scene import SceneError, load_scene
    from cablelife.signals.errors import SignalError

    try:
        sc = load_scene(scene)
        found = compute_modes(sc, count)
    except (SceneError, SignalError) as err:
        raise fail(str(err)) from None
    if sc.junctions:
        # One system: the frequencies are those of the whole harness (the same per cable).
        names = ", ".join(f"'{n}'" for n in found)
        found = {f"harness ({names})": next(iter(found.values()))}
    for name, m in found.items():
        title = name if sc.junctions else f"cable '{name}'"
        t = Table(title=escape(f"{title}: natural frequencies"), title_justify="left")
        t.add_column("mode", justify="right")
        t.add_column(escape("f [Hz]"), justify="right")
        t.add_column(escape("ω [rad/s]"), justify="right")
        t.add_column("type")
        t.add_column("energy share", justify="right")
        for i, (f, w) in enumerate(zip(m.frequencies, m.omega, strict=True), start=1):
            share = f"{100 * m.shares[i - 1].max():.0f} %"
            t.add_row(str(i), f"{f:.4g}", f"{w:.4g}", m.kind[i - 1], share)
        console.print(t)


@app.command()
def schema(
    output: Annotated[Path | None, typer.Option("-o", "--output", help="write here")] = None,
) -> None:
    """Print (or write) the JSON schema of the scene format."""
    import json

    from cablelife.scene import json_schema

    text = json.dumps(json_schema(), indent=2)
    if output is None:
        console.print_json(text)
        return
    from cablelife.atomic import write_text_atomic

    if not output.parent.is_dir():
        raise fail(f"--output {str(output)!r} is in a folder that does not exist")
    try:
        write_text_atomic(output, text + "\n")
    except OSError as err:
        what = "is a directory" if output.is_dir() else f"cannot be written ({err.strerror})"
        raise fail(f"--output {str(output)!r} {what}") from None


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
    from cablelife.workbench.cli import workbench_command

    app.command(name="workbench")(workbench_command)


_register_optional()


def main() -> None:  # pragma: no cover
    app(prog_name="cablelife")


if __name__ == "__main__":  # pragma: no cover
    main()
