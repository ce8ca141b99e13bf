"""Shared harness of the bad-input suite (tests/test_bad_input_*.py).

Every case runs the real command line (typer's CliRunner in process; a sample in real
subprocesses) and asserts what a user must get for bad input: the documented exit code, a
message naming the item, no traceback, no Rust panic, no markup eaten, and no NaN in any file
written. ``CASES_RUN`` counts the cases run in this session (printed at the end of the suite).
"""

from __future__ import annotations

import copy
import os
import subprocess
import sys
from pathlib import Path

import h5py
import numpy as np
import tomli_w
from conftest import BASE

PANIC = ("Traceback", "panicked", "RUST_BACKTRACE", "memory allocation", "core dumped")
CASES_RUN: list[str] = []


def scene(**changes) -> dict:
    """The two-clip hose scene (conftest.BASE) as a fresh dict."""
    d = copy.deepcopy(BASE)
    d.update(changes)
    return d


def write_scene(folder: Path, data: dict | str | bytes, name: str = "scene.toml") -> Path:
    path = folder / name
    if isinstance(data, bytes):
        path.write_bytes(data)
    elif isinstance(data, str):
        path.write_text(data)
    else:
        path.write_text(tomli_w.dumps(data))
    return path


def _nan_in(path: Path) -> str | None:
    """A description of the first NaN in an output file (HDF5, CSV, VTK, HTML), else None."""
    if not path.is_file():
        return None
    if path.suffix in (".h5", ".hdf5"):
        found = []

        def visit(name, obj):
            if isinstance(obj, h5py.Dataset) and obj.dtype.kind == "f" and obj.size < 10**8:
                data = obj[()]
                if not np.all(np.isfinite(data)) and "solver" not in name:
                    found.append(name)

        with h5py.File(path, "r") as f:
            f.visititems(visit)
        return found[0] if found else None
    if path.suffix in (".csv", ".vtp", ".pvd", ".vtk", ".stl", ".ply"):
        text = path.read_bytes()[:50_000_000].decode("latin-1").lower()
        for word in ("nan", "inf"):
            if f" {word}" in text or f",{word}" in text or f"\n{word}" in text:
                return word
    return None


def check_output(text: str, code: int, expect: tuple[str, ...], exit_code: int, case: str) -> None:
    assert exit_code == code, f"{case}: exit code {exit_code}, expected {code}\n{text}"
    for bad in PANIC:
        assert bad not in text, f"{case}: {bad!r} in the output\n{text}"
    for e in expect:
        assert e in text, f"{case}: {e!r} not in the output\n{text}"


def cli(
    args: list,
    expect: tuple[str, ...] = (),
    code: int = 2,
    outputs: tuple[Path, ...] = (),
    case: str = "",
) -> str:
    """Runs ``cablelife ARGS`` in process; asserts exit code, message, no traceback, no NaN
    in ``outputs`` (and no output at all when the command failed)."""
    from cablelife.cli import app
    from typer.testing import CliRunner

    CASES_RUN.append(case or " ".join(map(str, args)))
    res = CliRunner().invoke(app, [str(a) for a in args])
    text = res.output
    if res.exception is not None and not isinstance(res.exception, SystemExit):
        import traceback

        tb = "".join(traceback.format_exception(res.exception))
        raise AssertionError(f"{case}: uncaught {type(res.exception).__name__}\n{text}\n{tb}")
    check_output(text, code, expect, res.exit_code, case)
    for p in outputs:
        if code != 0:
            assert not Path(p).exists() or Path(p).is_dir(), f"{case}: {p} written on failure"
        else:
            assert _nan_in(Path(p)) is None, f"{case}: NaN in {p}"
    return text


def cli_subprocess(
    args: list, expect: tuple[str, ...] = (), code: int = 2, timeout: float = 60, case: str = ""
) -> str:
    """Runs ``python -m cablelife ARGS`` in a real process (aborts, allocations, hangs)."""
    CASES_RUN.append(case or " ".join(map(str, args)))
    env = dict(os.environ, COLUMNS="200")
    proc = subprocess.run(
        [sys.executable, "-m", "cablelife", *map(str, args)],
        capture_output=True,
        text=True,
        timeout=timeout,
        env=env,
    )
    text = proc.stdout + proc.stderr
    assert proc.returncode >= 0, f"{case}: killed by signal {-proc.returncode}\n{text}"
    check_output(text, code, expect, proc.returncode, case)
    return text
