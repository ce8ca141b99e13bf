"""Rigid body motion from channel signals.

Conventions (o the body origin, R0 the body axes at rest — identity unless given):
- A body point at rest position X (global) moves to  x(t) = o + u(t) + R(t) (X − o).
- Rotation: R(t) = R_g(t) · R0 R_b(t) R0ᵀ, with
  R_g = Rz(rz) · Ry(ry) · Rx(rx) from the "global" channels (extrinsic x-y-z: about the fixed
  global axes, first x, then y, then z), and
  R_b = Rx(rx) · Ry(ry) · Rz(rz) from the "body" channels (intrinsic x-y′-z″: about the body's
  own axes, first x, then the new y, then the newest z).
  The body rotations act first (in the body's axes), the global ones after.
- Translation: u(t) = u_g(t) + R(t) R0 u_b(t): "global" channels add directly, "body" channels
  are along the body's current axes.
- Several signals on the same channel and frame add.
Velocities and accelerations are the exact time derivatives of these expressions, built from
each channel's derivatives (see ``generate.kinematics``).
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from cablelife.signals.errors import SignalError, SignalWarning
from cablelife.signals.generate import kinematics
from cablelife.signals.kinematics import Kinematics, time_step_of
from cablelife.signals.spec import ROTATIONS, TRANSLATIONS, ChannelMotion, PsdSignal

_AXES = {"x": 0, "y": 1, "z": 2, "rx": 0, "ry": 1, "rz": 2}


@dataclass
class BodyMotion:
    """Rigid motion of one body on a uniform time grid (global frame, SI units)."""

    time: np.ndarray  # (T,) s
    translation: np.ndarray  # (T, 3) m, displacement u of the body origin
    rotation: np.ndarray  # (T, 3, 3) rotation matrices R
    velocity: np.ndarray  # (T, 3) m/s of the origin
    angular_velocity: np.ndarray  # (T, 3) rad/s
    acceleration: np.ndarray  # (T, 3) m/s² of the origin
    angular_acceleration: np.ndarray  # (T, 3) rad/s²
    rotates: bool = True  # False: R(t) = I, ω = α = 0 at every t (no rotation channel moves)

    def positions(self, points: np.ndarray, origin: np.ndarray) -> np.ndarray:
        """(T, P, 3) positions of body points at rest positions ``points`` (P, 3)."""
        r = np.asarray(points, float) - np.asarray(origin, float)
        return (
            np.asarray(origin, float)
            + self.translation[:, None, :]
            + np.einsum("tij,pj->tpi", self.rotation, r)
        )

    def point_velocities(self, points: np.ndarray, origin: np.ndarray) -> np.ndarray:
        """(T, P, 3) velocities ẋ = u̇ + ω × R (X − o)."""
        arm = self._arms(points, origin)
        return self.velocity[:, None, :] + np.cross(self.angular_velocity[:, None, :], arm)

    def point_accelerations(self, points: np.ndarray, origin: np.ndarray) -> np.ndarray:
        """(T, P, 3) accelerations ẍ = ü + α × r + ω × (ω × r), r = R (X − o)."""
        arm = self._arms(points, origin)
        w = self.angular_velocity[:, None, :]
        return (
            self.acceleration[:, None, :]
            + np.cross(self.angular_acceleration[:, None, :], arm)
            + np.cross(w, np.cross(w, arm))
        )

    def _arms(self, points, origin) -> np.ndarray:
        r = np.asarray(points, float) - np.asarray(origin, float)
        return np.einsum("tij,pj->tpi", self.rotation, r)


def axis_rotation(axis: np.ndarray, angle: np.ndarray) -> np.ndarray:
    """(T, 3, 3) rotations by ``angle`` (T,) about the unit vector ``axis`` (Rodrigues)."""
    n = np.asarray(axis, float)
    k = np.array([[0, -n[2], n[1]], [n[2], 0, -n[0]], [-n[1], n[0], 0]])
    s, c = np.sin(angle)[:, None, None], np.cos(angle)[:, None, None]
    return np.eye(3) + s * k + (1 - c) * (k @ k)


def compose_rotations(
    factors: list[tuple[np.ndarray, Kinematics]], n: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray, bool]:
    """R = R1 R2 ... of rotations about fixed axes n_i (in the frame to their left).

    Returns R (T,3,3), the spatial angular velocity ω = Σ θ̇_i a_i with a_i = R1..R_{i-1} n_i,
    α = Σ θ̈_i a_i + θ̇_i (ω_{<i} × a_i), and whether any factor moves (else R = I).
    """
    rotation = np.broadcast_to(np.eye(3), (n, 3, 3)).copy()
    omega = np.zeros((n, 3))
    alpha = np.zeros((n, 3))
    moves = False
    for axis, kin in factors:
        if not (kin.value.any() or kin.velocity.any() or kin.acceleration.any()):
            continue  # a channel at rest: R_i = I, no term (the same values to the last bit)
        moves = True
        a = rotation @ np.asarray(axis, float)
        alpha = alpha + kin.acceleration[:, None] * a + kin.velocity[:, None] * np.cross(omega, a)
        omega = omega + kin.velocity[:, None] * a
        rotation = rotation @ axis_rotation(axis, kin.value)
    return rotation, omega, alpha, moves


def body_motion(
    motions: list[ChannelMotion],
    time: np.ndarray,
    base_dir: Path | None = None,
    orientation: np.ndarray | None = None,
    allow_outside: bool = False,
) -> BodyMotion:
    """Combine a body's channel signals into its rigid motion on the uniform grid ``time``.

    ``orientation`` (3×3, columns = body axes in global coordinates at rest) defines the axes of
    the "body" frame; default: the global axes. See the module docstring for the conventions.
    """
    t = np.asarray(time, dtype=float)
    time_step_of(t)
    n = t.size
    r0 = np.eye(3) if orientation is None else _checked_orientation(orientation)
    _warn_shared_seeds(motions)

    channels: dict[tuple[str, str], Kinematics] = {}
    for motion in motions:
        key = (motion.frame, motion.channel)
        kin = kinematics(motion.signal, t, base_dir, allow_outside)
        channels[key] = channels[key] + kin if key in channels else kin
    zero = Kinematics.zeros(n)

    def get(frame: str, channel: str) -> Kinematics:
        return channels.get((frame, channel), zero)

    e = np.eye(3)
    factors = [(e[_AXES[c]], get("global", c)) for c in ("rz", "ry", "rx")]
    factors += [(r0[:, _AXES[c]], get("body", c)) for c in ROTATIONS]
    rotation, omega, alpha, rotates = compose_rotations(factors, n)

    def stack(frame: str, attr: str) -> np.ndarray:
        return np.stack([getattr(get(frame, c), attr) for c in TRANSLATIONS], axis=1)

    # global part, then the body part w = R R0 u_b along the current body axes
    axes = rotation @ r0 if rotates else np.broadcast_to(r0, (n, 3, 3))
    w = np.einsum("tij,tj->ti", axes, stack("body", "value"))
    w_rate = np.einsum("tij,tj->ti", axes, stack("body", "velocity"))  # R R0 u̇_b
    w_acc = np.einsum("tij,tj->ti", axes, stack("body", "acceleration"))  # R R0 ü_b
    translation = stack("global", "value") + w
    if not rotates:  # ω = α = 0: the cross products below vanish
        velocity = stack("global", "velocity") + w_rate
        acceleration = stack("global", "acceleration") + w_acc
        return BodyMotion(t, translation, rotation, velocity, omega, acceleration, alpha, False)
    velocity = stack("global", "velocity") + np.cross(omega, w) + w_rate
    acceleration = (
        stack("global", "acceleration")
        + np.cross(alpha, w)
        + np.cross(omega, np.cross(omega, w))
        + 2 * np.cross(omega, w_rate)
        + w_acc
    )
    return BodyMotion(t, translation, rotation, velocity, omega, acceleration, alpha, rotates)


def _checked_orientation(orientation: np.ndarray) -> np.ndarray:
    r0 = np.asarray(orientation, dtype=float)
    if r0.shape != (3, 3) or not np.allclose(r0.T @ r0, np.eye(3), atol=1e-9):
        raise SignalError(
            f"orientation: must be a 3x3 rotation matrix (orthonormal columns), got {r0.tolist()}"
        )
    if np.linalg.det(r0) < 0:
        raise SignalError("orientation: has determinant -1 (a reflection); allowed: a rotation")
    return r0


def _warn_shared_seeds(motions: list[ChannelMotion]) -> None:
    seen: dict[int, str] = {}
    for m in motions:
        if isinstance(m.signal, PsdSignal):
            label = f"{m.channel} ({m.frame})"
            if m.signal.seed in seen:
                warnings.warn(
                    f"channels {seen[m.signal.seed]} and {label} use the same PSD seed "
                    f"{m.signal.seed}: their random signals are fully correlated; give each "
                    "channel its own seed for independent excitations",
                    SignalWarning,
                    stacklevel=3,
                )
            seen.setdefault(m.signal.seed, label)
