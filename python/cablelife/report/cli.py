"""``cablelife report RESULT.h5 [DAMAGE.h5 …] -o report.html``."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer


def is_result_file(path: Path) -> bool:
    """True for a cablelife result file (HDF5 with format = cablelife-result)."""
    import h5py

    from cablelife.results import FORMAT

    try:
        with h5py.File(path, "r") as f:
            return f.attrs.get("format") == FORMAT
    except OSError as e:
        raise ValueError(f"{str(path)!r} is not a readable HDF5 file: {e}") from None


def report_runs(files: list[Path]):
    """Result files become runs (labelled by file stem); damage files are attached to the
    results in order: the k-th damage file to the k-th result."""
    from cablelife.plots.fatigue_data import load_damage
    from cablelife.report.html import ReportRun
    from cablelife.results import load_result

    results, damages = [], []
    for p in files:
        if not p.exists():
            raise FileNotFoundError(f"file {str(p)!r} does not exist")
        (results if is_result_file(p) else damages).append(p)
    if not results:
        raise ValueError("files: give at least one result file (RESULT.h5)")
    if len(damages) > len(results):
        raise ValueError(
            f"{len(damages)} damage files for {len(results)} results: give at most one "
            "damage file per result, in the same order"
        )
    runs = []
    for k, p in enumerate(results):
        stem = (
            p.stem if [q.stem for q in results].count(p.stem) == 1 else f"{p.parent.name}/{p.stem}"
        )
        damage = load_damage(damages[k]) if k < len(damages) else {}
        runs.append(ReportRun(stem, load_result(p), damage))
    return runs


def report_command(
    files: Annotated[
        list[Path], typer.Argument(help="result files, then damage files in the same order")
    ],
    output: Annotated[Path, typer.Option("-o", "--output", help="HTML file")] = Path("report.html"),
    color_by: Annotated[
        str, typer.Option(help="tube colour: shear, tension, bending or torsion")
    ] = "bending",
    frames: Annotated[int, typer.Option(help="animation frames of the 3D view")] = 40,
    voxel: Annotated[str, typer.Option(help="voxel of the motion volumes ('none': skip)")] = "4mm",
    bend_factor: Annotated[
        float, typer.Option(help="bend radius rule: at least this × the diameter")
    ] = 10.0,
) -> None:
    """Write a self-contained HTML report (works offline) of one or several runs."""
    from rich.console import Console

    from cablelife.report.html import write_report
    from cablelife.volume.cli import parse_length

    err = Console(stderr=True)
    try:
        h = None if voxel.strip().lower() == "none" else parse_length(voxel)
        runs = report_runs(files)
        path = write_report(
            output, runs, color_by=color_by, frames=frames, voxel=h, bend_factor=bend_factor
        )
    except (ValueError, FileNotFoundError) as e:
        err.print(f"[bold red]error:[/] {e}", highlight=False)
        raise typer.Exit(2) from None
    size = path.stat().st_size / 1e6
    Console().print(f"report written to {path} ({size:.1f} MB)")
