"""Reading the project's TOML inputs (scenes, signal specs, study files) with clear errors."""

from __future__ import annotations

import tomllib
from pathlib import Path

# Larger input files are not scenes, signal specs or study files (those are a few kB; tables
# of samples belong in measured-signal files).
MAX_TOML_BYTES = 16 * 2**20
# Deeper nesting than this is no cablelife input (a scene nests about 5 levels).
MAX_TOML_DEPTH = 32


def _depth(value, level: int = 0) -> int:
    """The nesting depth of parsed TOML (tables and arrays), iteratively."""
    deepest, stack = level, [(value, level)]
    while stack:
        v, d = stack.pop()
        deepest = max(deepest, d)
        if isinstance(v, dict):
            stack.extend((x, d + 1) for x in v.values())
        elif isinstance(v, list):
            stack.extend((x, d + 1) for x in v)
    return deepest


def read_toml(path: str | Path, what: str, error: type[Exception]) -> dict:
    """The top-level table of a TOML file; raises ``error`` naming the file as ``what`` (e.g.
    "scene file") when it does not exist, is a directory, is not UTF-8 text, is not valid TOML
    or is nested absurdly deep."""
    path = Path(path)
    shown = repr(str(path))
    if path.is_dir():
        raise error(f"{what} {shown} is a directory; give a TOML file")
    if not path.exists():
        raise error(f"{what} {shown} does not exist")
    try:
        size = path.stat().st_size
        if size > MAX_TOML_BYTES:
            raise error(
                f"{what} {shown} has {size / 2**20:.0f} MiB; allowed: at most "
                f"{MAX_TOML_BYTES // 2**20} MiB of TOML text"
            )
        raw = path.read_bytes()
    except OSError as err:
        raise error(f"{what} {shown} cannot be read ({err.strerror or err})") from None
    if b"\x00" in raw:
        raise error(f"{what} {shown} is a binary file, not TOML text")
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as err:
        raise error(
            f"{what} {shown} is not UTF-8 text (invalid byte at offset {err.start}); "
            "save it as UTF-8"
        ) from None
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as err:
        raise error(f"{what} {shown} is not valid TOML: {err}") from None
    except RecursionError:
        raise error(
            f"{what} {shown} is nested too deeply; allowed: at most {MAX_TOML_DEPTH} levels"
        ) from None
    if _depth(data) > MAX_TOML_DEPTH:
        raise error(
            f"{what} {shown} is nested {_depth(data)} levels deep; allowed: at most "
            f"{MAX_TOML_DEPTH} levels"
        )
    return data
