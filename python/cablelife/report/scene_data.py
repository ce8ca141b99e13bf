"""What the report takes from a result's embedded scene: the bodies' poses at the saved steps
(for the 3D views) and the excitation the cable sees at its clips (for the natural frequencies
over the excitation spectrum)."""

from __future__ import annotations

import tomllib
from dataclasses import dataclass

import numpy as np

from cablelife.scene import Scene, SceneError, scene_from_dict


def result_scene(scene_toml: str) -> Scene:
    """The scene a result was computed from (``Result.scene_toml``); SceneError when the
    result has none or it does not validate."""
    if not scene_toml.strip():
        raise SceneError("the result holds no scene (scene_toml is empty)")
    try:
        data = tomllib.loads(scene_toml)
    except tomllib.TOMLDecodeError as err:
        raise SceneError(f"the result's scene_toml is not valid TOML: {err}") from None
    return scene_from_dict(data, source="embedded in the result")


def scene_times(scene: Scene, mode: str) -> np.ndarray:
    """The time grid the run evaluated the body motions on (as ``simulate`` does)."""
    from cablelife.simulate import output_times

    times = output_times(scene, mode)
    return times if times.size > 1 else np.array([times[0], times[0] + scene.simulation.time_step])


def nearest(grid: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Indices of the grid times (sorted) nearest to ``t``."""
    k = np.clip(np.searchsorted(grid, t), 1, grid.size - 1)
    return np.where(np.abs(grid[k - 1] - t) <= np.abs(grid[k] - t), k - 1, k)


@dataclass
class BodyPose:
    """A body at the requested times: origin (T, 3) and axes (T, 3, 3) (columns x, y, z),
    global; ``clips``: the cable's clips it carries."""

    name: str
    origin: np.ndarray
    axes: np.ndarray
    clips: list[str]
    moving: bool


def body_poses(scene: Scene, cable: str, times: np.ndarray, mode: str) -> list[BodyPose]:
    """Poses of every body of ``scene`` at ``times`` (the saved steps): the body motions on the
    run's time grid, taken at the nearest grid times."""
    from cablelife.signals import body_motion
    from cablelife.simulate import euler_matrix

    spec = next((c for c in scene.cables if c.name == cable), None)
    t = np.asarray(times, dtype=float)
    grid = scene_times(scene, mode) if mode != "static" else None
    out = []
    for body in scene.bodies:
        r0 = euler_matrix(body.orientation)
        origin = np.broadcast_to(np.asarray(body.origin, float), (t.size, 3)).copy()
        axes = np.broadcast_to(r0, (t.size, 3, 3)).copy()
        channels = body.channel_motions(scene.base_dir) if grid is not None else []
        if channels:
            m = body_motion(channels, grid, scene.base_dir, r0)
            k = nearest(grid, t)
            origin += m.translation[k]
            axes = m.rotation[k] @ r0
        clips = [c.name for c in spec.clips if c.body == body.name] if spec else []
        out.append(BodyPose(body.name, origin, axes, clips, bool(channels)))
    return out


@dataclass
class Excitation:
    """One-sided PSD (C, F) of the acceleration of each clip on a moving body (sum over x, y,
    z), in (m/s²)²/Hz, at frequencies ``frequency`` (F,) Hz (> 0)."""

    frequency: np.ndarray
    psd: np.ndarray
    labels: list[str]


def welch(x: np.ndarray, fs: float, nperseg: int) -> tuple[np.ndarray, np.ndarray]:
    """One-sided PSD of ``x`` along axis 0 by Welch's method as ``scipy.signal.welch(x, fs,
    nperseg=nperseg, axis=0)`` computes it (periodic Hann window, half overlap, each segment's
    mean removed, density scaling): (frequencies, PSD). By hand because importing
    ``scipy.signal`` costs 1.6 s, a third of the report's generation (docs/visuals.md);
    the report test compares it with scipy's."""
    n = x.shape[0]
    nperseg = min(nperseg, n)
    step = nperseg - nperseg // 2
    window = 0.5 - 0.5 * np.cos(2 * np.pi * np.arange(nperseg) / nperseg)
    starts = range(0, n - nperseg + 1, step)
    shape = (-1,) + (1,) * (x.ndim - 1)
    p = 0.0
    for k in starts:
        seg = x[k : k + nperseg]
        spec = np.fft.rfft((seg - seg.mean(axis=0)) * window.reshape(shape), axis=0)
        p = p + np.abs(spec) ** 2
    p = p / (len(starts) * fs * float(np.sum(window**2)))
    last = None if nperseg % 2 else -1  # the Nyquist bin of an even segment is not doubled
    p[1:last] *= 2
    return np.fft.rfftfreq(nperseg, 1.0 / fs), p


def excitation_psd(scene: Scene, cable: str, mode: str) -> Excitation:
    """The acceleration PSD at the cable's clips on moving bodies, from the body motions of the
    scene evaluated on the run's time grid (Welch, Hann; segments of 512 samples or an eighth
    of the record)."""
    from cablelife.simulate import clip_kinematics

    spec = next((c for c in scene.cables if c.name == cable), None)
    if spec is None:
        have = [c.name for c in scene.cables]
        raise SceneError(f"cable {cable!r} is not in the scene; it has {have}")
    if mode == "static":
        raise SceneError("a static run has no excitation")
    moving = {b.name for b in scene.bodies if b.motion or b.motion_file is not None}
    picked = [j for j, c in enumerate(spec.clips) if c.body in moving]
    if not picked:
        raise SceneError(f"no clip of cable {cable!r} sits on a moving body")
    times = scene_times(scene, mode)
    dt = float(times[1] - times[0])
    acc = clip_kinematics(scene, spec, times)["accelerations"][:, picked]  # (T, C, 3)
    n = times.size
    f, p = welch(acc, 1.0 / dt, min(n, max(512, n // 8)))
    psd = p.sum(axis=2).T  # (C, F)
    keep = f > 0
    labels = [f"clip {spec.clips[j].name} ({spec.clips[j].body})" for j in picked]
    return Excitation(f[keep], psd[:, keep], labels)


def signal_band(signal) -> tuple[float, float] | None:
    """(lowest, highest) frequency a signal definition excites, Hz: a sine its frequency, a
    sweep f0–f1, a PSD its band (f_low–f_high, default the breakpoints); None for measured
    signals and tables (no definition of a band)."""
    kind = getattr(signal, "type", None)
    if kind == "sine":
        return (float(signal.frequency), float(signal.frequency))
    if kind == "sweep":
        return (float(min(signal.f0, signal.f1)), float(max(signal.f0, signal.f1)))
    if kind == "psd":
        f = signal.psd().frequency
        lo = float(f[0] if signal.f_low is None else signal.f_low)
        hi = float(f[-1] if signal.f_high is None else signal.f_high)
        return (lo, hi)
    return None


def excited_band(scene: Scene, cable: str, exc: Excitation | None = None) -> tuple[float, float]:
    """The band the cable's clips are excited in: the union of the bands of the signals of the
    bodies that carry its clips (:func:`signal_band`), capped at the Nyquist frequency of the
    time step; where a signal defines no band (measured, table), the central 99 % of the
    variance of ``exc`` (:func:`cablelife.plots.spectrum.variance_band`), which the leakage of
    a fade-in does not widen the way a level below the peak does."""
    from cablelife.plots.spectrum import variance_band

    spec = next(c for c in scene.cables if c.name == cable)
    carriers = {c.body for c in spec.clips}
    bands = []
    for body in scene.bodies:
        if body.name not in carriers:
            continue
        for m in body.channel_motions(scene.base_dir):
            b = signal_band(m.signal)
            if b is None and exc is not None:
                b = variance_band(exc.frequency, exc.psd)
            if b is not None:
                bands.append(b)
    if not bands:
        if exc is None:
            raise SceneError(f"no clip of cable {cable!r} sits on a moving body")
        return variance_band(exc.frequency, exc.psd)
    nyquist = 0.5 / scene.simulation.time_step
    return (min(b[0] for b in bands), min(max(b[1] for b in bands), nyquist))
