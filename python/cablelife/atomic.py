"""Atomic file writing: a temporary file in the target folder, flushed to disk and renamed into
place on success, removed on failure (exceptions, Ctrl-C), so that a reader never sees a
half-written file. Every file cablelife writes (results, damage maps, volumes, reports, VTK,
plots, tables) goes through :func:`atomic_path`.

The temporary file is ``.NAME.PID-RANDOM.tmp`` beside ``NAME``. A process killed outright
(SIGKILL, power loss) cannot remove it; the next write to the same target removes the ones
whose process is gone.
"""

from __future__ import annotations

import os
import re
import secrets
from collections.abc import Callable, Iterator
from contextlib import contextmanager, suppress
from pathlib import Path
from typing import IO


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def temp_name(target: Path) -> str:
    """A fresh temporary name for ``target`` (our pattern: ``.NAME.PID-RANDOM.tmp``)."""
    return f".{target.name}.{os.getpid()}-{secrets.token_hex(4)}.tmp"


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # someone else's process
        return True
    return True


def stale_temp_files(target: Path) -> list[Path]:
    """Temporary files of earlier writes to ``target`` whose process is gone: ours
    (``.NAME.PID-RANDOM.tmp``) and those of earlier versions (``.NAME.XXXXXXXX.tmp``)."""
    ours = re.compile(rf"^\.{re.escape(target.name)}\.(\d+)-[0-9a-f]{{8}}\.tmp$")
    legacy = re.compile(rf"^\.{re.escape(target.name)}\.[a-z0-9_]{{8}}\.tmp$")
    stale = []
    with suppress(OSError):
        for entry in os.scandir(target.parent):
            m = ours.match(entry.name)
            if (m and not _alive(int(m[1]))) or (not m and legacy.match(entry.name)):
                stale.append(Path(entry.path))
    return stale


def _fsync(path: Path, directory: bool = False) -> None:
    flags = os.O_RDONLY | (getattr(os, "O_DIRECTORY", 0) if directory else 0)
    try:
        fd = os.open(path, flags)
    except OSError:
        if directory:  # not every platform opens folders
            return
        raise
    try:
        os.fsync(fd)
    except OSError:
        if not directory:
            raise
    finally:
        os.close(fd)


@contextmanager
def atomic_path(path: str | os.PathLike) -> Iterator[Path]:
    """Yields a temporary path next to ``path``; when the block ends normally the file is
    flushed to disk and replaces ``path`` (with the usual file permissions), and the folder
    entry is flushed too; on any exception, Ctrl-C included, it is removed and ``path`` is left
    as it was. Stale temporary files of ``path`` are removed first."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    for old in stale_temp_files(path):
        old.unlink(missing_ok=True)
    tmp = path.parent / temp_name(path)
    try:
        fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600)
        os.close(fd)
        yield tmp
        _fsync(tmp)
        os.chmod(tmp, 0o666 & ~_umask())
        os.replace(tmp, path)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise
    _fsync(path.parent, directory=True)


def write_atomic(path: str | os.PathLike, write: Callable[[IO[bytes]], None]) -> Path:
    """Calls ``write(file)`` on a temporary binary file and moves it to ``path``."""
    with atomic_path(path) as tmp, open(tmp, "wb") as f:
        write(f)
    return Path(path)


def write_text_atomic(path: str | os.PathLike, text: str) -> Path:
    """Writes ``text`` (UTF-8) to ``path`` atomically."""
    return write_atomic(path, lambda f: f.write(text.encode("utf-8")))
