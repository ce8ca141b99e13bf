"""Scene keys of contact with the surroundings (docs/contact.md): ``[contact]``, and the
contact obstacles built from the geometry of ``[[bodies]]`` (docs/environment.md) with their
global poses over time for the Rust solver."""

from __future__ import annotations

import numpy as np
from pydantic import BaseModel, ConfigDict, model_validator

from cablelife.scene_types import Flag, Friction, Time, bounded


class ContactSettings(BaseModel):
    """``[contact]``: off unless ``enabled``; Coulomb ``friction`` μ (a geometry part's own
    ``friction`` overrides it); barrier and friction-smoothing parameters (0: defaults from the
    cable radius). The obstacles are the geometry parts of ``[[bodies]]``."""

    model_config = ConfigDict(extra="forbid", allow_inf_nan=False)

    enabled: Flag = False
    friction: Friction = 0.0
    distance: bounded("contact_length") = 0.0  # d̂, m (0: 1 % of the cable radius)
    # κ, N/m² (0: automatic — from the weight per length, raised per part by the static solve
    # to the contact load it carries; docs/contact.md "The barrier scaled to the load")
    stiffness: bounded("contact_stiffness") = 0.0
    stick_distance: bounded("contact_length") = 0.0  # ε_x, m (0: 0.1 % of r)
    stick_velocity: bounded("stick_velocity") = 1e-3  # ε_v, m/s
    damping: Time = 5e-4  # τ_c, s: normal damping of dynamic contact

    @model_validator(mode="before")
    @classmethod
    def _no_own_geometry(cls, data):
        if isinstance(data, dict) and "geometry" in data:
            raise ValueError(
                "contact.geometry is no longer read: contact uses the geometry of the bodies; "
                "move each part to [[bodies]] geometry = [...] of the body that carries it "
                "(docs/environment.md; plane: shape = 'plane', point, normal)"
            )
        return data


def check_geometry(scene) -> None:
    """Raises ValueError if contact is enabled but no body carries geometry."""
    c = scene.contact
    if c is None or not c.enabled:
        return
    if not any(b.geometry for b in scene.bodies):
        raise ValueError(
            "contact.enabled = true but no body has geometry; add geometry parts to "
            "[[bodies]] (geometry = [{ shape = 'plane', point = [...], normal = [...] }] or "
            "a mesh file, docs/environment.md) or set contact.enabled = false"
        )


