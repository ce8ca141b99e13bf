"""The HDF5 files of cablelife (results, damage maps): written atomically, opened with a check
of their ``format`` attribute, attributes read back as plain Python values."""

from __future__ import annotations

import os
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from cablelife.atomic import atomic_path

if TYPE_CHECKING:
    import h5py


@contextmanager
def atomic_h5(path: str | os.PathLike) -> Iterator[h5py.File]:
    """An ``h5py.File`` on a temporary file that replaces ``path`` on success and is removed on
    failure."""
    import h5py

    with atomic_path(path) as tmp, h5py.File(tmp, "w") as f:
        yield f


@contextmanager
def open_h5(path: str | os.PathLike, fmt: str, what: str) -> Iterator[h5py.File]:
    """Opens a cablelife file for reading; clear errors when it is missing or of another kind."""
    import h5py

    path = Path(path)
    if path.is_dir():
        raise ValueError(f"{what} file {str(path)!r} is a directory; give an HDF5 file")
    if not path.exists():
        raise FileNotFoundError(f"{what} file {str(path)!r} does not exist")
    try:
        f = h5py.File(path, "r")
    except OSError:
        raise ValueError(
            f"{what} file {str(path)!r} is not a readable HDF5 file (truncated, empty or of "
            "another kind)"
        ) from None
    with f:
        try:
            found = f.attrs.get("format")
        except OSError:
            found = None
        if found != fmt:
            raise ValueError(f"{str(path)!r} is not a cablelife {what} file (format attribute)")
        yield f


def plain(value):
    """An HDF5 attribute as a plain Python value (numpy scalars → numbers, bytes → str)."""
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, bytes):
        return value.decode()
    return value
