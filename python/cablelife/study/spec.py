"""The study file: a base scene, the parameters to vary, how to combine them, the run mode and
the fatigue-analysis settings (TOML, validated with pydantic)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Literal

from pydantic import BaseModel, ConfigDict, Field, ValidationError, model_validator

from cablelife.lda.settings import LdaSettings
from cablelife.scene import format_validation_errors
from cablelife.scene_types import Flag, NonNegativeFloat, PositiveFloat, PositiveInt, Real, Vec3
from cablelife.tomlfile import read_toml

ParameterName = Annotated[str, Field(min_length=1, pattern=r"^[A-Za-z_][A-Za-z0-9_\-]*$")]


class StudyError(ValueError):
    """An unusable study file or parameter."""


class _Model(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class _Parameter(_Model):
    name: ParameterName
    values: list[Real] = []  # the grid values (combine = "grid")


class ClipPosition(_Parameter):
    """Shift a clip's position by ``value`` metres along ``direction`` (default: the clip's
    cable direction), in the clip's frame (global or body). ``slide = true`` also moves the
    clip's arc length ``s`` by the same value: the clip slides along the cable's route."""

    kind: Literal["clip_position"]
    cable: str | None = None
    clip: str
    direction: Vec3 | None = None
    slide: Flag = False


class CableLength(_Parameter):
    """Set the cable length (m). The added length goes into the span after clip ``after_clip``
    (default: the longest span): the clips beyond it keep their distance to the cable's end."""

    kind: Literal["cable_length"]
    cable: str | None = None
    after_clip: str | None = None


class MaterialValue(_Parameter):
    """Set one value of the cable's material (or measured stiffness), e.g. youngs_modulus."""

    kind: Literal["material"]
    cable: str | None = None
    field: str


class ExcitationLevel(_Parameter):
    """Scale a body's motion by ``value`` (all channels, or those in ``channels``): PSD and
    measured signals by their ``scale``, sines and sweeps by their amplitude, tables by their
    values."""

    kind: Literal["excitation"]
    body: str
    channels: list[Literal["x", "y", "z", "rx", "ry", "rz"]] | None = None


class SceneValue(_Parameter):
    """Set any scene value by its path: dotted keys, list entries by their ``name`` or index,
    e.g. ``cables.harness.clips.body-2.s`` or ``simulation.time_step``."""

    kind: Literal["set"]
    path: Annotated[str, Field(min_length=1)]


Parameter = Annotated[
    ClipPosition | CableLength | MaterialValue | ExcitationLevel | SceneValue,
    Field(discriminator="kind"),
]


class VolumeSettings(_Model):
    """Motion volume per variant (its size goes into the summary); voxel 0 switches it off.
    At most ``max_steps`` saved steps are swept (every k-th step of longer runs)."""

    voxel: NonNegativeFloat = 0.004  # m
    max_steps: PositiveInt = 1000


class StudySettings(_Model):
    scene: Path  # the base scene, relative to the study file
    name: str | None = None
    mode: Literal["static", "quasistatic", "dynamic"] | None = None  # default: the scene's
    duration: PositiveFloat | None = None  # s, overrides simulation.duration
    combine: Literal["grid", "list"] = "grid"
    threads: PositiveInt = 1  # threads per variant (LDA kernels)


class StudyFile(_Model):
    """A whole study file."""

    study: StudySettings
    lda: LdaSettings = LdaSettings()
    volume: VolumeSettings = VolumeSettings()
    parameters: Annotated[list[Parameter], Field(min_length=1)]
    variants: list[dict[str, Real | str]] = []

    @model_validator(mode="after")
    def _check(self) -> StudyFile:
        names = [p.name for p in self.parameters]
        dup = sorted({n for n in names if names.count(n) > 1})
        if dup:
            raise ValueError(f"parameter names must be unique; repeated: {dup}")
        if self.study.combine == "grid":
            if self.variants:
                raise ValueError(
                    "[[variants]] are only read with study.combine = 'list'; "
                    "with 'grid' every parameter lists its values"
                )
            empty = [p.name for p in self.parameters if not p.values]
            if empty:
                raise ValueError(f"parameters {empty} have no values; a grid needs values")
        else:
            if not self.variants:
                raise ValueError("study.combine = 'list' needs [[variants]] tables")
            for i, v in enumerate(self.variants):
                unknown = sorted(set(v) - set(names) - {"name"})
                if unknown:
                    raise ValueError(
                        f"variants[{i}] sets {unknown}, which are not parameters; "
                        f"allowed: 'name' and {names}"
                    )
                for k, x in v.items():
                    if k != "name" and isinstance(x, str):
                        raise ValueError(f"variants[{i}].{k} = {x!r}: must be a number")
        return self


def load_study(path: str | Path) -> tuple[StudyFile, Path]:
    """Reads and validates a study file; returns it with its directory (for relative paths)."""
    path = Path(path)
    data = read_toml(path, "study file", StudyError)
    try:
        study = StudyFile.model_validate(data)
    except ValidationError as err:
        raise StudyError(format_validation_errors(err, f"{str(path)!r}", "study")) from None
    return study, path.parent.resolve()
