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
    Strict,
    ValidationError,
    field_validator,
    model_validator,
)

from cablelife import _core
from cablelife.contact_settings import ContactSettings, check_geometry
from cablelife.limits import LIMITS, MAX_SEGMENTS, MIN_SEGMENTS
from cablelife.paths import SceneFileError, resolve_scene_file, shown_names
from cablelife.rotations import euler_matrix
from cablelife.scene_types import (
    Acceleration,
    AxialStiffness,
    BendingStiffness,
    Curvature,
    Density,
    Direction,
    Flag,
    Force,
    Friction,
    Length,
    Modulus,
    Moment,
    Name,
    NonNegativeFloat,
    Point,
    PositiveFloat,
    PositiveInt,
    Radius,
    Time,
    Vec3,
    bounded,
    check_nonzero,
)
from cablelife.sections import SectionProperties, from_material, from_measured
from cablelife.signals.spec import ChannelMotion, TableSignal
from cablelife.surroundings.models import ClearanceSettings, GeometryPart
from cablelife.tomlfile import read_toml


class SceneError(ValueError):
    """A scene that cannot be used; the message says where and why."""


class _Model(BaseModel):
    model_config = ConfigDict(extra="forbid", allow_inf_nan=False)


class CircleSection(_Model):
    """Solid circular section."""

    shape: Literal["circle"]
    radius: Radius


class TubeSection(_Model):
    """Circular tube (hose)."""

    shape: Literal["tube"]
    outer_radius: Radius
    inner_radius: Radius

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

    youngs_modulus: Modulus  # Pa
    poisson_ratio: Annotated[float, Strict(), Field(ge=0.0, le=0.5)] | None = None
    shear_modulus: Modulus | None = None  # Pa
    density: Density  # kg/m³

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
    EA: AxialStiffness  # N
    GA: AxialStiffness | None = None  # N (shear stiffness incl. shear coefficient)
    EI: BendingStiffness | None = None  # N m² (round cables)
    EI1: BendingStiffness | None = None  # N m² (non-round cables: both)
    EI2: BendingStiffness | None = None
    GJ: BendingStiffness  # N m²
    mass_per_length: bounded("mass_per_length")  # kg/m
    radius: Radius  # m, outer radius (contact, pictures, stresses)
    rotary_inertia: bounded("rotary_inertia") | None = None  # kg m (ρI per length, d1 and d2)
    polar_rotary_inertia: bounded("rotary_inertia") | None = None  # kg m (ρI₃ about the axis d3)

    @model_validator(mode="after")
    def _bending(self):
        if self.EI is None and (self.EI1 is None or self.EI2 is None):
            raise ValueError("give EI, or both EI1 and EI2")
        if self.EI is not None and (self.EI1 is not None or self.EI2 is not None):
            raise ValueError("give EI or EI1/EI2, not both")
        return self


class Clip(_Model):
    """A clip holding the cable at arc length ``s`` (the clip centre)."""

    name: Name
    s: NonNegativeFloat  # m
    body: Annotated[str, Strict()] = "world"
    position: Point  # m
    direction: Direction  # cable tangent d3 at the clip
    normal: Direction | None = None  # d1 at the clip (fixes the twist); default: any normal
    type: Literal["fixed", "swivel", "ball", "hinge", "sliding"] = "fixed"
    length: NonNegativeFloat = 0.0  # held length; 0 = point clip
    axis: Direction | None = None  # hinge: the turning axis in the clip frame (d1, d2, d3)
    friction: Friction = 0.0  # sliding: Coulomb friction coefficient μ
    frame: Literal["global", "body"] = "global"  # frame of position/direction/normal

    @field_validator("direction", "normal", "axis")
    @classmethod
    def _nonzero(cls, v, info):
        return check_nonzero(v, info.field_name)

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
        if self.type in ("ball", "hinge") and self.length > 0:
            raise ValueError(f"a {self.type} clip holds a point: its length must be 0")
        if self.type == "hinge" and self.axis is None:
            raise ValueError(
                "a hinge clip needs its axis = [a1, a2, a3] in the clip frame (d1 = normal, "
                "d3 = cable direction), e.g. axis = [0, 1, 0] for a hinge about d2"
            )
        if self.type == "sliding" and self.length <= 0:
            raise ValueError(
                "a sliding clip is a guide that holds the cable's axis on its line over its "
                "length: give length > 0 (at least two edges of the cable)"
            )
        if self.friction != 0 and self.type != "sliding":
            raise ValueError(
                f"friction = {self.friction} is given for a {self.type} clip; only a sliding "
                "clip has friction"
            )
        if self.type != "hinge" and self.axis is not None:
            raise ValueError(
                f"axis = {list(self.axis)} is given for a {self.type} clip; only a hinge clip "
                "has an axis"
            )
        if self.frame == "body" and self.body == "world":
            raise ValueError(
                "frame = 'body' needs a clip on a body, but body = 'world' (the fixed frame); "
                "allowed: frame = 'global' on world clips, or name the clip's body"
            )
        return self


