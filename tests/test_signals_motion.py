"""Rigid body motion from channels: rotation conventions, frames, exact derivatives."""

import numpy as np
import pytest
from cablelife.signals import (
    ChannelMotion,
    SignalError,
    SignalWarning,
    body_motion,
    time_grid,
)

ORIGIN = np.array([1.0, 2.0, 0.5])


def channel(name, value=None, frame="global", signal=None):
    """A channel holding a constant (table) value, or the given signal."""
    signal = signal or {"type": "table", "t": [0.0, 1.0], "value": [value, value]}
    return ChannelMotion.model_validate({"channel": name, "frame": frame, "signal": signal})


def sine(amplitude, frequency, phase=0.0):
    return {"type": "sine", "amplitude": amplitude, "frequency": frequency, "phase": phase}


T = time_grid(1.0, 0.5)


def test_pure_rotation_about_an_axis_moves_a_point():
    m = body_motion([channel("rz", np.pi / 2)], T)
    point = ORIGIN + [0.3, 0.0, 0.2]
    moved = m.positions(point[None, :], ORIGIN)[0, 0]
    assert np.allclose(moved, ORIGIN + [0.0, 0.3, 0.2])
    assert np.allclose(m.translation, 0)


def test_global_rotations_compose_extrinsic_x_then_z():
    """R = Rz·Ry·Rx about fixed axes: e_y --Rx(90°)--> e_z --Rz(90°)--> e_z."""
    m = body_motion([channel("rx", np.pi / 2), channel("rz", np.pi / 2)], T)
    assert np.allclose(m.rotation[0] @ [0, 1, 0], [0, 0, 1])
    assert np.allclose(m.rotation[0] @ [1, 0, 0], [0, 1, 0])


def test_body_rotations_compose_intrinsic_x_then_new_z():
    """R = Rx·Ry·Rz: about body x first, then the body's new z axis."""
    m = body_motion(
        [channel("rx", np.pi / 2, frame="body"), channel("rz", np.pi / 2, frame="body")], T
    )
    # after rx = 90° the body's z axis points along global -y; rz = 90° about it turns the
    # body's x axis from e_x to +e_z and its y axis (then e_z) to -e_x
    assert np.allclose(m.rotation[0] @ [1, 0, 0], [0, 0, 1])
    assert np.allclose(m.rotation[0] @ [0, 1, 0], [-1, 0, 0])
    # the same angles about the global axes give a different rotation
    g = body_motion([channel("rx", np.pi / 2), channel("rz", np.pi / 2)], T)
    assert not np.allclose(g.rotation[0], m.rotation[0])


def test_body_frame_translation_follows_the_rotation():
    m = body_motion([channel("rz", np.pi / 2), channel("x", 0.01, frame="body")], T)
    assert np.allclose(m.translation[0], [0.0, 0.01, 0.0])
    g = body_motion([channel("rz", np.pi / 2), channel("x", 0.01)], T)
    assert np.allclose(g.translation[0], [0.01, 0.0, 0.0])


def test_body_orientation_defines_body_axes():
    """A body whose x axis points along global y: body x translation moves along global y."""
    r0 = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
    m = body_motion(
        [channel("x", 0.02, frame="body"), channel("rx", 0.3, frame="body")], T, orientation=r0
    )
    assert np.allclose(m.translation[0], [0.0, 0.02, 0.0])
    assert np.allclose(m.rotation[0] @ [0, 1, 0], [0, 1, 0])  # rotation about global y
    with pytest.raises(SignalError, match=r"orientation: must be a 3x3 rotation matrix"):
        body_motion([], T, orientation=2 * r0)


def test_signals_on_the_same_channel_add():
    m = body_motion([channel("z", 0.01), channel("z", 0.02)], T)
    assert np.allclose(m.translation[:, 2], 0.03)


