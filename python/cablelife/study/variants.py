"""The variants of a study: every combination of the parameter values (grid) or the listed
ones, each with its own scene (validated before anything runs)."""

from __future__ import annotations

import copy
import hashlib
import itertools
import json
import re
from dataclasses import dataclass
from pathlib import Path

from cablelife.scene import Scene, SceneError, scene_from_dict
from cablelife.study.parameters import apply_parameter
from cablelife.study.spec import StudyError, StudyFile
from cablelife.tomlfile import read_toml


@dataclass(frozen=True)
class Variant:
    """One variant: its name (also its directory), parameter values and scene (a dict)."""

    name: str
    values: dict[str, float]
    scene: dict
    base_dir: Path
    mode: str

    def row(self) -> dict:
        """The first columns of its summary row: name, parameter values, mode."""
        return {"variant": self.name, **self.values, "mode": self.mode}

    def validated(self) -> Scene:
        return scene_from_dict(self.scene, self.base_dir, f"of variant {self.name!r}")

    def fingerprint(self, settings: dict) -> str:
        """A hash of everything that determines the variant's results: a finished variant with
        the same fingerprint is not computed again."""
        text = json.dumps(
            {"scene": self.scene, "mode": self.mode, "settings": settings}, sort_keys=True
        )
        return hashlib.sha256(text.encode()).hexdigest()[:16]


def _safe(text: str) -> str:
    return re.sub(r"[^A-Za-z0-9_.=+\-]", "_", text)


def _grid_name(values: dict[str, float]) -> str:
    return _safe("_".join(f"{k}={v:g}" for k, v in values.items()))


def base_scene(
    study: StudyFile, study_dir: Path, allow_outside_files: bool = False
) -> tuple[dict, Path]:
    """The base scene dict with the study's mode/duration overrides, and its directory;
    ``allow_outside_files`` sets the scene's ``files.allow_outside`` (CLI flag)."""
    path = study.study.scene if study.study.scene.is_absolute() else study_dir / study.study.scene
    data = read_toml(path, "study.scene: scene file", StudyError)
    if allow_outside_files:
        files = data.setdefault("files", {})
        if isinstance(files, dict):
            files["allow_outside"] = True
    sim = data.setdefault("simulation", {})
    if study.study.mode is not None:
        sim["mode"] = study.study.mode
    if study.study.duration is not None:
        sim["duration"] = study.study.duration
    return data, path.parent.resolve()


def expand(study: StudyFile, study_dir: Path, allow_outside_files: bool = False) -> list[Variant]:
    """All variants, each scene validated (a bad value fails here, before any run)."""
    base, scene_dir = base_scene(study, study_dir, allow_outside_files)
    params = {p.name: p for p in study.parameters}
    if study.study.combine == "grid":
        combos = [
            (None, dict(zip(params, vals, strict=True)))
            for vals in itertools.product(*(p.values for p in study.parameters))
        ]
    else:
        combos = [
            (v.get("name"), {k: float(x) for k, x in v.items() if k != "name"})
            for v in study.variants
        ]
    variants: list[Variant] = []
    for i, (name, values) in enumerate(combos):
        label = str(name) if name is not None else (_grid_name(values) or f"variant-{i + 1:03d}")
        label = _safe(label)
        scene = copy.deepcopy(base)
        for key, value in values.items():
            apply_parameter(scene, params[key], value)
        variant = Variant(
            label, values, scene, scene_dir, scene["simulation"].get("mode", "static")
        )
        try:
            variant.validated()
        except SceneError as err:
            raise StudyError(f"variant {label!r} ({values}): {err}") from None
        variants.append(variant)
    names = [v.name for v in variants]
    dup = sorted({n for n in names if names.count(n) > 1})
    if dup:
        raise StudyError(f"variant names must be unique; repeated: {dup}")
    return variants
