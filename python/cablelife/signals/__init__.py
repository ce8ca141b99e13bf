"""Signal generator: excitation signals for the rigid bodies that carry the cable clips.

Signal types (``spec``): sine, sweep, PSD (breakpoints or a named standard profile), measured
files (CSV, ASAM MDF4, TDMS) and inline tables. ``generate``/``kinematics`` evaluate one channel
on a uniform time grid; ``body_motion`` combines a body's channels into its rigid motion.
See docs/signals.md.
"""

from cablelife._lazy import lazy_package

__all__ = lazy_package(
    __name__,
    {
        "cablelife.signals.errors": ["SignalError", "SignalWarning"],
        "cablelife.signals.generate": ["generate", "kinematics"],
        "cablelife.signals.kinematics": ["Kinematics", "time_grid"],
        "cablelife.signals.motion": ["BodyMotion", "body_motion"],
        "cablelife.signals.profiles": ["PROFILES", "Profile", "get_profile"],
        "cablelife.signals.psd": ["PowerLawPsd"],
        "cablelife.signals.spec": [
            "ChannelMotion",
            "MeasuredSignal",
            "PsdSignal",
            "Signal",
            "SignalFile",
            "SineSignal",
            "SweepSignal",
            "TableSignal",
        ],
    },
)
