"""The scene: cables, their clips on bodies, loads, body motions and simulation settings.

A scene is a TOML file (see docs/scene.md and the JSON schema docs/scene.schema.json) or is
built in Python. Validation errors name the key path, the bad value and what is allowed.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Annotated, Literal

import numpy as np
from pydantic import (
    BaseModel,
    ConfigDict,
    Field,
    NonNegativeFloat,
    PositiveFloat,
    PositiveInt,
    ValidationError,
    field_validator,
    model_validator,
)

from cablelife import _core
from cablelife.contact_settings import ContactSettings, check_bodies
from cablelife.sections import SectionProperties, from_material, from_measured
from cablelife.signals.spec import ChannelMotion, TableSignal
from cablelife.tomlfile import read_toml

Vec3 = tuple[float, float, float]


class SceneError(ValueError):
    """A scene that cannot be used; the message says where and why."""


class _Model(BaseModel):
    model_config = ConfigDict(extra="forbid", allow_inf_nan=False)


class CircleSection(_Model):
    """Solid circular section."""

    shape: Literal["circle"]
    radius: PositiveFloat


class TubeSection(_Model):
    """Circular tube (hose)."""

    shape: Literal["tube"]
    outer_radius: PositiveFloat
    inner_radius: PositiveFloat

    @model_validator(mode="after")
    def _radii(self):
        if self.inner_radius >= self.outer_radius:
            raise ValueError(
                f"inner_radius = {self.inner_radius} must be smaller than "
                f"outer_radius = {self.outer_radius}"
            )
        return self


class Material(_Model):
    """Isotropic material: Young's modulus and Poisson's ratio (or shear modulus), density."""

    youngs_modulus: PositiveFloat  # Pa
    poisson_ratio: Annotated[float, Field(ge=0.0, le=0.5)] | None = None
    shear_modulus: PositiveFloat | None = None  # Pa
    density: PositiveFloat  # kg/m³

    @model_validator(mode="after")
    def _elastic(self):
        if (self.poisson_ratio is None) == (self.shear_modulus is None):
            raise ValueError("give exactly one of poisson_ratio and shear_modulus")
        if self.shear_modulus is not None:
            nu = self.youngs_modulus / (2 * self.shear_modulus) - 1
            if not 0.0 <= nu <= 0.5:
                raise ValueError(
                    f"shear_modulus = {self.shear_modulus} gives Poisson's ratio {nu:.3f}; "
                    "allowed is G between E/3 and E/2"
                )
        return self

    @property
    def nu(self) -> float:
        if self.poisson_ratio is not None:
            return self.poisson_ratio
        return self.youngs_modulus / (2 * self.shear_modulus) - 1


class MeasuredStiffness(_Model):
    """Effective stiffnesses as measured by cable suppliers, instead of section + material."""

    model_config = ConfigDict(extra="forbid", populate_by_name=True)
    EA: PositiveFloat  # N
    GA: PositiveFloat | None = None  # N (shear stiffness incl. shear coefficient)
    EI: PositiveFloat | None = None  # N m² (round cables)
    EI1: PositiveFloat | None = None  # N m² (non-round cables: both)
    EI2: PositiveFloat | None = None
    GJ: PositiveFloat  # N m²
    mass_per_length: PositiveFloat  # kg/m
    radius: PositiveFloat  # m, outer radius (contact, pictures, stresses)
    rotary_inertia: PositiveFloat | None = None  # kg m (ρI per length)

    @model_validator(mode="after")
    def _bending(self):
        if self.EI is None and (self.EI1 is None or self.EI2 is None):
            raise ValueError("give EI, or both EI1 and EI2")
        if self.EI is not None and (self.EI1 is not None or self.EI2 is not None):
            raise ValueError("give EI or EI1/EI2, not both")
        return self


class Clip(_Model):
    """A clip holding the cable at arc length ``s`` (the clip centre)."""

    name: Annotated[str, Field(min_length=1)]
    s: NonNegativeFloat  # m
    body: str = "world"
    position: Vec3  # m
    direction: Vec3  # cable tangent d3 at the clip
    normal: Vec3 | None = None  # d1 at the clip (fixes the twist); default: any normal
    type: Literal["fixed", "swivel", "ball"] = "fixed"
    length: NonNegativeFloat = 0.0  # held length; 0 = point clip
    frame: Literal["global", "body"] = "global"  # frame of position/direction/normal

    @field_validator("direction")
    @classmethod
    def _nonzero(cls, v):
        if math.hypot(*v) == 0:
            raise ValueError("direction must not be the zero vector")
        return v

    @model_validator(mode="after")
    def _normal(self):
        if self.normal is not None:
            d = np.array(self.direction) / np.linalg.norm(self.direction)
            n = np.array(self.normal)
            if np.linalg.norm(n - d * n.dot(d)) < 1e-9 * max(np.linalg.norm(n), 1e-300):
                raise ValueError(
                    f"normal = {list(self.normal)} is parallel to direction = "
                    f"{list(self.direction)}; it must have a part orthogonal to it"
                )
        if self.type == "ball" and self.length > 0:
            raise ValueError("a ball clip holds a point: its length must be 0")
        return self


class Load(_Model):
    """A dead load (global frame) at arc length ``s``."""

    s: NonNegativeFloat
    force: Vec3 = (0.0, 0.0, 0.0)  # N
    moment: Vec3 = (0.0, 0.0, 0.0)  # N m


class Damping(_Model):
    """Kelvin–Voigt damping C^Γ̇ = τC^Γ, C^K̇ = τC^K. Give ``ratio`` ζ (fraction of critical
    damping of the mounted cable's first mode: τ = 2ζ/ω₁; ζ = 1 is critical, the default) or
    ``retardation_time`` τ directly; the per-mode times override τ for that deformation mode."""

    ratio: PositiveFloat | None = None
    retardation_time: NonNegativeFloat | None = None  # s
    extension: NonNegativeFloat | None = None  # s, τ of EA
    shear: NonNegativeFloat | None = None  # s, τ of GA₁, GA₂
    bending: NonNegativeFloat | None = None  # s, τ of EI₁, EI₂
    torsion: NonNegativeFloat | None = None  # s, τ of GJ

    @model_validator(mode="after")
    def _one(self):
        if self.ratio is not None and self.retardation_time is not None:
            raise ValueError("give ratio or retardation_time, not both")
        return self


DEFAULT_DAMPING_RATIO = 1.0


class Cable(_Model):
    """One cable or hose."""

    name: Annotated[str, Field(min_length=1)]
    length: PositiveFloat  # m
    segments: PositiveInt | None = None
    max_segment_length: PositiveFloat | None = None  # m
    natural_curvature: Vec3 = (0.0, 0.0, 0.0)  # κ₁, κ₂, twist in 1/m
    section: Annotated[CircleSection | TubeSection, Field(discriminator="shape")] | None = None
    material: Material | None = None
    stiffness: MeasuredStiffness | None = None
    clips: Annotated[list[Clip], Field(min_length=1)]
    loads: list[Load] = []
    damping: Damping = Damping()

    @model_validator(mode="after")
    def _consistent(self):
        if self.stiffness is None and (self.section is None or self.material is None):
            raise ValueError("give section and material, or stiffness (measured values)")
        if self.stiffness is not None and (self.section is not None or self.material is not None):
            raise ValueError("give either section + material or stiffness, not both")
        if self.segments is not None and self.max_segment_length is not None:
            raise ValueError("give segments or max_segment_length, not both")
        names = [c.name for c in self.clips]
        dup = {n for n in names if names.count(n) > 1}
        if dup:
            raise ValueError(f"clip names must be unique; repeated: {sorted(dup)}")
        for i, c in enumerate(self.clips):
            lo, hi = c.s - c.length / 2, c.s + c.length / 2
            if lo < -1e-12 or hi > self.length * (1 + 1e-12):
                raise ValueError(
                    f"clips[{i}] ('{c.name}') covers s = [{lo}, {hi}] m, outside the cable "
                    f"[0, {self.length}] m"
                )
        for i, ld in enumerate(self.loads):
            if ld.s > self.length * (1 + 1e-12):
                raise ValueError(f"loads[{i}].s = {ld.s} m is beyond the cable end {self.length} m")
        return self

    @property
    def n_segments(self) -> int:
        if self.segments is not None:
            return self.segments
        if self.max_segment_length is not None:
            return max(1, math.ceil(self.length / self.max_segment_length))
        return 50

    def properties(self) -> SectionProperties:
        """Effective section properties."""
        if self.stiffness is not None:
            k = self.stiffness
            ei1 = k.EI if k.EI is not None else k.EI1
            ei2 = k.EI if k.EI is not None else k.EI2
            return from_measured(
                k.EA, k.GA, ei1, ei2, k.GJ, k.mass_per_length, k.radius, k.rotary_inertia
            )
        sec, mat = self.section, self.material
        if sec.shape == "circle":
            outer, inner = sec.radius, 0.0
        else:
            outer, inner = sec.outer_radius, sec.inner_radius
        return from_material(sec.shape, outer, inner, mat.youngs_modulus, mat.nu, mat.density)


class Body(_Model):
    """A rigid body carrying clips; its motion is a list of channel signals, or a CSV table
    ``motion_file`` with columns t, x, y, z, rx, ry, rz (m, rad; global frame)."""

    name: Annotated[str, Field(min_length=1)]
    origin: Vec3 = (0.0, 0.0, 0.0)  # reference point (rotation centre) of the body, global
    orientation: Vec3 = (0.0, 0.0, 0.0)  # rx, ry, rz (rad) of the body frame, R = Rz Ry Rx
    motion: list[ChannelMotion] = []
    motion_file: Path | None = None

    @model_validator(mode="after")
    def _one_motion(self):
        if self.motion and self.motion_file is not None:
            raise ValueError("give motion (channels) or motion_file, not both")
        return self

    def channel_motions(self, base_dir: Path | None = None) -> list[ChannelMotion]:
        """The body's channel signals; a ``motion_file`` table becomes six table signals
        (linear interpolation between its rows: poses, not a sampled signal to filter)."""
        if self.motion_file is None:
            return list(self.motion)
        path = self.motion_file
        if not path.is_absolute() and base_dir is not None:
            path = base_dir / path
        table = read_pose_table(path, f"bodies '{self.name}' motion_file")
        return [
            ChannelMotion(
                channel=ch,
                frame="global",
                signal=TableSignal(type="table", t=table["t"].tolist(), value=table[ch].tolist()),
            )
            for ch in POSE_COLUMNS[1:]
        ]


POSE_COLUMNS = ("t", "x", "y", "z", "rx", "ry", "rz")


def read_pose_table(path: Path, what: str) -> dict[str, np.ndarray]:
    """Reads a CSV pose table with the columns t, x, y, z, rx, ry, rz (m, rad)."""
    if not path.is_file():
        raise SceneError(f"{what} = {str(path)!r} does not exist")
    try:
        data = np.genfromtxt(path, delimiter=",", names=True, dtype=float, encoding="utf-8")
    except ValueError as err:
        raise SceneError(f"{what} = {str(path)!r} is not a numeric CSV table: {err}") from None
    names = data.dtype.names or ()
    missing = [c for c in POSE_COLUMNS if c not in names]
    if missing:
        raise SceneError(
            f"{what} = {str(path)!r} lacks the columns {missing}; it has {list(names)}, "
            f"needed: {list(POSE_COLUMNS)}"
        )
    table = {c: np.atleast_1d(data[c]) for c in POSE_COLUMNS}
    for c, v in table.items():
        if not np.all(np.isfinite(v)):
            row = int(np.flatnonzero(~np.isfinite(v))[0]) + 2
            raise SceneError(
                f"{what}: column {c!r} has a missing or non-numeric value in line {row}"
            )
    if table["t"].size < 2 or np.any(np.diff(table["t"]) <= 0):
        raise SceneError(f"{what}: the times in column 't' must increase strictly (≥ 2 rows)")
    return table


class Simulation(_Model):
    """Run settings."""

    mode: Literal["static", "quasistatic", "dynamic"] = "static"
    gravity: Vec3 = (0.0, 0.0, -9.81)  # m/s²
    duration: PositiveFloat | None = None  # s
    time_step: PositiveFloat = 1e-3  # s
    output_step: PositiveFloat | None = None  # s (default: every step)
    max_iterations: PositiveInt = 40
    spectral_radius: Annotated[float, Field(ge=0.0, le=1.0)] = 0.9  # ρ∞ of generalized-α
    # Dynamic Newton iteration: converged when the correction is below this fraction of the
    # step's increment (docs/dynamics.md: the error it leaves vs the time-step error).
    newton_tolerance: Annotated[float, Field(gt=0.0, lt=1.0)] = _core.DEFAULT_NEWTON_TOLERANCE


class Scene(_Model):
    """A complete scene."""

    simulation: Simulation = Simulation()
    bodies: list[Body] = []
    cables: Annotated[list[Cable], Field(min_length=1)]
    contact: ContactSettings | None = None  # docs/contact.md
    base_dir: Annotated[Path | None, Field(exclude=True)] = None

    @model_validator(mode="after")
    def _references(self):
        body_names = [b.name for b in self.bodies]
        if "world" in body_names:
            raise ValueError("'world' is reserved for the fixed frame; name the body otherwise")
        dup = {n for n in body_names if body_names.count(n) > 1}
        if dup:
            raise ValueError(f"body names must be unique; repeated: {sorted(dup)}")
        cable_names = [c.name for c in self.cables]
        dup = {n for n in cable_names if cable_names.count(n) > 1}
        if dup:
            raise ValueError(f"cable names must be unique; repeated: {sorted(dup)}")
        allowed = ["world", *body_names]
        for i, cable in enumerate(self.cables):
            for j, clip in enumerate(cable.clips):
                if clip.body not in allowed:
                    raise ValueError(
                        f"cables[{i}].clips[{j}].body = '{clip.body}' is not a body of the scene; "
                        f"allowed: {allowed}"
                    )
        if self.contact is not None:
            check_bodies(self.contact, body_names)
        if self.simulation.mode != "static" and self.simulation.duration is None:
            raise ValueError(f"simulation.duration is required in {self.simulation.mode} mode")
        return self

    def body(self, name: str) -> Body | None:
        return next((b for b in self.bodies if b.name == name), None)

    def to_toml(self) -> str:
        """The scene as TOML text (as embedded in result files)."""
        import tomli_w

        data = self.model_dump(mode="json", exclude_none=True)
        return tomli_w.dumps(data)


def format_validation_errors(err: ValidationError, source: str, what: str = "scene") -> str:
    """One line per validation error: key path, message and the offending value."""
    lines = [f"invalid {what} {source}:"]
    for e in err.errors():
        loc = ".".join(str(p) if not isinstance(p, int) else f"[{p}]" for p in e["loc"])
        loc = loc.replace(".[", "[")
        msg = e["msg"].removeprefix("Value error, ")
        value = e.get("input")
        shown = repr(value)
        if len(shown) > 80:
            shown = shown[:77] + "..."
        if e["type"] in ("missing",):
            lines.append(f"  {loc}: required, but missing")
        elif e["type"] == "extra_forbidden":
            lines.append(f"  {loc}: unknown key (value {shown}); check the spelling")
        elif isinstance(value, dict):
            lines.append(f"  {loc or '(top level)'}: {msg}")
        else:
            lines.append(f"  {loc or '(top level)'}: {msg} (got {shown})")
    return "\n".join(lines)


def scene_from_dict(data: dict, base_dir: Path | None = None, source: str = "") -> Scene:
    """Validates a scene given as a dict (as parsed from TOML)."""
    try:
        scene = Scene.model_validate(data)
    except ValidationError as err:
        raise SceneError(format_validation_errors(err, source)) from None
    scene.base_dir = base_dir
    return scene


def load_scene(path: str | Path) -> Scene:
    """Reads and validates a scene TOML file."""
    path = Path(path)
    data = read_toml(path, "scene file", SceneError)
    return scene_from_dict(data, base_dir=path.parent.resolve(), source=f"{str(path)!r}")


def json_schema() -> dict:
    """JSON schema of the scene format."""
    return Scene.model_json_schema()
