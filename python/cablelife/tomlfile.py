"""Reading the project's TOML inputs (scenes, signal specs, study files) with clear errors."""

from __future__ import annotations

import tomllib
from pathlib import Path


def read_toml(path: str | Path, what: str, error: type[Exception]) -> dict:
    """The top-level table of a TOML file; raises ``error`` naming the file as ``what`` (e.g.
    "scene file") when it does not exist or is not valid TOML."""
    path = Path(path)
    try:
        return tomllib.loads(path.read_text(encoding="utf-8"))
    except (FileNotFoundError, IsADirectoryError):
        raise error(f"{what} {str(path)!r} does not exist") from None
    except tomllib.TOMLDecodeError as err:
        raise error(f"{what} {str(path)!r} is not valid TOML: {err}") from None
