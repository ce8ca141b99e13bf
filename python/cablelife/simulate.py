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

from cablelife import _core, interrupt
from cablelife.contact_settings import set_contact
from cablelife.limits import LIMITS, MAX_RUN_BYTES, human_bytes, run_bytes
from cablelife.results import CONTACT_KEYS, CableResult, ClipReaction, Result
from cablelife.rotations import euler_matrix, matrix_quaternions
from cablelife.scene import Cable, Scene, SceneError
from cablelife.signals import body_motion, time_grid
from cablelife.surroundings.build import load_surroundings
from cablelife.surroundings.clearance import add_clearance

Progress = Callable[[str, int, int], None]

#: ``Result.message`` of a run whose clearance Ctrl-C stopped (every step of it is saved).
CLEARANCE_INTERRUPTED = (
    f"{interrupt.INTERRUPTED}: the clearance was not computed (every step of the run is saved)"
)


class SimulationError(RuntimeError):
    """A run that stopped early; ``result`` holds every step computed before the stop
    (``result.complete`` is False, ``result.message`` says why: "interrupted" after Ctrl-C);
    ``kept`` says what it holds, when not the steps before the stop."""

    def __init__(self, message: str, result: Result, kept: str | None = None):
        super().__init__(message)
        self.result = result
        self.kept = kept

    @property
    def interrupted(self) -> bool:
        """The run was stopped on request (Ctrl-C), not by a solver failure."""
        return self.result.message.startswith(interrupt.INTERRUPTED)


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
    (a0, a1, a2), (b0, b1, b2) = d3.tolist(), d1.tolist()  # d2 = d3 × d1
    d2 = (a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0)
    return np.array([[b0, d2[0], a0], [b1, d2[1], a1], [b2, d2[2], a2]])


def _grid_steps(duration: float, time_step: float) -> float:
    """Points of the grid 0, time_step, …, duration (a float: may be inf for absurd input)."""
    return float(np.floor(duration / time_step + 1e-9)) + 1.0


def _needs_run_grid(scene: Scene) -> bool:
    """Whether a body's motion depends on the run's whole time grid even at t = 0: PSD
    realisations are drawn on it, measured signals are filtered at its Nyquist frequency."""
    return any(m.signal.type in ("psd", "measured") for b in scene.bodies for m in b.motion)


def check_run_size(scene: Scene, mode: str) -> None:
    """Refuses a run whose signals and results would not fit the memory limit, before
    anything is allocated (docs/scene.md, Limits)."""
    sim = scene.simulation
    if sim.duration is None:
        return
    if mode == "static":
        if not _needs_run_grid(scene):
            return
        steps, saved = _grid_steps(sim.duration, sim.time_step), 1
    elif mode == "dynamic":
        steps = _grid_steps(sim.duration, sim.time_step)
        saved = _grid_steps(sim.duration, sim.output_step or sim.time_step)
    else:
        steps = saved = _grid_steps(sim.duration, sim.output_step or sim.time_step)
    cables = [(c.n_segments, len(c.clips)) for c in scene.cables]
    need = run_bytes(steps, saved, cables, len(scene.bodies))
    if need > MAX_RUN_BYTES:
        raise SceneError(
            f"simulation.time_step = {sim.time_step:g} s over duration = {sim.duration:g} s "
            f"is {steps:.4g} time steps ({saved:.4g} saved, {mode} mode); the signals and "
            f"results would need about {human_bytes(need)} of memory, allowed: "
            f"{human_bytes(MAX_RUN_BYTES)}; use a larger time_step or output_step, a shorter "
            "duration or fewer segments"
        )


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


