"""Running a scene: clip poses from the body motions, the Rust solver per cable, the Result.

Several cables in one scene are independent systems; they run in parallel threads (the Rust
solver releases the GIL).
"""

from __future__ import annotations

import os
import time as _time
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor

import numpy as np
from scipy.spatial.transform import Rotation

from cablelife import _core
from cablelife.results import CableResult, ClipReaction, Result
from cablelife.scene import Cable, Scene, SceneError
from cablelife.signals import body_motion, time_grid

Progress = Callable[[str, int, int], None]


class SimulationError(RuntimeError):
    """A run that stopped early; ``result`` holds every step computed before the stop."""

    def __init__(self, message: str, result: Result):
        super().__init__(message)
        self.result = result


def frame_matrix(direction, normal=None) -> np.ndarray:
    """Rotation matrix with columns (d1, d2, d3): d3 along ``direction``, d1 the part of
    ``normal`` orthogonal to it (default: the global axis least aligned with d3)."""
    d3 = np.asarray(direction, float)
    d3 = d3 / np.linalg.norm(d3)
    if normal is None:
        normal = np.eye(3)[int(np.argmin(np.abs(d3)))]
    n = np.asarray(normal, float)
    d1 = n - d3 * n.dot(d3)
    d1 /= np.linalg.norm(d1)
    return np.column_stack([d1, np.cross(d3, d1), d3])


def euler_matrix(angles) -> np.ndarray:
    """R = Rz(rz) Ry(ry) Rx(rx) (rotations about the global axes, x first)."""
    return Rotation.from_euler("xyz", angles).as_matrix()


def output_times(scene: Scene, mode: str) -> np.ndarray:
    """The saved time steps of a run."""
    sim = scene.simulation
    if mode == "static":
        return np.array([0.0])
    if sim.duration is None:
        raise SceneError(f"simulation.duration is required in {mode} mode")
    return time_grid(sim.duration, sim.output_step or sim.time_step)


def clip_poses(scene: Scene, cable: Cable, times: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Clip positions (T, C, 3) and orientations as quaternions, scalar first (T, C, 4)."""
    n_t, n_c = times.size, len(cable.clips)
    grid = times if n_t > 1 else np.array([times[0], times[0] + scene.simulation.time_step])
    motions = {}
    for body in scene.bodies:
        r0 = euler_matrix(body.orientation)
        channels = body.channel_motions(scene.base_dir)
        motion = body_motion(channels, grid, scene.base_dir, r0) if channels else None
        motions[body.name] = (body, r0, motion)
    positions = np.empty((n_t, n_c, 3))
    frames = np.empty((n_t, n_c, 3, 3))
    for j, clip in enumerate(cable.clips):
        local = frame_matrix(clip.direction, clip.normal)
        pos = np.asarray(clip.position, float)
        if clip.body == "world":
            positions[:, j] = pos
            frames[:, j] = local
            continue
        body, r0, motion = motions[clip.body]
        origin = np.asarray(body.origin, float)
        if clip.frame == "body":
            pos, local = origin + r0 @ pos, r0 @ local
        if motion is None:
            positions[:, j] = pos
            frames[:, j] = local
            continue
        rot = motion.rotation[:n_t]
        positions[:, j] = origin + motion.translation[:n_t] + rot @ (pos - origin)
        frames[:, j] = rot @ local
    quats = Rotation.from_matrix(frames.reshape(-1, 3, 3)).as_quat(scalar_first=True)
    return positions, quats.reshape(n_t, n_c, 4)


def build_cable(scene: Scene, cable: Cable) -> _core.Cable:
    """The Rust solver object of one cable at its reference clip poses."""
    props = cable.properties()
    pos, quat = clip_poses(scene, cable, np.array([0.0]))
    clips = [
        (c.name, c.s, c.length, c.type, pos[0, j].tolist(), quat[0, j].tolist())
        for j, c in enumerate(cable.clips)
    ]
    loads = [(ld.s, list(ld.force), list(ld.moment)) for ld in cable.loads]
    try:
        return _core.Cable(
            cable.length,
            cable.n_segments,
            props.shear_stiffness,
            props.bend_stiffness,
            props.mass_per_length,
            list(props.rotary_inertia),
            list(cable.natural_curvature),
            list(scene.simulation.gravity),
            clips,
            loads,
            max_iterations=scene.simulation.max_iterations,
        )
    except ValueError as err:
        raise SceneError(f"cable '{cable.name}': {err}") from None


def _run_cable(scene: Scene, cable: Cable, times: np.ndarray, progress: Progress | None):
    core = build_cable(scene, cable)
    pos, quat = clip_poses(scene, cable, times)
    callback = (lambda k, n: progress(cable.name, k, n)) if progress else None
    start = _time.perf_counter()
    try:
        out = core.run_sequence(pos, quat, callback, max(1, times.size // 100))
    except ValueError as err:
        raise SceneError(f"cable '{cable.name}': {err}") from None
    wall = _time.perf_counter() - start
    n = int(out["steps"])
    props = cable.properties()
    clips = {
        c.name: ClipReaction(
            c.name, c.s, out["reaction_force"][:, j].copy(), out["reaction_moment"][:, j].copy()
        )
        for j, c in enumerate(cable.clips)
    }
    solver = {
        "iterations": out["iterations"],
        "substeps": out["substeps"],
        "residual": out["residual"],
        "segments": int(core.arc_length.size - 1),
        "wall_time": wall,
        "error": out["error"] or "",
    }
    res = CableResult(
        name=cable.name,
        time=times[:n].copy(),
        arc_length=core.arc_length,
        positions=out["positions"],
        quaternions=out["quaternions"],
        forces=out["forces"],
        moments=out["moments"],
        clips=clips,
        section=props.as_attrs(),
        solver=solver,
        energies={"elastic_energy": out["elastic_energy"]},
    )
    return res, out["error"]


def simulate(scene: Scene, mode: str | None = None, progress: Progress | None = None) -> Result:
    """Runs the scene (``mode`` overrides ``scene.simulation.mode``).

    Raises :class:`SimulationError` with the partial result if a cable's solve fails or the run
    is interrupted; :class:`SceneError` for an unusable scene.
    """
    mode = mode or scene.simulation.mode
    if mode not in ("static", "quasistatic"):
        raise SceneError(
            f"simulation.mode = {mode!r} is not available in this version; "
            "allowed: 'static', 'quasistatic'"
        )
    times = output_times(scene, mode)
    workers = max(1, min(len(scene.cables), os.cpu_count() or 1))
    with ThreadPoolExecutor(max_workers=workers) as pool:
        futures = [pool.submit(_run_cable, scene, c, times, progress) for c in scene.cables]
        outcomes = [f.result() for f in futures]
    cables = {res.name: res for res, _ in outcomes}
    errors = [f"cable '{res.name}': {err}" for res, err in outcomes if err]
    result = Result(
        mode=mode,
        cables=cables,
        scene_toml=scene.to_toml(),
        complete=not errors,
        message="; ".join(errors),
    )
    if errors:
        raise SimulationError(result.message, result)
    return result
