"""Units of signal amplitudes and PSD values, and their factors to SI (m, rad, s).

An amplitude unit has a quantity (displacement, velocity, acceleration), a dimension (``length``
for translations x, y, z; ``angle`` for rotations rx, ry, rz) and a factor to SI. A PSD unit is
the square of an amplitude unit per Hz, e.g. ``(m/s^2)^2/Hz`` or ``g^2/Hz``.
Spellings are compared case-insensitively, without spaces; ``²`` and ``**2`` mean ``^2``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

Quantity = Literal["displacement", "velocity", "acceleration"]
Dimension = Literal["length", "angle"]

STANDARD_GRAVITY = 9.80665  # m/s², ISO 80000-3
QUANTITIES: tuple[Quantity, ...] = ("displacement", "velocity", "acceleration")
#: Order of the time derivative of displacement for each quantity.
DERIVATIVE_ORDER: dict[str, int] = {"displacement": 0, "velocity": 1, "acceleration": 2}


@dataclass(frozen=True)
class Unit:
    """One amplitude unit (or the PSD unit built from it)."""

    name: str
    quantity: Quantity
    dimension: Dimension
    factor: float  # multiply a value in this unit by factor to get SI (m, rad based)


_DEG = math.pi / 180.0
AMPLITUDE_UNITS: dict[str, Unit] = {
    u.name: u
    for u in [
        Unit("m", "displacement", "length", 1.0),
        Unit("mm", "displacement", "length", 1e-3),
        Unit("rad", "displacement", "angle", 1.0),
        Unit("deg", "displacement", "angle", _DEG),
        Unit("m/s", "velocity", "length", 1.0),
        Unit("mm/s", "velocity", "length", 1e-3),
        Unit("rad/s", "velocity", "angle", 1.0),
        Unit("deg/s", "velocity", "angle", _DEG),
        Unit("m/s^2", "acceleration", "length", 1.0),
        Unit("mm/s^2", "acceleration", "length", 1e-3),
        Unit("g", "acceleration", "length", STANDARD_GRAVITY),
        Unit("rad/s^2", "acceleration", "angle", 1.0),
        Unit("deg/s^2", "acceleration", "angle", _DEG),
    ]
}


def _psd_spellings(u: Unit) -> list[str]:
    """Accepted spellings of the PSD unit built from amplitude unit ``u``."""
    if "/" not in u.name:
        return [f"{u.name}^2/Hz"]
    num, den = u.name.split("/")
    den_sq = "s^4" if den == "s^2" else "s^2"
    return [f"({u.name})^2/Hz", f"{num}^2/{den_sq}/Hz"]


PSD_UNITS: dict[str, Unit] = {
    spelling: Unit(_psd_spellings(u)[0], u.quantity, u.dimension, u.factor**2)
    for u in AMPLITUDE_UNITS.values()
    for spelling in _psd_spellings(u)
}


def _normalise(text: str) -> str:
    return text.replace(" ", "").replace("²", "^2").replace("⁴", "^4").replace("**", "^").lower()


def _lookup(text: str, table: dict[str, Unit], kind: str) -> Unit:
    key = _normalise(text)
    for name, unit in table.items():
        if _normalise(name) == key:
            return unit
    allowed = ", ".join(sorted({u.name for u in table.values()}))
    raise ValueError(f"{kind} unit {text!r} is not known; allowed: {allowed}")


def amplitude_unit(text: str) -> Unit:
    """The amplitude unit spelled ``text`` (e.g. ``"mm"``, ``"g"``, ``"deg/s"``)."""
    return _lookup(text, AMPLITUDE_UNITS, "amplitude")


def psd_unit(text: str) -> Unit:
    """The PSD unit spelled ``text`` (e.g. ``"g^2/Hz"``, ``"(m/s^2)^2/Hz"``)."""
    return _lookup(text, PSD_UNITS, "PSD")


def si_amplitude_name(quantity: str, dimension: str) -> str:
    """SI unit name of a quantity for a translation (``length``) or rotation (``angle``)."""
    base = "m" if dimension == "length" else "rad"
    return {"displacement": base, "velocity": f"{base}/s", "acceleration": f"{base}/s^2"}[quantity]


def si_psd_name(quantity: str, dimension: str) -> str:
    """SI PSD unit name of a quantity, e.g. ``(m/s^2)^2/Hz``."""
    return _psd_spellings(AMPLITUDE_UNITS[si_amplitude_name(quantity, dimension)])[0]
