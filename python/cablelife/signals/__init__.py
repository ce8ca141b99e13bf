"""Signal generator: excitation signals for the rigid bodies that carry the cable clips.

Signal types (``spec``): sine, sweep, PSD (breakpoints or a named standard profile), measured
files (CSV, ASAM MDF4, TDMS) and inline tables. ``generate``/``kinematics`` evaluate one channel
on a uniform time grid; ``body_motion`` combines a body's channels into its rigid motion.
See docs/signals.md.
"""

from cablelife.signals.errors import SignalError, SignalWarning
from cablelife.signals.generate import generate, kinematics
from cablelife.signals.kinematics import Kinematics, time_grid
from cablelife.signals.motion import BodyMotion, body_motion
from cablelife.signals.profiles import PROFILES, Profile, get_profile
from cablelife.signals.psd import PowerLawPsd
from cablelife.signals.spec import (
    ChannelMotion,
    MeasuredSignal,
    PsdSignal,
    Signal,
    SignalFile,
    SineSignal,
    SweepSignal,
    TableSignal,
)

__all__ = [
    "PROFILES",
    "BodyMotion",
    "ChannelMotion",
    "Kinematics",
    "MeasuredSignal",
    "PowerLawPsd",
    "Profile",
    "PsdSignal",
    "Signal",
    "SignalError",
    "SignalFile",
    "SignalWarning",
    "SineSignal",
    "SweepSignal",
    "TableSignal",
    "body_motion",
    "generate",
    "get_profile",
    "kinematics",
    "time_grid",
]
