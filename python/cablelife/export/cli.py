"""``cablelife paraview``: a result as a ParaView time series."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer


def paraview_command(
    result: Annotated[Path, typer.Argument(help="result HDF5 file")],
    output: Annotated[
        Path, typer.Option("-o", "--output", help=".pvd index; step files go beside it")
    ] = Path("cable.pvd"),
    cable: Annotated[str | None, typer.Option(help="cable name (default: every cable)")] = None,
    every: Annotated[int, typer.Option(help="write every k-th saved step")] = 1,
    damage: Annotated[
        Path | None,
        typer.Option(help="damage file of cablelife lda: damage on the line and on a tube part"),
    ] = None,
) -> None:
    """Write one VTK PolyData file per saved step plus a .pvd index for ParaView."""
    from cablelife.clitext import console as make_console
    from cablelife.clitext import escape, print_error, printed_warnings
    from cablelife.export.paraview import write_paraview
    from cablelife.plots.fatigue_data import damage_maps
    from cablelife.results import load_result

    err = make_console(stderr=True)
    written = []
    try:
        if every < 1:
            raise ValueError(f"every = {every}: must be >= 1")
        if output.is_dir():
            raise ValueError(f"--output {str(output)!r} is a directory; give a .pvd file")
        with printed_warnings(err):
            res = load_result(result)
        names = [cable] if cable is not None else list(res.cables)
        maps = damage_maps(damage) if damage is not None else {}
        if maps and not set(maps) & set(names):
            raise ValueError(
                f"damage file {str(damage)!r} has the cables {', '.join(maps)}; the result "
                f"{str(result)!r} has {', '.join(res.cables)}"
            )
        for name in names:
            if name not in res.cables:
                raise ValueError(f"cable = {name!r}: {str(result)!r} has {', '.join(res.cables)}")
            out = output if len(names) == 1 else output.with_name(f"{output.stem}_{name}.pvd")
            dm = maps[name][0] if name in maps else None
            if dm is not None:
                dm.check_fits(res.cables[name].arc_length, f"cable {name!r} of {str(result)!r}")
            written.append(
                write_paraview(res.cables[name], out, damage=dm, steps=slice(None, None, every))
            )
        if res.surroundings is not None:  # the bodies' geometry, moving with them
            from cablelife.surroundings.paraview import write_bodies

            written.append(write_bodies(res.surroundings, output, slice(None, None, every)))
    except KeyboardInterrupt:
        from cablelife.interrupt import interrupted

        done = ", ".join(map(str, written)) or "none"
        raise interrupted(f"complete time series: {done}; frame files of the others kept") from None
    except (ValueError, FileNotFoundError, OSError) as e:
        print_error(err, e)
        raise typer.Exit(2) from None
    for p in written:
        make_console().print(escape(f"ParaView time series written to {p}"))
