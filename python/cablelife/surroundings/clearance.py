"""Clearance of the cables of a result to the scene's surroundings (computed after the run,
in Rust, for every saved step and node). Ctrl-C (or ``interrupt.request_stop``) stops it
within a step; it reports its progress like the solvers."""

from __future__ import annotations

from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor

import numpy as np

from cablelife import interrupt
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
    progress: Callable[[int, int], None] | None = None,
    stop=None,
    maps: np.ndarray | None = None,
) -> CableClearance | None:
    """Clearance of one cable with node ``positions`` (S, N+1, 3) at the saved ``steps``
    (indices into the run's time grid ``times``); None if ``stop`` (a ``StopFlag``) was set
    before it was done. ``progress(done, total)``: steps done, every 50 ms. ``maps``: the
    bodies' maps at those steps (``body_maps``) when the caller has them."""
    if maps is None:
        maps = body_maps(scene, env.bodies, times, steps)
    out = env.core.clearance(np.ascontiguousarray(positions, float), radius, maps, progress, stop)
    if out is None:
        return None
    value, part = out
    part = part.astype(np.int64)
    return CableClearance(
        value=value,
        body=env.part_body[part],
        bodies=list(env.bodies),
        part=part,
        parts=list(env.parts),
        min_clearance=env.min_clearance,
    )


#: How the clearance's progress reports name a cable: ``progress(CLEARANCE_LABEL + name, …)``.
CLEARANCE_LABEL = "clearance of "


def add_clearance(
    env: Surroundings,
    scene: Scene,
    result,
    times: np.ndarray,
    every: int,
    progress: Callable[[str, int, int], None] | None = None,
) -> bool:
    """Sets ``surroundings`` on every cable of ``result`` (also a partial one): its saved step
    k is step k·every of the run's grid ``times``; and the geometry for pictures on
    ``result.surroundings``. ``progress(label, done, total)`` with the label "clearance of
    <cable>". Returns False if Ctrl-C (or ``interrupt.request_stop``) stopped it: the cables
    done before keep their clearance, the others have none."""
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

    def every_cable(stop) -> dict[str, CableClearance | None]:
        done: dict[str, CableClearance | None] = {}
        for cable in scene.cables:
            c = result.cables.get(cable.name)
            if c is None or c.n_steps == 0:
                continue
            radius = cable.properties().outer_radius
            steps = np.arange(c.n_steps) * every
            label = f"{CLEARANCE_LABEL}{cable.name}"
            report = (lambda k, n, label=label: progress(label, k, n)) if progress else None
            # the bodies' maps of the longest run, above (every cable's steps start at 0)
            maps = np.ascontiguousarray(to_body[:, : c.n_steps])
            done[cable.name] = cable_clearance(
                env, scene, c.positions, radius, times, steps, report, stop, maps
            )
            if done[cable.name] is None:
                break  # stopped
        return done

    # In a worker thread, as the solvers: the main thread waits for Ctrl-C meanwhile.
    with interrupt.stop_flag() as stop, ThreadPoolExecutor(max_workers=1) as pool:
        job = pool.submit(every_cable, stop)
        interrupt.wait_stopping([job], stop.set)
        done = job.result()
    for name, clearance in done.items():
        result.cables[name].surroundings = clearance
    return all(c is not None for c in done.values())
