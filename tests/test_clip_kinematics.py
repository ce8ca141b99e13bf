"""Clip kinematics from body motions (``simulate.clip_kinematics``): a body that only
translates takes the short path, with the same values as the general rigid-motion formulas."""

import dataclasses

import numpy as np
from cablelife.scene import scene_from_dict
from cablelife.simulate import body_motions, clip_kinematics, output_times


def test_a_translating_body_gives_the_general_formulas_values(scene_dict):
    psd = {"type": "psd", "profile": "iso16750-3:2007/I-engine", "f_high": 100.0, "seed": 3}
    scene_dict["simulation"] = {"mode": "dynamic", "time_step": 1e-3, "duration": 0.2}
    scene_dict["bodies"] = [
        {
            "name": "engine",
            "origin": [1.0, 0.2, -0.1],
            "orientation": [0.1, -0.2, 0.3],
            "motion": [
                {"channel": "z", "signal": psd},
                {"channel": "x", "frame": "body", "signal": {**psd, "seed": 4}},
            ],
        }
    ]
    clips = scene_dict["cables"][0]["clips"]
    clips[1]["body"] = "engine"  # global frame
    clips.insert(1, {**clips[0], "name": "m", "s": 0.5, "body": "engine", "frame": "body"})
    sc = scene_from_dict(scene_dict)
    times = output_times(sc, "dynamic")
    motions = body_motions(sc, times)
    body, r0, motion = motions["engine"]
    assert not motion.rotates and motion.velocity.any()
    fast = clip_kinematics(sc, sc.cables[0], times, motions=motions)
    general = {"engine": (body, r0, dataclasses.replace(motion, rotates=True))}
    slow = clip_kinematics(sc, sc.cables[0], times, motions=general)
    assert fast.keys() == slow.keys()
    for key in fast:
        assert np.array_equal(fast[key], slow[key]), key
    assert fast["positions"][:, 1:].std(axis=0).min() > 1e-5  # both clips move with the body


def test_few_frames_convert_as_the_array_code_bit_for_bit():
    """Up to ``SMALL`` matrices are converted one by one in Python floats: the same
    quaternions to the last bit as the array code, on every branch of Shepperd's method
    (random rotations, ones near the degenerate branches, exact ties)."""
    from cablelife import rotations

    rng = np.random.default_rng(1)
    for trial in range(2000):
        q = rng.normal(size=(int(rng.integers(1, rotations.SMALL + 1)), 4))
        if trial % 7 == 0:
            q[:, trial % 4] *= 1e-9
        q /= np.linalg.norm(q, axis=1, keepdims=True)
        w, x, y, z = q.T
        m = np.stack(
            [
                np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], -1),
                np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], -1),
                np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], -1),
            ],
            -2,
        )
        small = rotations.matrix_quaternions(m)
        assert small.tobytes() == rotations._matrix_quaternions_arrays(m).tobytes(), trial
        np.testing.assert_allclose(np.abs(np.sum(small * q, axis=1)), 1.0, atol=1e-12)
    # 170° about (1, 1, 0.1): the equal first two diagonal entries are the largest (a tie:
    # the first is taken, as numpy's argmax takes it)
    n = np.array([1.0, 1.0, 0.1]) / np.linalg.norm([1.0, 1.0, 0.1])
    c, s = np.cos(np.radians(170.0)), np.sin(np.radians(170.0))
    k = np.array([[0.0, -n[2], n[1]], [n[2], 0.0, -n[0]], [-n[1], n[0], 0.0]])
    tie = c * np.eye(3) + s * k + (1 - c) * np.outer(n, n)
    assert tie[0, 0] == tie[1, 1] == max(np.diag(tie).max(), np.trace(tie))
    for m in (np.eye(3), np.diag([1.0, -1, -1]), np.diag([-1.0, -1, 1]), tie):
        want = rotations._matrix_quaternions_arrays(m[None])
        assert rotations.matrix_quaternions(m).tobytes() == want.tobytes()
