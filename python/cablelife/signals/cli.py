"""The ``cablelife signal SPEC`` command: generate the channels of a spec file, write them and
plot them."""

from __future__ import annotations

import warnings
from pathlib import Path
from typing import Annotated

import typer


def signal_command(
    spec: Annotated[
        Path, typer.Argument(help="Signal spec file (TOML) with a signal table and channels.")
    ],
    output: Annotated[
        Path | None,
        typer.Option(
            "--output", "-o", help="Signal file, .csv or .h5/.hdf5 (default: SPEC with .csv)."
        ),
    ] = None,
    plot: Annotated[
        Path | None, typer.Option("--plot", help="PNG file (default: OUTPUT with .png).")
    ] = None,
    no_plot: Annotated[bool, typer.Option("--no-plot", help="Do not write the PNG.")] = False,
    allow_outside_files: Annotated[
        bool,
        typer.Option(
            "--allow-outside-files", help="read measured-signal files also outside SPEC's folder"
        ),
    ] = False,
    derivatives: Annotated[
        bool,
        typer.Option(
            "--derivatives", help="CSV: add velocity and acceleration columns (HDF5 has them)."
        ),
    ] = False,
) -> None:
    """Generate excitation signals from SPEC; write them (CSV or HDF5) and a PNG with the time
    history and the Welch PSD over the target."""
    from rich.console import Console
    from rich.markup import escape
    from rich.table import Table

    from cablelife.signals.errors import SignalError
    from cablelife.signals.export import write_signals
    from cablelife.signals.specfile import generate_channels, load_spec, rms_summary

    out = Console(emoji=False, highlight=False)
    err = Console(stderr=True, emoji=False, highlight=False)
    output = output or spec.with_suffix(".csv")
    plot_path = None if no_plot else (plot or output.with_suffix(".png"))
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            settings = load_spec(spec)
            time, series = generate_channels(settings, spec.parent, allow_outside_files)
            write_signals(output, time, series, derivatives, spec.read_text(encoding="utf-8"))
            if plot_path is not None:
                from cablelife.signals.plot import plot_signals

                plot_signals(plot_path, time, series)
    except (SignalError, OSError) as error:
        err.print(f"[red]error:[/red] {escape(str(error))}", highlight=False, soft_wrap=True)
        raise typer.Exit(code=2) from None
    for w in caught:
        err.print(
            f"[yellow]warning:[/yellow] {escape(str(w.message))}", highlight=False, soft_wrap=True
        )

    table = Table(
        title=escape(f"{spec.name}: {time.size} samples, step {settings.signal.time_step:g} s")
    )
    for column in ("channel", "frame", "type", "quantity", "RMS", "target RMS", "unit"):
        table.add_column(column)
    for s in series:
        quantity, rms, target = rms_summary(s, settings.signal.time_step)
        unit = {"displacement": "", "velocity": "/s", "acceleration": "/s^2"}[quantity]
        table.add_row(
            *map(
                escape,
                (
                    s.name,
                    s.motion.frame,
                    s.motion.signal.type,
                    quantity,
                    f"{rms:.5g}",
                    "" if target is None else f"{target:.5g}",
                    s.motion.unit + unit,
                ),
            )
        )
    out.print(table)
    out.print(escape(f"wrote {output}" + ("" if plot_path is None else f" and {plot_path}")))