class Load(_Model):
    """A dead load (global frame) at arc length ``s``."""

    s: NonNegativeFloat
    force: tuple[Force, Force, Force] = (0.0, 0.0, 0.0)  # N
    moment: tuple[Moment, Moment, Moment] = (0.0, 0.0, 0.0)  # N m


class Damping(_Model):
    """Kelvin–Voigt damping C^Γ̇ = τC^Γ, C^K̇ = τC^K. Give ``ratio`` ζ (fraction of critical
    damping of the mounted cable's first mode: τ = 2ζ/ω₁; ζ = 1 is critical, the default) or
    ``retardation_time`` τ directly; the per-mode times override τ for that deformation mode."""

    ratio: Annotated[float, Strict(), Field(gt=0, le=LIMITS["damping_ratio"][1])] | None = None
    retardation_time: Time | None = None  # s
    extension: Time | None = None  # s, τ of EA
    shear: Time | None = None  # s, τ of GA₁, GA₂
    bending: Time | None = None  # s, τ of EI₁, EI₂
    torsion: Time | None = None  # s, τ of GJ

    @model_validator(mode="after")
    def _one(self):
        if self.ratio is not None and self.retardation_time is not None:
            raise ValueError("give ratio or retardation_time, not both")
        return self


DEFAULT_DAMPING_RATIO = 1.0


class Cable(_Model):
    """One cable or hose."""

    name: Name
    length: Length  # m
    segments: Annotated[int, Strict()] | None = None
    max_segment_length: PositiveFloat | None = None  # m
    natural_curvature: tuple[Curvature, Curvature, Curvature] = (0.0, 0.0, 0.0)  # κ₁, κ₂, τ 1/m
    section: Annotated[CircleSection | TubeSection, Field(discriminator="shape")] | None = None
    material: Material | None = None
    stiffness: MeasuredStiffness | None = None
    # At least one clip, unless a junction holds the cable (checked with the junctions).
    clips: list[Clip] = []
    loads: list[Load] = []
    damping: Damping = Damping()

    @field_validator("segments")
    @classmethod
    def _segments(cls, v):
        if v is not None and not MIN_SEGMENTS <= v <= MAX_SEGMENTS:
            raise ValueError(
                f"segments = {v}: allowed: {MIN_SEGMENTS} to {MAX_SEGMENTS}; fewer cannot "
                "represent a cable bent between clips (one segment is a straight bar), more is "
                "finer than any cable needs while results grow with the segments"
            )
        return v

    @model_validator(mode="after")
    def _consistent(self):
        if self.stiffness is None and (self.section is None or self.material is None):
            raise ValueError("give section and material, or stiffness (measured values)")
        if self.stiffness is not None and (self.section is not None or self.material is not None):
            raise ValueError("give either section + material or stiffness, not both")
        if self.segments is not None and self.max_segment_length is not None:
            raise ValueError("give segments or max_segment_length, not both")
        if self.max_segment_length is not None and self.n_segments > MAX_SEGMENTS:
            raise ValueError(
                f"max_segment_length = {self.max_segment_length} m gives {self.n_segments} "
                f"segments on {self.length} m; allowed: at most {MAX_SEGMENTS} segments "
                "(finer than any cable needs; results grow with the segments)"
            )
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
            return max(MIN_SEGMENTS, math.ceil(self.length / self.max_segment_length))
        return 50

    def properties(self) -> SectionProperties:
        """Effective section properties."""
        if self.stiffness is not None:
            k = self.stiffness
            ei1 = k.EI if k.EI is not None else k.EI1
            ei2 = k.EI if k.EI is not None else k.EI2
            return from_measured(
                k.EA,
                k.GA,
                ei1,
                ei2,
                k.GJ,
                k.mass_per_length,
                k.radius,
                k.rotary_inertia,
                k.polar_rotary_inertia,
            )
        sec, mat = self.section, self.material
        if sec.shape == "circle":
            outer, inner = sec.radius, 0.0
        else:
            outer, inner = sec.outer_radius, sec.inner_radius
        return from_material(sec.shape, outer, inner, mat.youngs_modulus, mat.nu, mat.density)


