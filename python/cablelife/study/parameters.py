"""Apply a study parameter's value to a scene (as the dict parsed from its TOML)."""

from __future__ import annotations

import math

import numpy as np

from cablelife.scene import Material, MeasuredStiffness
from cablelife.study.spec import (
    CableLength,
    ClipPosition,
    ExcitationLevel,
    MaterialValue,
    Parameter,
    SceneValue,
    StudyError,
)


def _named(items: list, name: str, what: str, where: str) -> dict:
    for item in items:
        if isinstance(item, dict) and item.get("name") == name:
            return item
    names = [i.get("name") for i in items if isinstance(i, dict)]
    raise StudyError(f"{where}: no {what} named {name!r}; the scene has {names}")


def _cable(scene: dict, name: str | None, param: str) -> dict:
    cables = scene.get("cables", [])
    if name is None:
        if len(cables) != 1:
            raise StudyError(
                f"parameter {param!r}: the scene has {len(cables)} cables; say which (cable = ...)"
            )
        return cables[0]
    return _named(cables, name, "cable", f"parameter {param!r}")


def _shift_clip(scene: dict, p: ClipPosition, value: float) -> None:
    clip = _named(
        _cable(scene, p.cable, p.name).get("clips", []), p.clip, "clip", f"parameter {p.name!r}"
    )
    direction = np.asarray(p.direction if p.direction is not None else clip["direction"], float)
    norm = float(np.linalg.norm(direction))
    if not norm > 0:
        raise StudyError(f"parameter {p.name!r}: direction {list(direction)} has zero length")
    clip["position"] = (np.asarray(clip["position"], float) + value * direction / norm).tolist()
    if p.slide:
        clip["s"] = float(clip["s"]) + value


def _set_length(scene: dict, p: CableLength, value: float) -> None:
    cable = _cable(scene, p.cable, p.name)
    clips = sorted(cable.get("clips", []), key=lambda c: float(c["s"]))
    if p.after_clip is not None:
        start = float(_named(clips, p.after_clip, "clip", f"parameter {p.name!r}")["s"])
    elif len(clips) >= 2:
        gaps = [float(b["s"]) - float(a["s"]) for a, b in zip(clips, clips[1:], strict=False)]
        start = float(clips[int(np.argmax(gaps))]["s"])
    else:
        start = math.inf  # one clip: the length changes at the free end
    delta = value - float(cable["length"])
    cable["length"] = value
    for item in [*cable.get("clips", []), *cable.get("loads", [])]:
        if float(item["s"]) > start:
            item["s"] = float(item["s"]) + delta


_MATERIAL_FIELDS = set(Material.model_fields)
_STIFFNESS_FIELDS = set(MeasuredStiffness.model_fields)


def _set_material(scene: dict, p: MaterialValue, value: float) -> None:
    cable = _cable(scene, p.cable, p.name)
    table, allowed = (
        ("material", _MATERIAL_FIELDS)
        if "material" in cable
        else (
            "stiffness",
            _STIFFNESS_FIELDS,
        )
    )
    if table not in cable:
        raise StudyError(f"parameter {p.name!r}: cable has neither material nor stiffness")
    if p.field not in allowed:
        raise StudyError(
            f"parameter {p.name!r}: field {p.field!r} is not a value of the cable's {table}; "
            f"allowed: {sorted(allowed)}"
        )
    cable[table][p.field] = value


def _scale_signal(signal: dict, factor: float, where: str) -> None:
    kind = signal.get("type")
    if kind in ("psd", "measured"):
        signal["scale"] = float(signal.get("scale", 1.0)) * factor
    elif kind in ("sine", "sweep"):
        signal["amplitude"] = float(signal["amplitude"]) * factor
    elif kind == "table":
        signal["values"] = [float(v) * factor for v in signal["values"]]
    else:
        raise StudyError(f"{where}: cannot scale a signal of type {kind!r}")


def _scale_excitation(scene: dict, p: ExcitationLevel, value: float) -> None:
    body = _named(scene.get("bodies", []), p.body, "body", f"parameter {p.name!r}")
    if "motion_file" in body:
        raise StudyError(
            f"parameter {p.name!r}: body {p.body!r} moves by a motion_file, which cannot be "
            "scaled; give its channels as signals (type = 'measured' or 'table')"
        )
    channels = [
        m for m in body.get("motion", []) if p.channels is None or m["channel"] in p.channels
    ]
    if not channels:
        raise StudyError(f"parameter {p.name!r}: body {p.body!r} has no motion to scale")
    if value < 0:
        raise StudyError(f"parameter {p.name!r}: excitation factor {value} must be >= 0")
    for m in channels:
        _scale_signal(m["signal"], value, f"parameter {p.name!r}, channel {m['channel']!r}")


def _set_path(scene: dict, p: SceneValue, value: float) -> None:
    keys = p.path.split(".")
    node = scene
    for i, key in enumerate(keys):
        last = i == len(keys) - 1
        where = ".".join(keys[: i + 1])
        if isinstance(node, list):
            if key.isdigit() and int(key) < len(node):
                idx = int(key)
            else:
                item = _named(node, key, "entry", f"parameter {p.name!r} ({p.path})")
                idx = node.index(item)
            if last:
                node[idx] = value
            node = node[idx]
        elif isinstance(node, dict):
            if last:
                node[key] = value
            elif key not in node:
                raise StudyError(
                    f"parameter {p.name!r}: the scene has no {where!r}; "
                    f"allowed keys there: {sorted(node)}"
                )
            else:
                node = node[key]
        else:
            raise StudyError(f"parameter {p.name!r}: {where!r} is not a table or a list")


_APPLY = {
    "clip_position": _shift_clip,
    "cable_length": _set_length,
    "material": _set_material,
    "excitation": _scale_excitation,
    "set": _set_path,
}


def apply_parameter(scene: dict, parameter: Parameter, value: float) -> None:
    """Changes ``scene`` (a scene dict) in place: shifts (clip_position) and factors
    (excitation) are relative to the base scene, the other kinds set absolute values."""
    if not math.isfinite(value):
        raise StudyError(f"parameter {parameter.name!r}: value {value} must be finite")
    _APPLY[parameter.kind](scene, parameter, float(value))


#: Units of material values a study may vary.
_MATERIAL_UNITS = {
    "youngs_modulus": "Pa",
    "shear_modulus": "Pa",
    "density": "kg/m³",
    "poisson_ratio": "1",
    "EA": "N",
    "GA": "N",
    "EI": "N m²",
    "EI1": "N m²",
    "EI2": "N m²",
    "GJ": "N m²",
    "mass_per_length": "kg/m",
}


def parameter_axis(parameter: Parameter) -> str:
    """An axis label of a parameter with its unit (when the kind tells it)."""
    unit = {
        "clip_position": "m, shift",
        "cable_length": "m",
        "excitation": "× the base motion",
    }.get(parameter.kind)
    if parameter.kind == "material":
        unit = _MATERIAL_UNITS.get(parameter.field)
    if parameter.kind == "set" and parameter.path.endswith(("time_step", "duration", ".s")):
        unit = "s" if "simulation" in parameter.path else "m"
    return f"{parameter.name} [{unit}]" if unit else parameter.name
