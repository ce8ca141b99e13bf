"""The surroundings of a scene as one distance-query object (Rust, ``_core.Surroundings``):
every part in its body's reference frame (global coordinates at rest), and the per-step maps
that take the cable's global positions into each body's frame."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from cablelife import _core
from cablelife.scene import Scene, SceneError
from cablelife.surroundings.models import (
    BoxPart,
    CylinderPart,
    MeshPart,
    PlanePart,
    SpherePart,
    part_label,
)
from cablelife.surroundings.paths import resolve_scene_file


@dataclass
class Surroundings:
    """The geometry of a scene: ``bodies`` carrying it (index = body index of the parts),
    part labels, and the meshes (global, at rest) for pictures."""

    core: _core.Surroundings
    bodies: list[str]
    parts: list[str]
    part_body: np.ndarray  # (P,) body index of each part
    min_clearance: float = 0.0
    # (body index, vertices, faces) of every part, global at rest (primitives tessellated)
    meshes: list[tuple[int, np.ndarray, np.ndarray]] = field(default_factory=list)
    friction: list[float | None] = field(default_factory=list)

    def display_meshes(self) -> list[tuple[np.ndarray, np.ndarray]]:
        """One mesh per body for pictures, decimated to ≤ 20 000 triangles."""
        from cablelife.surroundings.display import decimate, merge

        return [
            decimate(*merge([(v, f) for b, v, f in self.meshes if b == k]))
            for k in range(len(self.bodies))
        ]


def scene_size(scene: Scene) -> float:
    """A length scale of the scene (m): the longest cable or the spread of the clips."""
    pts = [c.position for cable in scene.cables for c in cable.clips if c.frame == "global"]
    pts += [b.origin for b in scene.bodies]
    spread = float(np.ptp(np.array(pts), axis=0).max()) if len(pts) > 1 else 0.0
    return max(max(c.length for c in scene.cables), spread)


def has_geometry(scene: Scene) -> bool:
    return any(getattr(b, "geometry", None) for b in scene.bodies)


def load_surroundings(scene: Scene) -> Surroundings | None:
    """Reads and checks every part of the scene's bodies; None without geometry."""
    from cablelife.simulate import euler_matrix
    from cablelife.surroundings.meshes import load_mesh

    if not has_geometry(scene):
        return None
    core = _core.Surroundings()
    bodies: list[str] = []
    labels: list[str] = []
    part_body: list[int] = []
    meshes: list[tuple[int, np.ndarray, np.ndarray]] = []
    friction: list[float | None] = []
    size = scene_size(scene)
    clips = [c.position for cable in scene.cables for c in cable.clips if c.frame == "global"]
    centre = np.mean(clips, axis=0) if clips else None
    for bi, body in enumerate(scene.bodies):
        if not body.geometry:
            continue
        b = len(bodies)
        bodies.append(body.name)
        for k, part in enumerate(body.geometry):
            what = f"bodies[{bi}].geometry[{k}] ('{part_label(body.name, k, part)}')"
            # each part to global coordinates at rest: X = o + R0 p (body frame or placement)
            o, rot0 = body.part_frame(part)
            try:
                if isinstance(part, MeshPart):
                    path = resolve_scene_file(scene.base_dir, part.mesh)
                    m = load_mesh(path, part.scale, what, size)
                    v = m.vertices @ rot0.T + o
                    v = np.ascontiguousarray(v)
                    shells = m.shells or [m.faces]
                    for shell in shells[:-1]:  # each closed shell its own solid
                        core.add_mesh(b, v, shell)
                        labels.append(part_label(body.name, k, part))
                        part_body.append(b)
                        friction.append(part.friction)
                    core.add_mesh(b, v, shells[-1])
                    meshes.append((b, v, m.faces))
                elif isinstance(part, PlanePart):
                    core.add_plane(b, _at(o, rot0, part.point), (rot0 @ part.normal).tolist())
                elif isinstance(part, BoxPart):
                    rot = euler_matrix(part.orientation)
                    rot = rot0 @ rot
                    half = (np.asarray(part.size) / 2).tolist()
                    core.add_box(b, _at(o, rot0, part.center), rot.tolist(), half)
                elif isinstance(part, CylinderPart):
                    core.add_cylinder(
                        b,
                        _at(o, rot0, part.center),
                        (rot0 @ part.axis).tolist(),
                        part.radius,
                        part.length / 2,
                    )
                elif isinstance(part, SpherePart):
                    core.add_sphere(b, _at(o, rot0, part.center), part.radius)
            except ValueError as err:
                if isinstance(err, SceneError):
                    raise
                raise SceneError(f"{what}: {err}") from None
            if not isinstance(part, MeshPart):
                from cablelife.surroundings.display import primitive_mesh

                # a plane is drawn as a square of the scene's size under the clips
                near = None if part.frame == "body" or centre is None else rot0.T @ (centre - o)
                pv, pf = primitive_mesh(part, 1.5 * size, near)
                meshes.append((b, pv @ rot0.T + o, pf))
            labels.append(part_label(body.name, k, part))
            part_body.append(b)
            friction.append(part.friction)
    settings = getattr(scene, "clearance", None)
    return Surroundings(
        core=core,
        bodies=bodies,
        parts=labels,
        part_body=np.array(part_body, dtype=np.int64),
        min_clearance=settings.min_clearance if settings is not None else 0.0,
        meshes=meshes,
        friction=friction,
    )


def _at(origin: np.ndarray, rot: np.ndarray, p) -> list[float]:
    return (origin + rot @ np.asarray(p, float)).tolist()


def body_maps(scene: Scene, bodies: list[str], times: np.ndarray, steps: np.ndarray) -> np.ndarray:
    """(B, S, 3, 4) maps [M | v] taking global points at the saved ``steps`` (indices into the
    run's time grid ``times``) into each body's reference frame: X = M x + v, with
    x = o + u + R (X − o) the body motion the clips follow."""
    from cablelife.simulate import body_motions

    motions = body_motions(scene, times)
    out = np.zeros((len(bodies), steps.size, 3, 4))
    for b, name in enumerate(bodies):
        _, _, motion = motions[name]
        body = scene.body(name)
        origin = np.asarray(body.origin, float)
        if motion is None:
            out[b, :, :, :3] = np.eye(3)
            continue
        rot = motion.rotation[steps]  # (S, 3, 3)
        rt = np.transpose(rot, (0, 2, 1))
        u = motion.translation[steps]
        out[b, :, :, :3] = rt
        out[b, :, :, 3] = origin - np.einsum("sij,sj->si", rt, origin + u)
    return out
