"""Running a scene: clip poses from the body motions, the Rust solver per cable, the Result.

Several cables in one scene are independent systems; they run in parallel threads (the Rust
solver releases the GIL).
"""

from __future__ import annotations

import os
import time as _time
import warnings
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor

import numpy as np
from scipy.spatial.transform import Rotation

from cablelife import _core, interrupt
from cablelife.results import CableResult, ClipReaction, Result
from cablelife.scene import Cable, Scene, SceneError
from cablelife.signals import body_motion, time_grid

Progress = Callable[[str, int, int], None]


class SimulationError(RuntimeError):
    """A run that stopped early; ``result`` holds every step computed before the stop
    (``result.complete`` is False, ``result.message`` says why: "interrupted" after Ctrl-C)."""

    def __init__(self, message: str, result: Result):
        super().__init__(message)
        self.result = result

    @property
    def interrupted(self) -> bool:
        """The run was stopped on request (Ctrl-C), not by a solver failure."""
        return self.result.message == interrupt.INTERRUPTED


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
    """The time grid of a run: the saved steps (static, quasistatic) or the integration
    steps (dynamic; every ``output_every``-th is saved)."""
    sim = scene.simulation
    if mode == "static":
        return np.array([0.0])
    if sim.duration is None:
        raise SceneError(f"simulation.duration is required in {mode} mode")
    if mode == "dynamic":
        return time_grid(sim.duration, sim.time_step)  # the integration steps
    return time_grid(sim.duration, sim.output_step or sim.time_step)


def clip_kinematics(
    scene: Scene, cable: Cable, times: np.ndarray, with_motion: bool = True
) -> dict[str, np.ndarray]:
    """Clip kinematics on ``times``: positions (T, C, 3), quaternions scalar first (T, C, 4),
    velocities, angular velocities, accelerations, angular accelerations (T, C, 3), global.
    Without ``with_motion``: the reference poses (bodies at rest)."""
    n_t, n_c = times.size, len(cable.clips)
    grid = times
    if n_t == 1:  # one pose (static run): the motions' value at that time on their usual grid
        sim = scene.simulation
        grid = (
            time_grid(sim.duration, sim.time_step, times[0])
            if sim.duration is not None and sim.duration > sim.time_step
            else np.array([times[0], times[0] + sim.time_step])
        )
    motions = {}
    for body in scene.bodies:
        r0 = euler_matrix(body.orientation)
        channels = body.channel_motions(scene.base_dir) if with_motion else []
        motion = body_motion(channels, grid, scene.base_dir, r0) if channels else None
        motions[body.name] = (body, r0, motion)
    out = {
        k: np.zeros((n_t, n_c, 3))
        for k in (
            "positions",
            "velocities",
            "angular_velocities",
            "accelerations",
            "angular_accelerations",
        )
    }
    frames = np.empty((n_t, n_c, 3, 3))
    for j, clip in enumerate(cable.clips):
        local = frame_matrix(clip.direction, clip.normal)
        pos = np.asarray(clip.position, float)
        if clip.body == "world":
            out["positions"][:, j] = pos
            frames[:, j] = local
            continue
        body, r0, motion = motions[clip.body]
        origin = np.asarray(body.origin, float)
        if clip.frame == "body":
            pos, local = origin + r0 @ pos, r0 @ local
        if motion is None:
            out["positions"][:, j] = pos
            frames[:, j] = local
            continue
        rot = motion.rotation[:n_t]
        arm = rot @ (pos - origin)  # r = R(X − o)
        w, alpha = motion.angular_velocity[:n_t], motion.angular_acceleration[:n_t]
        out["positions"][:, j] = origin + motion.translation[:n_t] + arm
        out["velocities"][:, j] = motion.velocity[:n_t] + np.cross(w, arm)
        out["accelerations"][:, j] = (
            motion.acceleration[:n_t] + np.cross(alpha, arm) + np.cross(w, np.cross(w, arm))
        )
        out["angular_velocities"][:, j] = w
        out["angular_accelerations"][:, j] = alpha
        frames[:, j] = rot @ local
    quats = Rotation.from_matrix(frames.reshape(-1, 3, 3)).as_quat(scalar_first=True)
    out["quaternions"] = quats.reshape(n_t, n_c, 4)
    return out


def clip_poses(
    scene: Scene, cable: Cable, times: np.ndarray, with_motion: bool = True
) -> tuple[np.ndarray, np.ndarray]:
    """Clip positions (T, C, 3) and orientations as quaternions, scalar first (T, C, 4)."""
    k = clip_kinematics(scene, cable, times, with_motion)
    return k["positions"], k["quaternions"]


def build_cable(scene: Scene, cable: Cable) -> _core.Cable:
    """The Rust solver object of one cable at its reference clip poses."""
    props = cable.properties()
    pos, quat = clip_poses(scene, cable, np.array([0.0]), with_motion=False)
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


def output_every(scene: Scene) -> int:
    """Integration steps per saved step of a dynamic run."""
    sim = scene.simulation
    if sim.output_step is None:
        return 1
    ratio = sim.output_step / sim.time_step
    k = round(ratio)
    if k < 1 or abs(ratio - k) > 1e-6 * ratio:
        raise SceneError(
            f"simulation.output_step = {sim.output_step} s must be a whole multiple of "
            f"time_step = {sim.time_step} s"
        )
    return k


class StartUpWarning(UserWarning):
    """A dynamic run starts with moving clips while the cable is at rest."""


