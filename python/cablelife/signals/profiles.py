"""Named standard random-vibration profiles (acceleration PSD breakpoint tables).

Each profile names its standard and edition, because test numbering changes between editions
(ISO 16750-3 renumbered its tests in 2023). Breakpoints are (Hz, (m/s²)²/Hz) with log-log
interpolation; ``rms`` is the published RMS, which the table integrates to (checked by a test).
Where the standard combines a random test with a sinusoidal one, only the random part is here:
add the sine as a separate channel.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from cablelife.signals.psd import PowerLawPsd

_ISO16750_3_2007 = (
    "ISO 16750-3:2007, Road vehicles - Environmental conditions and testing for electrical and "
    "electronic equipment - Part 3: Mechanical loads; random vibration (breakpoints as commonly "
    "quoted)"
)


@dataclass(frozen=True)
class Profile:
    """A published acceleration PSD profile."""

    name: str
    title: str
    source: str
    edition: str
    breakpoints: tuple[tuple[float, float], ...]  # (Hz, (m/s²)²/Hz)
    rms: float  # published RMS acceleration, m/s²
    quantity: str = "acceleration"
    unit: str = "(m/s^2)^2/Hz"

    def psd(self) -> PowerLawPsd:
        """The profile as a PSD in SI units."""
        f, g = np.array(self.breakpoints, dtype=float).T
        return PowerLawPsd.from_breakpoints(f, g, self.quantity)


def _iso(code: str, title: str, breakpoints, rms: float) -> Profile:
    return Profile(
        name=f"iso16750-3:2007/{code}",
        title=f"ISO 16750-3:2007 Test {code.split('-')[0]}: {title}",
        source=_ISO16750_3_2007,
        edition="2007",
        breakpoints=tuple(breakpoints),
        rms=rms,
    )


PROFILES: dict[str, Profile] = {
    p.name: p
    for p in [
        _iso(
            "I-engine",
            "passenger car, engine",
            [(10, 10), (100, 10), (300, 0.51), (500, 20), (2000, 20)],
            181.0,
        ),
        _iso(
            "II-gearbox",
            "passenger car, gearbox",
            [(10, 10), (100, 10), (300, 0.51), (500, 5), (2000, 5)],
            96.6,
        ),
        _iso(
            "IV-sprung-mass",
            "passenger car, sprung masses (vehicle body)",
            [(10, 20), (55, 6.5), (180, 0.25), (300, 0.25), (360, 0.14), (1000, 0.14)],
            27.8,
        ),
        _iso(
            "V-unsprung-mass",
            "passenger car, unsprung masses (wheel, suspension)",
            [(20, 200), (40, 200), (300, 0.5), (800, 0.5), (1000, 3), (2000, 3)],
            107.3,
        ),
        _iso(
            "VII-cv-sprung-mass",
            "commercial vehicle, sprung masses",
            [(10, 18), (20, 36), (30, 36), (180, 1), (2000, 1)],
            57.9,
        ),
    ]
}


def get_profile(name: str) -> Profile:
    """The profile called ``name`` (case-insensitive); a clear error listing the known names."""
    for key, profile in PROFILES.items():
        if key.lower() == name.strip().lower():
            return profile
    raise ValueError(f"profile {name!r} is not known; allowed: {', '.join(PROFILES)}")
