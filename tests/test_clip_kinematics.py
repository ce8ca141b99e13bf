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