def body_motions(scene: Scene, times: np.ndarray, with_motion: bool = True) -> dict:
    """Per body name: (body, R0 its axes at rest, its BodyMotion on ``times`` or None when it
    does not move). Clips and the surroundings' geometry move with these motions."""
    grid = times
    if times.size == 1:  # one pose (static run): the motions' value at that time on their grid
        sim = scene.simulation
        grid = (  # on the run's grid only where the value depends on it (PSD, measured)
            time_grid(sim.duration, sim.time_step, times[0])
            if sim.duration is not None
            and sim.duration > sim.time_step
            and with_motion
            and _needs_run_grid(scene)
            else np.array([times[0], times[0] + sim.time_step])
        )
    motions = {}
    for body in scene.bodies:
        r0 = euler_matrix(body.orientation)
        allow = scene.files.allow_outside
        channels = body.channel_motions(scene.base_dir, allow) if with_motion else []
        motion = body_motion(channels, grid, scene.base_dir, r0, allow) if channels else None
        motions[body.name] = (body, r0, motion)
    return motions


def clip_kinematics(
    scene: Scene, cable: Cable, times: np.ndarray, with_motion: bool = True, motions=None
) -> dict[str, np.ndarray]:
    """Clip kinematics on ``times``: positions (T, C, 3), quaternions scalar first (T, C, 4),
    velocities, angular velocities, accelerations, angular accelerations (T, C, 3), global.
    Without ``with_motion``: the reference poses (bodies at rest). ``motions``: the
    :func:`body_motions` on ``times`` if already at hand (several cables)."""
    n_t, n_c = times.size, len(cable.clips)
    if motions is None:
        motions = body_motions(scene, times, with_motion)
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
    # per clip its frame: one matrix for a clip at rest, else (T, 3, 3); to quaternions below
    frames: list[np.ndarray] = []
    for j, clip in enumerate(cable.clips):
        local = frame_matrix(clip.direction, clip.normal)
        pos = np.asarray(clip.position, float)
        if clip.body == "world":
            out["positions"][:, j] = pos
            frames.append(local)
            continue
        body, r0, motion = motions[clip.body]
        origin = np.asarray(body.origin, float)
        if clip.frame == "body":
            pos, local = origin + r0 @ pos, r0 @ local
        if motion is None:
            out["positions"][:, j] = pos
            frames.append(local)
            continue
        if not motion.rotates:  # R = I, ω = α = 0: the same values as below, T times cheaper
            out["positions"][:, j] = origin + motion.translation[:n_t] + (pos - origin)
            out["velocities"][:, j] = motion.velocity[:n_t]
            out["accelerations"][:, j] = motion.acceleration[:n_t]
            frames.append(local)
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
        frames.append(rot @ local)
    _check_clip_motion(cable, times, out)
    # one conversion for all clips; a clip at rest converts its one matrix (the same
    # quaternion as each of T copies)
    out["quaternions"] = np.empty((n_t, n_c, 4))
    if frames:
        stacked = [f.reshape(-1, 3, 3) for f in frames]
        quats = matrix_quaternions(np.concatenate(stacked))
        start = 0
        for j, f in enumerate(stacked):
            out["quaternions"][:, j] = quats[start : start + len(f)]
            start += len(f)
    return out


def _check_clip_motion(cable: Cable, times: np.ndarray, kin: dict[str, np.ndarray]) -> None:
    """The body motions keep every clip finite and inside the coordinate range (a signal of
    1e300 m, or a unit mistake, fails here with names instead of in the solver)."""
    lo, hi = LIMITS["coordinate"]
    for key in ("positions", "velocities", "accelerations", "angular_velocities"):
        a = kin[key]
        bad = ~np.isfinite(a) | ((a < lo) | (a > hi) if key == "positions" else False)
        if bad.any():
            t, j, _ = np.argwhere(bad)[0]
            clip = cable.clips[j]
            raise SceneError(
                f"cable '{cable.name}', clip '{clip.name}' (body '{clip.body}'): the body "
                f"motion gives {key} {a[t, j].tolist()} at t = {times[min(t, times.size - 1)]:g} "
                f"s; allowed: finite values, positions within {lo:g} … {hi:g} m (check the "
                "motion's amplitude and unit)"
            )


