"""``cablelife report RESULT.h5 [DAMAGE.h5 …] -o report.html``."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Annotated

import typer


def is_result_file(path: Path) -> bool:
    """True for a cablelife result file (HDF5 with format = cablelife-result)."""
    import h5py

    from cablelife.results import FORMAT

    if path.is_dir():
        raise ValueError(f"{str(path)!r} is a directory; give result and damage files")
    try:
        with h5py.File(path, "r") as f:
            return f.attrs.get("format") == FORMAT
    except OSError:
        raise ValueError(
            f"{str(path)!r} is not a readable HDF5 file (truncated, empty or of another kind)"
        ) from None


def _made_from(source: str, damage: Path, result: Path) -> bool:
    """Whether a damage file's ``source`` (the result path given to ``cablelife lda``) names
    ``result``: the same file seen from here or from the damage file's folder."""
    if not source:
        return False
    src = Path(source)
    for base in (Path.cwd(), damage.parent):
        q = src if src.is_absolute() else base / src
        if q.exists() and q.resolve() == result.resolve():
            return True
    return False


def attach_damage(results: list[Path], damages: list[tuple[Path, object]]) -> dict[int, object]:
    """Result index → damage analysis: a damage file goes to the result it was made from (its
    ``source``), the others to the remaining results in order."""
    attached: dict[int, object] = {}
    rest = []
    for path, analysis in damages:
        hits = [i for i, r in enumerate(results) if _made_from(analysis.source, path, r)]
        if len(hits) == 1 and hits[0] not in attached:
            attached[hits[0]] = analysis
        else:
            rest.append((path, analysis))
    free = [i for i in range(len(results)) if i not in attached]
    if len(rest) > len(free):
        raise ValueError(
            f"{len(damages)} damage files for {len(results)} results: give at most one "
            "damage file per result (matched by the result it was made from, else in order)"
        )
    attached.update((i, a) for i, (_, a) in zip(free, rest, strict=False))
    return attached


def report_runs(files: list[Path]):
    """Result files become runs (labelled by file stem); each damage file (``cablelife lda``)
    is attached to the result it was made from, else to the results in order."""
    from cablelife.lda.io import is_damage_file, load_damage
    from cablelife.report.html import ReportRun
    from cablelife.results import load_result

    results, damages = [], []
    for p in files:
        if not p.exists():
            raise FileNotFoundError(f"file {str(p)!r} does not exist")
        if is_result_file(p):
            results.append(p)
        elif is_damage_file(p):
            damages.append((p, load_damage(p)))
        else:
            raise ValueError(
                f"{str(p)!r} is not a cablelife result file nor a damage file (format "
                "attribute); give RESULT.h5 files and their damage files (cablelife lda)"
            )
    if not results:
        raise ValueError("files: give at least one result file (RESULT.h5)")
    attached = attach_damage(results, damages)
    runs = []
    for k, p in enumerate(results):
        stem = (
            p.stem if [q.stem for q in results].count(p.stem) == 1 else f"{p.parent.name}/{p.stem}"
        )
        runs.append(ReportRun(stem, load_result(p), attached.get(k)))
    return runs


def report_command(
    files: Annotated[
        list[Path],
        typer.Argument(
            help="result files and damage files (cablelife lda), each matched to its result"
        ),
    ],
    output: Annotated[Path, typer.Option("-o", "--output", help="HTML file")] = Path("report.html"),
    color_by: Annotated[
        str, typer.Option(help="tube colour: shear, tension, bending or torsion")
    ] = "bending",
    frames: Annotated[int, typer.Option(help="animation frames of the 3D view")] = 24,
    voxel: Annotated[str, typer.Option(help="voxel of the motion volumes ('none': skip)")] = "4mm",
    bend_factor: Annotated[
        float, typer.Option(help="bend radius rule: at least this × the diameter")
    ] = 10.0,
) -> None:
    """Write a self-contained HTML report (works offline) of one or several runs."""
    from cablelife.clitext import console as make_console
    from cablelife.clitext import escape, print_error, printed_warnings
    from cablelife.report.html import write_report
    from cablelife.volume.cli import parse_length

    err = make_console(stderr=True)
    try:
        if not (math.isfinite(bend_factor) and bend_factor > 0):
            raise ValueError(f"--bend-factor = {bend_factor}: allowed: a number > 0")
        h = None if voxel.strip().lower() == "none" else parse_length(voxel)
        with printed_warnings(err), err.status("reading the runs") as status:  # partial results
            runs = report_runs(files)
            path = write_report(
                output,
                runs,
                color_by=color_by,
                frames=frames,
                voxel=h,
                bend_factor=bend_factor,
                on_step=lambda what: status.update(f"report: {what}"),
            )
    except KeyboardInterrupt:
        from cablelife.interrupt import interrupted

        raise interrupted("no report written") from None
    except (ValueError, FileNotFoundError, OSError) as e:
        print_error(err, e)
        raise typer.Exit(2) from None
    size = path.stat().st_size / 1e6
    make_console().print(escape(f"report written to {path} ({size:.1f} MB)"))