class Placement(_Model):
    """Where a body's geometry given in global coordinates (``frame = "global"``: meshes as CAD
    exports them, primitives) is put: a point x of such a part goes to ``position + R x``,
    R = Rz Ry Rx of ``orientation`` (rad). The identity (the default) leaves the parts where
    their coordinates say (docs/scene.md, Body placement)."""

    position: Point = (0.0, 0.0, 0.0)  # m
    orientation: Vec3 = (0.0, 0.0, 0.0)  # rx, ry, rz (rad)


class Body(_Model):
    """A rigid body carrying clips; its motion is a list of channel signals, or a CSV table
    ``motion_file`` with columns t, x, y, z, rx, ry, rz (m, rad; global frame)."""

    name: Name
    origin: Point = (0.0, 0.0, 0.0)  # reference point (rotation centre) of the body, global
    orientation: Vec3 = (0.0, 0.0, 0.0)  # rx, ry, rz (rad) of the body frame, R = Rz Ry Rx
    motion: list[ChannelMotion] = []
    motion_file: Path | None = None
    geometry: list[GeometryPart] = []  # shapes moving with the body (docs/environment.md)
    placement: Placement | None = None  # of the geometry in global coordinates (identity)

    @model_validator(mode="after")
    def _one_motion(self):
        if self.motion and self.motion_file is not None:
            raise ValueError("give motion (channels) or motion_file, not both")
        if self.placement is not None and all(p.frame == "body" for p in self.geometry):
            raise ValueError(
                f"placement = {self.placement.model_dump()} is given, but body '{self.name}' "
                "has no geometry in global coordinates (the placement moves only parts with "
                'frame = "global"); allowed: a placement with such parts, or none'
            )
        return self

    def part_frame(self, part) -> tuple[np.ndarray, np.ndarray]:
        """(o, R): a point p of a geometry ``part`` given in its own coordinates is at
        o + R p globally with the body at rest — the body's origin and axes for
        ``frame = "body"`` parts, the ``placement`` for parts in global coordinates."""
        if part.frame == "body":
            return np.asarray(self.origin, float), euler_matrix(self.orientation)
        if self.placement is None:
            return np.zeros(3), np.eye(3)
        return (
            np.asarray(self.placement.position, float),
            euler_matrix(self.placement.orientation),
        )

    def channel_motions(
        self, base_dir: Path | None = None, allow_outside: bool = False
    ) -> list[ChannelMotion]:
        """The body's channel signals; a ``motion_file`` table becomes six table signals
        (linear interpolation between its rows: poses, not a sampled signal to filter).
        ``motion_file`` follows the rule of files named in scenes (cablelife.paths)."""
        if self.motion_file is None:
            return list(self.motion)
        what = f"bodies '{self.name}' motion_file"
        try:
            path = resolve_scene_file(base_dir, self.motion_file, allow_outside, what)
        except SceneFileError as err:
            raise SceneError(str(err)) from None
        table = read_pose_table(path, what)
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
    except (ValueError, UnicodeDecodeError):
        raise SceneError(
            f"{what} = {str(path)!r} is not a numeric CSV table (UTF-8 text, a header row "
            f"{','.join(POSE_COLUMNS)}, then numbers)"
        ) from None
    names = data.dtype.names or ()
    missing = [c for c in POSE_COLUMNS if c not in names]
    if missing:
        raise SceneError(
            f"{what} = {str(path)!r} lacks the columns {missing}; it has {shown_names(names)}, "
            f"needed: {list(POSE_COLUMNS)}"
        )
    table = {c: np.atleast_1d(data[c]) for c in POSE_COLUMNS}
    for c, v in table.items():
        if not np.all(np.isfinite(v)):
            row = int(np.flatnonzero(~np.isfinite(v))[0]) + 2
            raise SceneError(
                f"{what} = {str(path)!r}: column {c!r} has a missing or non-numeric value in "
                f"line {row}"
            )
    if table["t"].size < 2 or np.any(np.diff(table["t"]) <= 0):
        raise SceneError(f"{what}: the times in column 't' must increase strictly (≥ 2 rows)")
    return table


class JunctionClip(_Model):
    """A clip that holds a junction (docs/harness.md): the junction is clamped to ``body``
    ("world": fixed) at its position and orientation; the solver prescribes its pose."""

    name: Name = "clip"
    body: Annotated[str, Strict()] = "world"


