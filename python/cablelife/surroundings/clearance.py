"""Clearance of the cables of a result to the scene's surroundings (computed after the run,
in Rust, for every saved step and node)."""

from __future__ import annotations

import numpy as np

from cablelife.scene import Scene
from cablelife.surroundings.build import Surroundings, body_maps
from cablelife.surroundings.data import CableClearance
from cablelife.surroundings.display import SurroundingsGeometry


def cable_clearance(
    env: Surroundings,
    scene: Scene,
    positions: np.ndarray,
    radius: float,
    times: np.ndarray,
    steps: np.ndarray,
) -> CableClearance:
    """Clearance of one cable with node ``positions`` (S, N+1, 3) at the saved ``steps``
    (indices into the run's time grid ``times``)."""
    maps = body_maps(scene, env.bodies, times, steps)
    value, part = env.core.clearance(np.ascontiguousarray(positions, float), radius, maps)
    part = part.astype(np.int64)
    return CableClearance(
        value=value,
        body=env.part_body[part],
        bodies=list(env.bodies),
        part=part,
        parts=list(env.parts),
        min_clearance=env.min_clearance,
    )


def add_clearance(env: Surroundings, scene: Scene, result, times: np.ndarray, every: int) -> None:
    """Sets ``surroundings`` on every cable of ``result`` (also a partial one): its saved step
    k is step k·every of the run's grid ``times``; and the geometry for pictures on
    ``result.surroundings``."""
    longest = max((c.n_steps for c in result.cables.values()), default=0)
    if longest:
        steps = np.arange(longest) * every
        to_body = body_maps(scene, env.bodies, times, steps)
        rot = np.transpose(to_body[..., :3], (0, 1, 3, 2))  # R = Mᵀ
        poses = np.concatenate(
            [rot, -np.einsum("btij,btj->bti", rot, to_body[..., 3])[..., None]], -1
        )
        result.surroundings = SurroundingsGeometry(
            list(env.bodies), env.display_meshes(), times[steps], poses
        )
    for cable in scene.cables:
        c = result.cables.get(cable.name)
        if c is None or c.n_steps == 0:
            continue
        radius = cable.properties().outer_radius
        steps = np.arange(c.n_steps) * every
        c.surroundings = cable_clearance(env, scene, c.positions, radius, times, steps)
