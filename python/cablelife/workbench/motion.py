"""Body motion in the workbench: the bodies' motion signals on the quasistatic time grid, by
the code the runs use (``simulate.output_times``, ``body_motions``, ``clip_kinematics``), so
that the page can show the static equilibrium at any time of that grid (warm-started from the
last one: the quasistatic response, scrubbed). It is static equilibrium at each time, not
dynamics: no inertia, no damping."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from cablelife.scene import Scene, SceneError

#: Steps of the time slider at most (a finer grid is no use on a slider; memory stays small).
MAX_STEPS = 100_001


class MotionError(ValueError):
    """The scene's motion cannot be shown (no duration, contact); the message says why."""


@dataclass
class MotionTrack:
    """Clip poses and body maps on the quasistatic grid ``times`` (T,)."""

    times: np.ndarray
    # per cable (for a harness: the cables with their joined-end clips): (T, C, 3), (T, C, 4)
    poses: dict[str, tuple[np.ndarray, np.ndarray]]
    # per body: (T, 3, 4) [A | b], a point X of the body at rest goes to A X + b at time t
    maps: dict[str, np.ndarray]

    def body_map(self, name: str, k: int) -> np.ndarray:
        return self.maps[name][k]


def motion_track(scene: Scene) -> MotionTrack:
    """The motion of ``scene``'s bodies on its quasistatic output grid 0, time_step, …,
    duration. Raises MotionError when it cannot be shown."""
    from cablelife.simulate import body_motions, clip_kinematics, output_times

    if scene.simulation.duration is None:
        raise MotionError(
            "the scene has no simulation.duration: give duration and time_step (the "
            "quasistatic time grid) to see the bodies' motion"
        )
    if scene.contact is not None and scene.contact.enabled:
        raise MotionError(
            "contact is enabled: the workbench solves contact against the geometry at rest "
            "only; run `cablelife run` (quasistatic) to see the motion with contact"
        )
    times = output_times(scene, "quasistatic")
    if times.size > MAX_STEPS:
        raise MotionError(
            f"the quasistatic grid has {times.size} steps (duration "
            f"{scene.simulation.duration:g} s, step {times[1] - times[0]:g} s); the slider offers "
            f"at most {MAX_STEPS}: give a larger time_step (or output_step)"
        )
    try:
        motions = body_motions(scene, times)
        cables = scene.cables
        if scene.junctions:
            from cablelife.harness import harness_cables

            cables = harness_cables(scene)[0]
        poses = {}
        for cable in cables:
            kin = clip_kinematics(scene, cable, times, motions=motions)
            poses[cable.name] = (kin["positions"], kin["quaternions"])
    except (SceneError, ValueError, OSError) as err:
        raise MotionError(f"the bodies' motion cannot be evaluated: {err}") from None
    maps = {}
    for name, (body, _, motion) in motions.items():
        m = np.zeros((times.size, 3, 4))
        m[:, :, :3] = np.eye(3)
        if motion is not None:
            o = np.asarray(body.origin, float)
            rot = motion.rotation[: times.size]
            m[:, :, :3] = rot
            m[:, :, 3] = o + motion.translation[: times.size] - rot @ o  # o + u + R(X − o)
        maps[name] = m
    return MotionTrack(times=times, poses=poses, maps=maps)
