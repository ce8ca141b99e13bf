"""Scene keys of contact with the surroundings (docs/contact.md): ``[contact]`` and its
geometry primitives, and their global poses over time for the Rust solver.

Until the geometry of ``[[bodies]]`` (the surroundings work) is merged, the primitives are
listed in ``[[contact.geometry]]`` with the same fields (type plane/box/cylinder/sphere, body,
center, normal, size, axis, radius, length, friction, frame); the lead unifies them at merge.
"""

from __future__ import annotations

from typing import Annotated, Literal

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, model_validator

Vec3 = tuple[float, float, float]


class _Model(BaseModel):
    model_config = ConfigDict(extra="forbid", allow_inf_nan=False)


class Primitive(_Model):
    """An analytic solid on a body (or on ``world``): plane (half-space below ``normal``),
    sphere (``radius``), cylinder (``radius``, ``length``, ``axis``; flat caps), box (full
    ``size``, rotated so that its local z is ``axis``)."""

    type: Literal["plane", "sphere", "cylinder", "box"]
    name: str = ""
    body: str = "world"
    frame: Literal["global", "body"] = "global"
    center: Vec3 = (0.0, 0.0, 0.0)
    normal: Vec3 = (0.0, 0.0, 1.0)
    axis: Vec3 = (0.0, 0.0, 1.0)
    radius: Annotated[float, Field(gt=0.0)] | None = None
    length: Annotated[float, Field(gt=0.0)] | None = None
    size: (
        tuple[
            Annotated[float, Field(gt=0.0)],
            Annotated[float, Field(gt=0.0)],
            Annotated[float, Field(gt=0.0)],
        ]
        | None
    ) = None
    friction: Annotated[float, Field(ge=0.0)] | None = None  # overrides [contact] friction

    @model_validator(mode="after")
    def _dimensions(self):
        need = {"sphere": ["radius"], "cylinder": ["radius", "length"], "box": ["size"]}
        missing = [k for k in need.get(self.type, []) if getattr(self, k) is None]
        if missing:
            raise ValueError(f"a {self.type} needs {', '.join(missing)}")
        for key in ("normal", "axis"):
            if np.linalg.norm(getattr(self, key)) == 0.0:
                raise ValueError(f"{key} = {getattr(self, key)}: must be a non-zero vector")
        return self

    def dimensions(self) -> list[float]:
        if self.type == "sphere":
            return [self.radius]
        if self.type == "cylinder":
            return [self.radius, self.length]
        if self.type == "box":
            return [0.5 * s for s in self.size]
        return []

    def local_frame(self) -> np.ndarray:
        """Columns: the primitive's axes in its body's (or the global) frame; z = normal/axis."""
        z = np.asarray(self.normal if self.type == "plane" else self.axis, float)
        z = z / np.linalg.norm(z)
        helper = np.array([1.0, 0.0, 0.0]) if abs(z[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
        x = np.cross(helper, z)
        x /= np.linalg.norm(x)
        return np.column_stack([x, np.cross(z, x), z])


class ContactSettings(_Model):
    """``[contact]``: off unless ``enabled``; Coulomb ``friction`` μ (per-primitive override);
    barrier and friction-smoothing parameters (0: defaults from the cable radius)."""

    enabled: bool = False
    friction: Annotated[float, Field(ge=0.0)] = 0.0
    distance: Annotated[float, Field(ge=0.0)] = 0.0  # d̂, m (0: 1 % of the cable radius)
    stiffness: Annotated[float, Field(ge=0.0)] = 0.0  # κ, N/m² (0: from the weight per length)
    stick_distance: Annotated[float, Field(ge=0.0)] = 0.0  # ε_x, m (0: 0.1 % of r)
    stick_velocity: Annotated[float, Field(gt=0.0)] = 1e-3  # ε_v, m/s
    geometry: list[Primitive] = []

    @model_validator(mode="after")
    def _geometry(self):
        if self.enabled and not self.geometry:
            raise ValueError(
                "contact.enabled = true but the scene has no geometry; add [[contact.geometry]] "
                "primitives (plane, sphere, cylinder, box) or set enabled = false"
            )
        for i, g in enumerate(self.geometry):
            if not g.name:
                g.name = f"{g.type}{i}"
        return self


def check_bodies(settings: ContactSettings, body_names: list[str]) -> None:
    """Raises ValueError if a primitive names an unknown body."""
    allowed = ["world", *body_names]
    for i, g in enumerate(settings.geometry):
        if g.body not in allowed:
            raise ValueError(
                f"contact.geometry[{i}].body = '{g.body}' is not a body of the scene; "
                f"allowed: {allowed}"
            )


def obstacle_poses(scene, times: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Global positions (T, O, 3) and orientations (T, O, 4, scalar first) of the contact
    primitives on ``times`` (their bodies' motions)."""
    from scipy.spatial.transform import Rotation

    from cablelife.signals import body_motion

    geo = scene.contact.geometry
    n_t = times.size
    pos = np.zeros((n_t, len(geo), 3))
    frames = np.zeros((n_t, len(geo), 3, 3))
    motions = {}
    for j, g in enumerate(geo):
        local = g.local_frame()
        center = np.asarray(g.center, float)
        body = scene.body(g.body) if g.body != "world" else None
        if body is None:
            pos[:, j], frames[:, j] = center, local
            continue
        r0 = Rotation.from_euler("xyz", body.orientation).as_matrix()
        origin = np.asarray(body.origin, float)
        if g.frame == "body":
            center, local = origin + r0 @ center, r0 @ local
        if body.name not in motions:
            channels = body.channel_motions(scene.base_dir)
            grid = times if n_t > 1 else np.array([times[0], times[0] + scene.simulation.time_step])
            motions[body.name] = (
                body_motion(channels, grid, scene.base_dir, r0) if channels else None
            )
        motion = motions[body.name]
        if motion is None:
            pos[:, j], frames[:, j] = center, local
            continue
        rot = motion.rotation[:n_t]
        pos[:, j] = origin + motion.translation[:n_t] + rot @ (center - origin)
        frames[:, j] = rot @ local
    quats = Rotation.from_matrix(frames.reshape(-1, 3, 3)).as_quat(scalar_first=True)
    return pos, quats.reshape(n_t, len(geo), 4)


def set_contact(core, scene, cable, times: np.ndarray) -> None:
    """Adds the contact term to the Rust cable ``core`` if ``[contact]`` is enabled."""
    c = scene.contact
    if c is None or not c.enabled:
        return
    pos, quat = obstacle_poses(scene, times)
    bodies = ["world", *[b.name for b in scene.bodies]]
    obstacles = [
        (
            g.name,
            bodies.index(g.body),
            g.type,
            g.dimensions(),
            c.friction if g.friction is None else g.friction,
        )
        for g in c.geometry
    ]
    core.set_contact(
        obstacles,
        len(bodies),
        cable.properties().outer_radius,
        pos,
        quat,
        distance=c.distance,
        stiffness=c.stiffness,
        stick_distance=c.stick_distance,
        stick_velocity=c.stick_velocity,
    )