def _warn_moving_start(cable: Cable, kin: dict[str, np.ndarray]) -> None:
    """Warn when a clip's velocity at t = 0 is a sizeable part of its largest velocity: the
    cable starts at rest in its static equilibrium, so the run begins with a start-up transient
    (large damping forces in the first steps) that also enters the fatigue analysis."""
    for key, unit in (("velocities", "m/s"), ("angular_velocities", "rad/s")):
        v = np.linalg.norm(kin[key], axis=-1)  # (T, C)
        peak = v.max(axis=0)
        for j, clip in enumerate(cable.clips):
            if peak[j] > 0 and v[0, j] > 0.05 * peak[j]:
                warnings.warn(
                    f"cable '{cable.name}', clip '{clip.name}': the motion starts with "
                    f"{v[0, j]:.3g} {unit} ({100 * v[0, j] / peak[j]:.0f} % of its peak) while "
                    "the cable starts at rest: expect a start-up transient; fade the signal in "
                    "(fade_in = ... s on sine and psd signals)",
                    StartUpWarning,
                    stacklevel=4,
                )
                return


def _run_cable(
    scene: Scene,
    cable: Cable,
    times: np.ndarray,
    mode: str,
    progress: Progress | None,
    stop: _core.StopFlag | None = None,
):
    core = build_cable(scene, cable)
    callback = (lambda k, n: progress(cable.name, k, n)) if progress else None
    solver: dict = {}
    start = _time.perf_counter()
    try:
        if mode == "dynamic":
            from cablelife.modal import retardation_times

            tau_shear, tau_bend, info = retardation_times(scene, cable)
            every = output_every(scene)
            kin = clip_kinematics(scene, cable, times)
            _warn_moving_start(cable, kin)
            start = _time.perf_counter()
            out = core.run_dynamic(
                scene.simulation.time_step,
                kin["positions"],
                kin["quaternions"],
                kin["velocities"],
                kin["angular_velocities"],
                kin["accelerations"],
                kin["angular_accelerations"],
                every,
                tau_shear,
                tau_bend,
                scene.simulation.spectral_radius,
                scene.simulation.newton_tolerance,
                callback,
                max(1, times.size // 200),
                stop=stop,
            )
            saved = times[::every]
            solver.update(
                spectral_radius=scene.simulation.spectral_radius,
                newton_tolerance=scene.simulation.newton_tolerance,
                time_step=scene.simulation.time_step,
                tau_shear=np.array(tau_shear),
                tau_bend=np.array(tau_bend),
                damping_source=info["source"],
                damping_ratio=info.get("ratio", float("nan")),
                omega1=info.get("omega1", float("nan")),
            )
        else:
            pos, quat = clip_poses(scene, cable, times)
            out = core.run_sequence(pos, quat, callback, max(1, times.size // 100), stop=stop)
            saved = times
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
    simulated = float(saved[n - 1] - saved[0]) if n > 1 else 0.0
    solver.update(
        iterations=out["iterations"],
        substeps=out["substeps"],
        residual=out["residual"],
        segments=int(core.arc_length.size - 1),
        wall_time=wall,
        real_time_factor=wall / simulated if simulated > 0 else float("nan"),
        error=out["error"] or "",
    )
    energies = {"elastic_energy": out["elastic_energy"]}
    if mode == "dynamic":
        energies.update(
            kinetic_energy=out["kinetic_energy"],
            dissipated_energy=out["dissipated_energy"],
            load_potential=out["load_potential"],
        )
    res = CableResult(
        name=cable.name,
        time=saved[:n].copy(),
        arc_length=core.arc_length,
        positions=out["positions"],
        quaternions=out["quaternions"],
        forces=out["forces"],
        moments=out["moments"],
        clips=clips,
        section=props.as_attrs(),
        solver=solver,
        energies=energies,
    )
    return res, out["error"]


def simulate(scene: Scene, mode: str | None = None, progress: Progress | None = None) -> Result:
    """Runs the scene (``mode`` overrides ``scene.simulation.mode``).

    Raises :class:`SimulationError` with the partial result if a cable's solve fails or the run
    is interrupted (Ctrl-C, or :func:`cablelife.interrupt.request_stop` from another thread: the
    solver threads stop after their current step); :class:`SceneError` for an unusable scene.
    """
    mode = mode or scene.simulation.mode
    if mode not in ("static", "quasistatic", "dynamic"):
        raise SceneError(
            f"mode = {mode!r} is not a simulation mode; allowed: 'static', 'quasistatic', 'dynamic'"
        )
    times = output_times(scene, mode)
    workers = max(1, min(len(scene.cables), os.cpu_count() or 1))
    with interrupt.stop_flag() as stop, ThreadPoolExecutor(max_workers=workers) as pool:
        futures = [
            pool.submit(_run_cable, scene, c, times, mode, progress, stop) for c in scene.cables
        ]
        interrupt.wait_stopping(futures, stop.set)  # Ctrl-C: the runs end after their step
        outcomes = [f.result() for f in futures]
    cables = {res.name: res for res, _ in outcomes}
    errors = [f"cable '{res.name}': {err}" for res, err in outcomes if err]
    stopped = all(err in (None, interrupt.INTERRUPTED) for _, err in outcomes)
    result = Result(
        mode=mode,
        cables=cables,
        scene_toml=scene.to_toml(),
        complete=not errors,
        message=interrupt.INTERRUPTED if errors and stopped else "; ".join(errors),
    )
    if errors:
        raise SimulationError(result.message, result)
    return result