class Junction(_Model):
    """A junction of a harness (docs/harness.md): joins cable ends rigidly at ``position``.
    ``ends`` name "cable:start" or "cable:end"; ``directions`` give each end's stress-free
    tangent at the junction, pointing away from it (global, at the reference); ``normals``
    (optional) its d1 (default: the global axis least aligned with the direction, as for
    clips). ``mass`` and ``rotary_inertia`` (about the junction's axes) of the tape or
    connector."""

    name: Name
    ends: Annotated[list[Annotated[str, Strict()]], Field(min_length=2)]
    position: Point  # m
    directions: list[Direction]
    normals: list[Direction] | None = None
    mass: bounded("junction_mass") = 0.0  # kg
    rotary_inertia: NonNegativeFloat = 0.0  # kg m², about each axis: 0 or LIMITS' range
    clip: JunctionClip | None = None  # a clip holding the junction (default: free)

    @field_validator("rotary_inertia")
    @classmethod
    def _inertia(cls, v):
        lo, hi = LIMITS["junction_inertia"]
        if v != 0.0 and not lo <= v <= hi:
            raise ValueError(f"rotary_inertia = {v:g} kg m²; allowed: 0 (none) or {lo:g} … {hi:g}")
        return v

    @model_validator(mode="after")
    def _ends(self):
        for i, e in enumerate(self.ends):
            cable, _, which = e.rpartition(":")
            if not cable or which not in ("start", "end"):
                raise ValueError(
                    f"ends[{i}] = {e!r}: allowed: 'cable:start' or 'cable:end' (a cable name, "
                    "a colon, and which end)"
                )
        if len(self.directions) != len(self.ends):
            raise ValueError(
                f"{len(self.directions)} directions for {len(self.ends)} ends; give one "
                "direction per end (its tangent pointing away from the junction)"
            )
        if self.normals is not None and len(self.normals) != len(self.ends):
            raise ValueError(
                f"{len(self.normals)} normals for {len(self.ends)} ends; give one per end or none"
            )
        for i, d in enumerate(self.directions):
            check_nonzero(d, f"directions[{i}]")
            if self.normals is not None:
                dd = np.array(d) / np.linalg.norm(d)
                n = np.array(self.normals[i])
                if np.linalg.norm(n - dd * n.dot(dd)) < 1e-9 * max(np.linalg.norm(n), 1e-300):
                    raise ValueError(
                        f"normals[{i}] = {list(n)} is zero or parallel to directions[{i}] = "
                        f"{list(d)}; it must have a part orthogonal to it"
                    )
        return self

    def end(self, i: int) -> tuple[str, str]:
        """(cable name, "start" or "end") of end i."""
        cable, _, which = self.ends[i].rpartition(":")
        return cable, which


class Files(_Model):
    """Files named in the scene (measured signals, motion_file): outside the scene's folder
    only with ``allow_outside = true`` (or the CLI flag ``--allow-outside-files``)."""

    allow_outside: Flag = False


class Simulation(_Model):
    """Run settings."""

    mode: Literal["static", "quasistatic", "dynamic"] = "static"
    gravity: tuple[Acceleration, Acceleration, Acceleration] = (0.0, 0.0, -9.81)  # m/s²
    duration: PositiveFloat | None = None  # s
    time_step: PositiveFloat = 1e-3  # s
    output_step: PositiveFloat | None = None  # s (default: every step)
    max_iterations: PositiveInt = 40
    spectral_radius: Annotated[float, Strict(), Field(ge=0.0, le=1.0)] = 0.9  # ρ∞ of generalized-α
    # Dynamic Newton iteration: converged when its estimated remaining error (from the
    # corrections' contraction) is below this fraction of the estimated local time error, the
    # correction at most 5e-3 of the step's increment (1e-4 while touching a contact barrier);
    # docs/dynamics.md: the error it leaves vs the time-step error.
    newton_tolerance: Annotated[float, Strict(), Field(gt=0.0, lt=1.0)] = (
        _core.DEFAULT_NEWTON_TOLERANCE
    )
    # Strains outside the model's validity range (docs/solver.md): a warning, or an error.
    strain_limit: Literal["warn", "error"] = "warn"
    # Precision of the saved histories in the result file (docs/results.md): float32 halves it.
    output_precision: Literal["float64", "float32"] = "float64"


class Scene(_Model):
    """A complete scene."""

    simulation: Simulation = Simulation()
    files: Files = Files()
    bodies: list[Body] = []
    cables: Annotated[list[Cable], Field(min_length=1)]
    junctions: list[Junction] = []  # harnesses: cable ends joined at junctions
    clearance: ClearanceSettings | None = None  # settings of the clearance to the geometry
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
        for i, junction in enumerate(self.junctions):
            if junction.clip is not None and junction.clip.body not in allowed:
                raise ValueError(
                    f"junctions[{i}].clip.body = '{junction.clip.body}' is not a body of the "
                    f"scene; allowed: {allowed}"
                )
        from cablelife.harness import check_junctions

        check_junctions(self)
        check_geometry(self)
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