# A dynamic step cannot follow a clip that turns by more than this within it (rad): the
# generalised-α step linearises the rotation over the step.
MAX_TURN_PER_STEP = 1.0


def check_turn_per_step(cable: Cable, kin: dict[str, np.ndarray], time_step: float) -> None:
    """A dynamic run's clips turn by at most ``MAX_TURN_PER_STEP`` per time step (a rotation
    amplitude in degrees given as radians, or a runaway signal, fails here with names instead
    of as a Newton failure at the first step)."""
    turn = np.linalg.norm(kin["angular_velocities"], axis=-1) * time_step  # (T, C)
    if turn.size and turn.max() > MAX_TURN_PER_STEP:
        t, j = np.unravel_index(np.argmax(turn), turn.shape)
        clip = cable.clips[j]
        raise SceneError(
            f"cable '{cable.name}', clip '{clip.name}' (body '{clip.body}'): the body motion "
            f"turns the clip by {turn[t, j]:.3g} rad within one time step (angular velocity "
            f"{turn[t, j] / time_step:.3g} rad/s at step {t}, time_step = {time_step:g} s); "
            f"allowed: at most {MAX_TURN_PER_STEP:g} rad per step, which a dynamic run can follow "
            "(check the rotation amplitude and its unit — radians — or reduce time_step)"
        )


def clip_poses(
    scene: Scene, cable: Cable, times: np.ndarray, with_motion: bool = True
) -> tuple[np.ndarray, np.ndarray]:
    """Clip positions (T, C, 3) and orientations as quaternions, scalar first (T, C, 4)."""
    k = clip_kinematics(scene, cable, times, with_motion)
    return k["positions"], k["quaternions"]


def build_cable(scene: Scene, cable: Cable, check: bool = True) -> _core.Cable:
    """The Rust solver object of one cable at its reference clip poses; ``check``: warn when
    its tangent stiffness there is ill-conditioned (off for helper builds whose cable is
    built and checked again for the run)."""
    props = cable.properties()
    pos, quat = clip_poses(scene, cable, np.array([0.0]), with_motion=False)
    clips = [
        (c.name, c.s, c.length, c.type, pos[0, j].tolist(), quat[0, j].tolist())
        for j, c in enumerate(cable.clips)
    ]
    loads = [(ld.s, list(ld.force), list(ld.moment)) for ld in cable.loads]
    try:
        core = _core.Cable(
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
            clip_axes={c.name: list(c.axis) for c in cable.clips if c.axis is not None},
            clip_friction={c.name: c.friction for c in cable.clips if c.type == "sliding"},
        )
    except ValueError as err:
        raise SceneError(f"cable '{cable.name}': {err}") from None
    used = int(core.arc_length.size - 1)
    if cable.segments is not None and used > cable.segments:
        raise SceneError(
            f"cable '{cable.name}': segments = {cable.segments}, but its clips and loads split "
            f"the cable into {used} intervals that need one segment each; allowed: segments "
            f">= {used} (or max_segment_length)"
        )
    if check:
        _check_conditioning(cable, props, core)
    return core


