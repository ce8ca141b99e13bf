"""Build a body's motion from channel signals and move a clip point with it.

Run: python examples/signals/body_motion.py
"""

import numpy as np
from cablelife.signals import ChannelMotion, body_motion, time_grid

motions = [
    ChannelMotion.model_validate(
        {
            "channel": "z",
            "frame": "global",
            "signal": {"type": "psd", "profile": "iso16750-3:2007/IV-sprung-mass", "seed": 1},
        }
    ),
    ChannelMotion.model_validate(
        {
            "channel": "ry",
            "frame": "body",
            "signal": {"type": "sine", "amplitude": 0.5, "unit": "deg", "frequency": 2.0},
        }
    ),
]

time = time_grid(duration=10.0, time_step=0.0005)  # 1000 Hz profile needs a step <= 0.5 ms
motion = body_motion(motions, time)

origin = np.array([1.2, 0.0, 0.4])  # body reference point, m
clip = np.array([[1.5, 0.1, 0.4]])  # a clip on the body, rest position, m
path = motion.positions(clip, origin)[:, 0, :]
print(f"origin z RMS: {1e3 * motion.translation[:, 2].std():.3f} mm")
print(f"clip   z RMS: {1e3 * (path[:, 2] - clip[0, 2]).std():.3f} mm")
print(f"max angular velocity: {np.abs(motion.angular_velocity).max():.4f} rad/s")
