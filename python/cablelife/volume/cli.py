"""``cablelife volume``: the motion volume of a result as STL/PLY, optionally compared with a
second result."""

from __future__ import annotations

import re
from pathlib import Path
from typing import Annotated

import typer

_LENGTH = re.compile(r"^\s*([0-9]*\.?[0-9]+(?:[eE][-+]?[0-9]+)?)\s*(mm|cm|m)?\s*$")
_TO_M = {"mm": 1e-3, "cm": 1e-2, "m": 1.0, None: 1e-3}


def parse_length(text: str, what: str = "voxel") -> float:
    """A length such as ``2mm``, ``0.5 cm``, ``0.002m`` in m; a bare number is in mm."""
    m = _LENGTH.match(str(text))
    if not m or float(m.group(1)) <= 0:
        raise ValueError(
            f"{what} = {text!r}: must be a positive length like '2mm', '0.5cm' or '0.002m' "
            "(a bare number is in mm)"
        )
    return float(m.group(1)) * _TO_M[m.group(2)]


def _fmt_box(box) -> str:
    lo, hi = box * 1e3
    return (
        f"[{lo[0]:.1f}, {hi[0]:.1f}] × [{lo[1]:.1f}, {hi[1]:.1f}] × [{lo[2]:.1f}, {hi[2]:.1f}] mm"
    )


def volume_command(
    result: Annotated[Path, typer.Argument(help="result HDF5 file")],
    voxel: Annotated[str, typer.Option(help="voxel size, e.g. 2mm")] = "2mm",
    output: Annotated[Path, typer.Option("-o", "--output", help="mesh file (.stl or .ply)")] = Path(
        "volume.stl"
    ),
    compare: Annotated[
        Path | None, typer.Option(help="second result: compare the two volumes")
    ] = None,
    cable: Annotated[str | None, typer.Option(help="only this cable (default: all)")] = None,
    unit: Annotated[str, typer.Option(help="length unit in the mesh file: m or mm")] = "m",
) -> None:
    """Motion volume (union of the tube over all saved steps) as a watertight mesh."""
    from rich.progress import Progress
    from rich.table import Table

    from cablelife.clitext import console as make_console
    from cablelife.clitext import escape, print_error, printed_warnings
    from cablelife.results import load_result
    from cablelife.volume.compare import compare_volumes
    from cablelife.volume.motion import motion_volume

    console = make_console()
    err = make_console(stderr=True)

    def source(path: Path):
        res = load_result(path)
        if cable is None:
            return res
        if cable not in res.cables:
            raise ValueError(
                f"cable = {cable!r}: {str(path)!r} has cables {', '.join(map(repr, res.cables))}"
            )
        return res.cables[cable]

    a_saved = False
    bar = Progress(console=err, transient=True)

    def rows(label: str):
        task = bar.add_task(escape(f"distance field of {label}"), total=None)
        return lambda done, total: bar.update(task, completed=done, total=total)

    try:
        if unit not in ("m", "mm"):
            raise ValueError(f"unit = {unit!r}: allowed: 'm' or 'mm'")
        h = parse_length(voxel)
        with bar, printed_warnings(err):
            a = motion_volume(source(result), h, progress=rows(result.name))
            a.save(output, unit=unit)
            a_saved = True
            b = None
            if compare is not None:
                b = motion_volume(source(compare), h, progress=rows(compare.name))
    except KeyboardInterrupt:
        from cablelife.interrupt import interrupted

        kept = f"the mesh was saved to {output}" if a_saved else "no mesh written"
        raise interrupted(kept) from None
    except (ValueError, FileNotFoundError, OSError) as e:
        print_error(err, e)
        raise typer.Exit(2) from None
    t = Table(title=f"motion volume at {h * 1e3:g} mm voxels", title_justify="left")
    t.add_column("run")
    t.add_column(escape("volume [l]"), justify="right")
    t.add_column("bounding box")
    t.add_row(escape(result.name), f"{a.litres:.4g}", escape(_fmt_box(a.bounding_box)))
    if b is not None:
        t.add_row(escape(compare.name), f"{b.litres:.4g}", escape(_fmt_box(b.bounding_box)))
    console.print(t)
    if b is not None:
        c = compare_volumes(a, b)
        v = c.volumes
        ct = Table(title="comparison (A = first, B = --compare)", title_justify="left")
        ct.add_column("quantity")
        ct.add_column("value", justify="right")
        for key, label in [
            ("union", "A ∪ B"),
            ("intersection", "A ∩ B"),
            ("a_minus_b", "A ∖ B"),
            ("b_minus_a", "B ∖ A"),
        ]:
            ct.add_row(f"volume {label}", f"{v[key] * 1e3:.4g} l")
        ct.add_row("A sticks out of B by", f"{c.a_beyond_b.distance * 1e3:.2f} mm")
        ct.add_row("B sticks out of A by", f"{c.b_beyond_a.distance * 1e3:.2f} mm")
        console.print(ct)
    res = load_result(result)
    if res.surroundings is not None:
        from cablelife.surroundings.volume import volume_vs_surroundings

        st = Table(title="motion volume relative to each body (all cables)", title_justify="left")
        st.add_column("body")
        st.add_column(escape("least distance [mm]"), justify="right")
        st.add_column(escape("volume inside the body [l]"), justify="right")
        # the motion volume just computed is that of every cable over every step (no --cable)
        for chk in volume_vs_surroundings(res, h, motion=a if cable is None else None):
            st.add_row(
                escape(chk.body), f"{chk.min_distance * 1e3:.2f}", f"{chk.intersection * 1e3:.4g}"
            )
        console.print(st)
    console.print(escape(f"mesh saved to {output}"))