def _frame(z) -> np.ndarray:
    """Columns x, y, z: a right-handed frame with the unit z given."""
    z = np.asarray(z, float)
    z = z / np.linalg.norm(z)
    helper = np.array([1.0, 0.0, 0.0]) if abs(z[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    x = np.cross(helper, z)
    x /= np.linalg.norm(x)
    return np.column_stack([x, np.cross(z, x), z])


def obstacles(scene) -> tuple[list, list, list[tuple[np.ndarray, np.ndarray]]]:
    """The contact obstacles of the scene's geometry: (name, body index in ["world", *bodies],
    type, dimensions, friction) tuples, their frames at rest (position, 3×3 axes; global), and
    the meshes (vertices in the obstacle frame, faces). A mesh file with several closed shells
    gives one obstacle per shell."""
    from cablelife.scene import SceneError
    from cablelife.simulate import euler_matrix
    from cablelife.surroundings.build import scene_size
    from cablelife.surroundings.meshes import load_mesh
    from cablelife.surroundings.models import (
        BoxPart,
        CylinderPart,
        MeshPart,
        PlanePart,
        part_label,
    )
    from cablelife.surroundings.paths import resolve_scene_file

    mu = scene.contact.friction
    tuples, frames, meshes = [], [], []
    size = None
    for bi, body in enumerate(scene.bodies):
        for k, part in enumerate(body.geometry):
            name = part_label(body.name, k, part)
            o, rot0 = body.part_frame(part)  # body frame or placement → global at rest
            friction = mu if part.friction is None else part.friction
            if isinstance(part, MeshPart):
                size = scene_size(scene) if size is None else size
                what = f"bodies[{bi}].geometry[{k}] ('{name}')"
                try:
                    m = load_mesh(
                        resolve_scene_file(scene.base_dir, part.mesh), part.scale, what, size
                    )
                except ValueError as err:
                    if isinstance(err, SceneError):
                        raise
                    raise SceneError(f"{what}: {err}") from None
                v = m.vertices @ rot0.T + o  # global at rest
                shells = m.shells or [m.faces]
                for s, shell in enumerate(shells):
                    label = name if len(shells) == 1 else f"{name}[{s}]"
                    # the obstacle frame at the shell's bounding-box centre (global axes): its
                    # bounding sphere rejects far edges before the hierarchy is asked
                    used = v[np.unique(shell)]
                    centre = 0.5 * (used.min(axis=0) + used.max(axis=0))
                    tuples.append((label, bi + 1, "mesh", [float(len(meshes))], friction))
                    frames.append((centre, np.eye(3)))
                    faces = np.ascontiguousarray(shell, dtype=np.int64)
                    meshes.append((np.ascontiguousarray(v - centre), faces))
                continue
            if isinstance(part, PlanePart):
                kind, dims = "plane", []
                pos, axes = part.point, _frame(part.normal)
            elif isinstance(part, BoxPart):
                kind, dims = "box", [0.5 * s for s in part.size]
                pos, axes = part.center, euler_matrix(part.orientation)
            elif isinstance(part, CylinderPart):
                kind, dims = "cylinder", [part.radius, part.length]
                pos, axes = part.center, _frame(part.axis)
            else:
                kind, dims = "sphere", [part.radius]
                pos, axes = part.center, np.eye(3)
            tuples.append((name, bi + 1, kind, dims, friction))
            frames.append((o + rot0 @ np.asarray(pos, float), rot0 @ axes))
    return tuples, frames, meshes


def obstacle_poses(scene, times: np.ndarray, frames: list, bodies: list[int], motions=None):
    """Global positions (T, O, 3) and orientations (T, O, 4, scalar first) of the obstacles on
    ``times``: each frame at rest moved with its body (simulate.body_motions on ``times``, as
    the clips and the clearance, or ``motions`` computed so already): x = o + u + R (X − o)."""
    from scipy.spatial.transform import Rotation

    from cablelife.simulate import body_motions

    if motions is None:
        motions = body_motions(scene, times)
    n_t = times.size
    pos = np.zeros((n_t, len(frames), 3))
    axes = np.zeros((n_t, len(frames), 3, 3))
    for j, ((p, a), b) in enumerate(zip(frames, bodies, strict=True)):
        body = scene.bodies[b - 1]
        _, _, motion = motions[body.name]
        if motion is None:
            pos[:, j], axes[:, j] = p, a
            continue
        origin = np.asarray(body.origin, float)
        rot = motion.rotation[:n_t]
        pos[:, j] = origin + motion.translation[:n_t] + rot @ (p - origin)
        axes[:, j] = rot @ a
    quats = Rotation.from_matrix(axes.reshape(-1, 3, 3)).as_quat(scalar_first=True)
    return pos, quats.reshape(n_t, len(frames), 4)


def set_contact(core, scene, cable, times: np.ndarray, motions=None) -> None:
    """Adds the contact term to the Rust cable ``core`` if ``[contact]`` is enabled (the
    bodies' ``motions`` on ``times`` if already computed: simulate.body_motions)."""
    c = scene.contact
    if c is None or not c.enabled:
        return
    check_geometry(scene)
    tuples, frames, meshes = obstacles(scene)
    pos, quat = obstacle_poses(scene, times, frames, [t[1] for t in tuples], motions)
    core.set_contact(
        tuples,
        len(scene.bodies) + 1,
        cable.properties().outer_radius,
        pos,
        quat,
        distance=c.distance,
        stiffness=c.stiffness,
        stick_distance=c.stick_distance,
        stick_velocity=c.stick_velocity,
        damping=c.damping,
        meshes=meshes,
    )
