"""The motion volume against the surroundings. A body moves, so each body is checked against
the space the cable sweeps *relative to it*: the cable's positions of every saved step taken
into the body's reference frame, their capsules (the tube) meshed on a voxel grid as for the
motion volume; then per body

- ``min_distance``: the least distance between the relative motion volume and the body
  (exact, the least clearance of any step and node — half-edges included — to that body);
- ``intersection``: the volume of the relative motion volume inside the body (voxels of the
  motion volume whose centre the body's signed distance puts inside), m³.

The body geometry is the result's display geometry (``Result.surroundings``: exact for
primitives and for meshes up to 20 000 triangles, decimated beyond)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass
class BodyVolumeCheck:
    body: str
    min_distance: float  # m, negative: the volume enters the body
    intersection: float  # m³
    voxel: float  # m


def _body_core(vertices, faces):
    from cablelife import _core

    core = _core.Surroundings()
    core.add_mesh(0, np.ascontiguousarray(vertices, float), np.asarray(faces, np.int64))
    return core


def volume_vs_surroundings(
    result, voxel: float = 0.002, steps=None, motion=None
) -> list[BodyVolumeCheck]:
    """Per body of ``result.surroundings``: the relative motion volume of all cables against
    the body (see the module docstring). ``motion``: the motion volume of all of ``result``'s
    cables over the same steps at the same voxel, if already computed: a body that does not
    move sees exactly that volume, whose distance field is then used as it is."""
    from cablelife.volume.field import Capsules, union_field
    from cablelife.volume.sweep import select_steps

    geom = result.surroundings
    if geom is None:
        raise ValueError("the result has no surroundings (no geometry on its bodies)")
    at_rest = np.zeros((3, 4))
    at_rest[:, :3] = np.eye(3)
    out = []
    for b, name in enumerate(geom.bodies):
        vertices, faces = geom.meshes[b]
        core = _body_core(vertices, faces)
        # at rest at every step: the cables sweep the motion volume itself relative to it
        still = motion is not None and motion.field.spacing == voxel
        still = still and bool(np.all(geom.poses[b] == at_rest))
        caps, least = [], np.inf
        for c in result.cables.values():
            idx = select_steps(c.n_steps, steps)
            pose = geom.poses[b, np.minimum(idx, geom.poses.shape[1] - 1)]
            rot, t = pose[..., :3], pose[..., 3]
            # X = Rᵀ (x − t): the cable in the body's reference frame
            local = np.einsum("sji,snj->sni", rot, c.positions[idx] - t[:, None, :])
            radius = float(c.section["outer_radius"])
            ident = np.zeros((1, len(idx), 3, 4))
            ident[0, :, :, :3] = np.eye(3)
            value, _ = core.clearance(np.ascontiguousarray(local), radius, ident)
            least = min(least, float(value.min()))
            if not still:
                caps.append(
                    Capsules(local[:, :-1].reshape(-1, 3), local[:, 1:].reshape(-1, 3), radius)
                )
        if still:
            f = motion.field
        else:
            allcaps = caps[0]
            for more in caps[1:]:
                allcaps = allcaps.concat(more)
            f = union_field(allcaps, voxel)
        inside = np.argwhere(f.values <= 0)
        sd = core.project_points(0, f.points(inside))["distance"] if len(inside) else np.array([])
        out.append(BodyVolumeCheck(name, least, float((sd < 0).sum()) * voxel**3, voxel))
    return out