def test_derivatives_match_finite_differences():
    """All six channels in both frames, a tilted body: ω, α, u̇, ü against central differences."""
    motions = [
        channel("x", signal=sine(0.01, 1.3, 0.1)),
        channel("y", signal=sine(0.02, 0.7, 0.4)),
        channel("z", frame="body", signal=sine(0.015, 1.1, 0.9)),
        channel("rx", signal=sine(0.3, 0.9, 0.2)),
        channel("ry", signal=sine(0.2, 1.7, 1.0)),
        channel("rz", signal=sine(0.4, 0.6, 2.0)),
        channel("rx", frame="body", signal=sine(0.25, 1.2, 0.5)),
        channel("ry", frame="body", signal=sine(0.35, 0.8, 0.3)),
        channel("rz", frame="body", signal=sine(0.3, 1.4, 1.5)),
        channel("x", frame="body", signal=sine(0.01, 2.1, 0.7)),
    ]
    c, s = np.cos(0.4), np.sin(0.4)
    r0 = np.array([[1, 0, 0], [0, c, -s], [0, s, c]]) @ np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])
    dt = 1e-4
    t = time_grid(2.0, dt)
    m = body_motion(motions, t, orientation=r0)
    assert np.allclose(np.einsum("tji,tjk->tik", m.rotation, m.rotation), np.eye(3), atol=1e-12)

    rdot = np.gradient(m.rotation, dt, axis=0)
    skew = np.einsum("tij,tkj->tik", rdot, m.rotation)  # Ṙ Rᵀ = [ω]×
    omega_fd = np.stack([skew[:, 2, 1], skew[:, 0, 2], skew[:, 1, 0]], axis=1)
    inner = slice(2, -2)

    def close(a, b, rel=1e-5):
        return np.max(np.abs(a[inner] - b[inner])) < rel * np.max(np.abs(b))

    assert close(omega_fd, m.angular_velocity)
    assert close(np.gradient(m.angular_velocity, dt, axis=0), m.angular_acceleration)
    assert close(np.gradient(m.translation, dt, axis=0), m.velocity)
    assert close(np.gradient(m.velocity, dt, axis=0), m.acceleration)

    points = ORIGIN + np.array([[0.2, -0.1, 0.3], [-0.4, 0.0, 0.1]])
    x = m.positions(points, ORIGIN)
    v = m.point_velocities(points, ORIGIN)
    assert close(np.gradient(x, dt, axis=0), v)
    assert close(np.gradient(v, dt, axis=0), m.point_accelerations(points, ORIGIN))


def test_shared_psd_seed_warns():
    psd = {"type": "psd", "breakpoints": [[5, 1.0], [50, 1.0]], "quantity": "acceleration"}
    with pytest.warns(SignalWarning, match=r"z \(global\) and x \(body\) use the same PSD seed 0"):
        body_motion(
            [channel("z", signal=psd), channel("x", frame="body", signal=psd)], time_grid(2.0, 1e-3)
        )


def test_translation_only_motion_skips_the_rotation_terms():
    """Without a moving rotation channel the body motion is a translation (``rotates`` False):
    R = I, ω = α = 0, global plus body-axis translations (R0 u_b), exact derivatives."""
    c, s = np.cos(0.4), np.sin(0.4)
    r0 = np.array([[1, 0, 0], [0, c, -s], [0, s, c]])
    motions = [
        channel("x", signal=sine(0.01, 1.3, 0.1)),
        channel("z", frame="body", signal=sine(0.015, 1.1, 0.9)),
        channel("ry", 0.0),  # a rotation channel at rest
    ]
    dt = 1e-4
    t = time_grid(1.0, dt)
    m = body_motion(motions, t, orientation=r0)
    assert not m.rotates
    assert np.array_equal(m.rotation, np.broadcast_to(np.eye(3), m.rotation.shape))
    assert not m.angular_velocity.any() and not m.angular_acceleration.any()
    u_g = 0.01 * np.sin(2 * np.pi * 1.3 * t + 0.1)
    u_b = 0.015 * np.sin(2 * np.pi * 1.1 * t + 0.9)
    expected = np.outer(u_g, [1.0, 0.0, 0.0]) + np.outer(u_b, r0[:, 2])
    assert np.allclose(m.translation, expected, rtol=0, atol=1e-15)
    inner = slice(2, -2)
    for x, v in ((m.translation, m.velocity), (m.velocity, m.acceleration)):
        fd = np.gradient(x, dt, axis=0)
        assert np.max(np.abs(fd[inner] - v[inner])) < 1e-5 * np.max(np.abs(v))
    assert body_motion([channel("rx", signal=sine(0.1, 1.0))], t).rotates
