"""Clip kinematics from body motions (``simulate.clip_kinematics``): a body that only
translates takes the short path, with the same values as the general rigid-motion formulas."""

import dataclasses

import numpy as np
from cablelife.scene import scene_from_dict
from cablelife.simulate import body_motions, clip_kinematics, output_times


def scene():
    psd = {"type": "psd", "profile": "iso16750-3:2007/I-engine", "f_high": 100.0, "seed": 3}
    clip = {"direction": [0.0, 1.0, 0.2], "normal": [0.0, 0.0, 1.0]}
    return scene_from_dict(
        {
            "simulation": {"mode": "dynamic", "time_step": 1e-3, "duration": 0.2},
            "bodies": [
                {
                    "name": "engine",
                    "origin": [1.0, 0.2, -0.1],
                    "orientation": [0.1, -0.2, 0.3],
                    "motion": [
                        {"channel": "z", "signal": psd},
                        {"channel": "x", "frame": "body", "signal": {**psd, "seed": 4}},
                    ],
                }
            ],
            "cables": [
                {
                    "name": "c",
                    "length": 1.0,
                    "segments": 20,
                    "section": {"shape": "circle", "radius": 0.004},
                    "material": {"youngs_modulus": 5e7, "poisson_ratio": 0.4, "density": 2000},
                    "clips": [
                        {"name": "a", "s": 0.0, "position": [0.0, 0.0, 0.0], **clip},
                        {
                            "name": "b",
                            "s": 1.0,
                            "position": [0.8, 0.3, 0.1],
                            "body": "engine",
                            **clip,
                        },
                        {
                            "name": "d",
                            "s": 0.5,
                            "position": [0.1, 0.2, 0.05],
                            "body": "engine",
                            "frame": "body",
                            **clip,
                        },
                    ],
                }
            ],
        }
    )


def test_a_translating_body_gives_the_general_formulas_values():
    sc = scene()
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
    assert fast["positions"][:, 1].std(axis=0).max() > 1e-5  # the clip moves with the body
