"""Files named inside scenes (measured signals, ``motion_file``, later meshes): one rule.

A relative name is taken from the scene's folder. A file outside that folder (an absolute
path elsewhere, or ``../``) is refused unless the user allows it explicitly: the scene key
``[files] allow_outside = true`` or the CLI flag ``--allow-outside-files``. A scene handed to
someone else therefore cannot make cablelife read, and quote in its messages, files such as
``/etc/passwd``. Messages name the item and the path, never the file's content.
"""

from __future__ import annotations

import os
from pathlib import Path


class SceneFileError(ValueError):
    """A file named in a scene that may not or cannot be read."""


ALLOW_OUTSIDE_HELP = (
    "read files named in the scene (measured signals, motion_file) also outside the scene's folder"
)
ALLOW_HINT = (
    "files outside the scene's folder are read only when allowed: set [files] allow_outside = "
    "true in the scene or pass --allow-outside-files"
)


def resolve_scene_file(
    scene_dir: str | os.PathLike | None,
    path: str | os.PathLike,
    allow_outside: bool = False,
    item: str = "file",
) -> Path:
    """The file ``path`` named by ``item`` (e.g. ``bodies[0].motion_file``) of a scene in
    ``scene_dir``: relative names resolved against the folder; outside it only when
    ``allow_outside``. Without a ``scene_dir`` (scenes built in Python) ``path`` is used as is.
    Raises :class:`SceneFileError` for a refused, missing or non-regular file."""
    p = Path(path)
    if scene_dir is not None:
        base = Path(scene_dir).resolve()
        full = (p if p.is_absolute() else base / p).resolve()
        if not allow_outside and not full.is_relative_to(base):
            raise SceneFileError(
                f"{item} = {str(path)!r} is outside the scene's folder {str(base)!r}; {ALLOW_HINT}"
            )
        p = full
    if p.is_dir():
        raise SceneFileError(f"{item} = {str(path)!r} is a directory; allowed: a file")
    if not p.exists():
        looked = f" (looked for {str(p)!r})" if str(p) != str(path) else ""
        raise SceneFileError(f"{item} = {str(path)!r} does not exist{looked}")
    if not p.is_file():
        raise SceneFileError(f"{item} = {str(path)!r} is not a regular file")
    return p


def shown_names(names, limit: int = 12, width: int = 32) -> str:
    """Column or channel names for a message: at most ``limit`` names of at most ``width``
    characters each (a header of a foreign file is not echoed whole)."""
    shown = []
    for n in list(names)[:limit]:
        n = str(n)
        shown.append(repr(n if len(n) <= width else n[: width - 1] + "…"))
    more = len(list(names)) - limit
    return ", ".join(shown) + (f" and {more} more" if more > 0 else "")
