"""Files named in scenes."""

from __future__ import annotations

from pathlib import Path


def resolve_scene_file(base_dir: Path | None, name: str) -> Path:
    """The file ``name`` of a scene: relative to the scene's folder (absolute paths as given).

    To be switched at merge to the scene-file helper of input validation (which also refuses
    paths outside the scene folder unless allowed).
    """
    path = Path(name).expanduser()
    if not path.is_absolute() and base_dir is not None:
        path = Path(base_dir) / path
    return path