def _check_conditioning(cable: Cable, props, core: _core.Cable) -> None:
    """Warns when the tangent stiffness at the initial routing is ill-conditioned."""
    from cablelife import validity

    try:
        condition = core.condition()[0]
    except ValueError:
        return  # a kinked routing: the solve reports it
    msg = validity.conditioning_message(cable.name, props, core.arc_length, condition)
    validity.report([msg] if msg else [], validity.ConditioningWarning)


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
    try:
        set_contact(core, scene, cable, times)
    except ValueError as err:
        raise SceneError(f"cable '{cable.name}': {err}") from None
    callback = (lambda k, n: progress(cable.name, k, n)) if progress else None
    solver: dict = {}
    start = _time.perf_counter()
    try:
        if mode == "dynamic":
            from cablelife.modal import retardation_times

            tau_shear, tau_bend, info = retardation_times(scene, cable)
            every = output_every(scene)
            kin = clip_kinematics(scene, cable, times)
            check_turn_per_step(cable, kin, scene.simulation.time_step)
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
                bending_share=info.get("bending_share", float("nan")),
            )
        else:
            pos, quat = clip_poses(scene, cable, times)
            out = core.run_sequence(pos, quat, callback, max(1, times.size // 100), stop=stop)
            saved = times
    except SceneError:
        raise  # already names the cable
    except ValueError as err:
        raise SceneError(f"cable '{cable.name}': {err}") from None
    wall = _time.perf_counter() - start
    n = int(out["steps"])
    props = cable.properties()
    clips = {
        c.name: ClipReaction(
            c.name,
            c.s,
            out["reaction_force"][:, j].copy(),
            out["reaction_moment"][:, j].copy(),
            out["slid_length"][:, j].copy() if c.type == "sliding" else None,
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
    solver.update(_stability_info(out, saved[:n], core.arc_length, cable.name))
    energies = {"elastic_energy": out["elastic_energy"]}
    if mode == "dynamic":
        from cablelife import validity

        solver["viscous_peak"] = np.asarray(out["viscous_peak"])
        solver["unresolved_gain"] = np.asarray(out["unresolved_gain"])
        solver["impact_dissipation"] = np.asarray(out["impact_dissipation"])
        validity.report(
            validity.impact_messages(
                f"cable '{cable.name}'",
                solver["unresolved_gain"],
                saved[:n],
                solver["impact_dissipation"],
            ),
            validity.ImpactWarning,
        )
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
        contact={k: out[k] for k in CONTACT_KEYS if k in out},
    )
    if "contact_energy" in out and res.contact:
        res.energies["contact_energy"] = out["contact_energy"]
    return res, _with_time(out["error"], saved)


def _with_time(error: str | None, times: np.ndarray) -> str | None:
    """A sequence's error "step k: …" with the time of step k (dynamic errors carry it)."""
    head, sep, rest = (error or "").partition(": ")
    k = head.removeprefix("step ")
    if not (sep and k.isdigit() and int(k) < times.size):
        return error
    return f"step {k} (t = {times[int(k)]:g} s): {rest}"


def _stability_info(out: dict, times: np.ndarray, arc: np.ndarray, name: str) -> dict:
    """Solver entries on stability and mounting: ``unstable`` (T,) negative eigenvalues of
    the tangent stiffness per saved step (0: stable; −1: dynamic step, not checked), the
    snap-throughs (time, arc length and size of the largest jump), the largest span pre-strain;
    warnings for unstable states, snap-throughs and stretched spans."""
    from cablelife import validity

    info = {"unstable": np.asarray(out["unstable"])}
    info.update(
        validity.snap_events(
            times, arc, out["snap_fraction"], out["snap_jump"], np.asarray(out["snap_node"])
        )
    )
    spans = out.get("spans", [])
    info["prestrain"] = max((chord / length - 1.0 for _, _, chord, length in spans), default=0.0)
    messages = []
    bad = np.flatnonzero(info["unstable"] > 0)
    if bad.size:
        messages.append(
            f"cable '{name}': {bad.size} saved static state(s) are unstable (first at "
            f"t = {times[bad[0]]:.4g} s, {info['unstable'][bad[0]]} negative stiffness "
            "eigenvalue(s)) and no stable equilibrium was found from them"
        )
    for t, s_, jump in zip(info["snap_time"], info["snap_s"], info["snap_jump"], strict=True):
        messages.append(
            f"cable '{name}': snap-through at t = {t:.4g} s: the equilibrium became unstable "
            f"and the cable jumped to a stable one, by up to {jump:.3g} m at s = {s_:.3f} m"
        )
    validity.report(messages, validity.StabilityWarning)
    validity.report(validity.prestrain_messages(name, spans), validity.PrestrainWarning)
    return info


def _check_strains(scene: Scene, cables) -> list[str]:
    """Strains outside the model's validity range: warnings, or errors with
    ``simulation.strain_limit = "error"`` (docs/solver.md)."""
    from cablelife import validity

    messages = [m for c in cables for m in validity.strain_violations(c)]
    if scene.simulation.strain_limit == "error":
        return messages
    validity.report(messages, validity.StrainLimitWarning)
    return []


def _simulate_harness(scene: Scene, mode: str, times: np.ndarray, env, progress) -> Result:
    """A scene with junctions: one harness system (cablelife.harness)."""
    from cablelife.harness import run_harness

    with interrupt.stop_flag() as stop:
        cables, junctions, error, energies = run_harness(scene, times, mode, progress, stop)
    errors = [f"harness: {error}"] if error else []
    stopped = error == interrupt.INTERRUPTED
    errors += _check_strains(scene, cables.values())
    result = Result(
        mode=mode,
        cables=cables,
        scene_toml=scene.to_toml(),
        complete=not errors,
        message=interrupt.INTERRUPTED if stopped else "; ".join(errors),
        precision=scene.simulation.output_precision,
        junctions=junctions,
        harness_energies=energies,
    )
    _clearance(env, scene, result, times, mode, progress, stopped)
    if errors:
        raise SimulationError(result.message, result)
    return result


def _clearance(env, scene: Scene, result: Result, times, mode: str, progress, stopped: bool):
    """The clearance of the run's cables, unless the run was interrupted (Ctrl-C: the user
    asked it to stop, and a partial run's clearance may take long); Ctrl-C while it is computed
    ends the command with the whole run saved without it (SimulationError)."""
    if env is None or stopped:
        return
    every = output_every(scene) if mode == "dynamic" else 1
    failure = "" if result.complete else result.message  # a run that failed before
    if not add_clearance(env, scene, result, times, every, progress):
        result.complete = False
        result.message = CLEARANCE_INTERRUPTED
        kept = "every step of the run, without the clearance: interrupted while computing it"
        if failure:
            result.message = f"{interrupt.INTERRUPTED}: the clearance was not computed; {failure}"
            kept = "the steps before the failure, without the clearance: interrupted"
        raise SimulationError(result.message, result, kept=kept)


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
    check_run_size(scene, mode)
    times = output_times(scene, mode)
    env = load_surroundings(scene)  # reads and checks the geometry before the run
    if scene.junctions:
        return _simulate_harness(scene, mode, times, env, progress)
    workers = max(1, min(len(scene.cables), os.cpu_count() or 1))
    # The cables run in threads: their warnings are collected and given again from here, so
    # that they point at the caller of simulate(), not at the thread pool's internals.
    with warnings.catch_warnings(record=True) as caught:
        with interrupt.stop_flag() as stop, ThreadPoolExecutor(max_workers=workers) as pool:
            futures = [
                pool.submit(_run_cable, scene, c, times, mode, progress, stop) for c in scene.cables
            ]
            interrupt.wait_stopping(futures, stop.set)  # Ctrl-C: the runs end after their step
            outcomes = [f.result() for f in futures]
    for w in caught:
        warnings.warn(w.message, w.category, stacklevel=2)
    cables = {res.name: res for res, _ in outcomes}
    errors = [f"cable '{res.name}': {err}" for res, err in outcomes if err]
    stopped = any(err == interrupt.INTERRUPTED for _, err in outcomes) and all(
        err in (None, interrupt.INTERRUPTED) for _, err in outcomes
    )
    errors += _check_strains(scene, cables.values())
    result = Result(
        mode=mode,
        cables=cables,
        scene_toml=scene.to_toml(),
        complete=not errors,
        message=interrupt.INTERRUPTED if errors and stopped else "; ".join(errors),
        precision=scene.simulation.output_precision,
    )
    _clearance(env, scene, result, times, mode, progress, stopped)
    if errors:
        raise SimulationError(result.message, result)
    return result
