"""Value types of the scene files (pydantic): strict numbers and flags, and numbers within the
documented limits (``cablelife.limits.LIMITS``, docs/scene.md "Limits").

Strict: a TOML number is a number (ints are fine where floats are wanted) and a flag is
``true`` or ``false``; booleans and strings are refused instead of coerced (``scale = true``
is not 1, ``enabled = "yes"`` is not true).
"""

from __future__ import annotations

import math
from typing import Annotated

from pydantic import AfterValidator, Field, Strict

from cablelife.limits import LIMITS, check_name

Real = Annotated[float, Strict()]
PositiveFloat = Annotated[float, Strict(), Field(gt=0)]
NonNegativeFloat = Annotated[float, Strict(), Field(ge=0)]
PositiveInt = Annotated[int, Strict(), Field(gt=0)]
Flag = Annotated[bool, Strict()]
Vec3 = tuple[Real, Real, Real]


def bounded(name: str):
    """A strict float within the documented range ``LIMITS[name]``."""
    lo, hi = LIMITS[name]
    return Annotated[float, Strict(), Field(ge=lo, le=hi)]


Length = bounded("length")  # m, cable length
Coordinate = bounded("coordinate")  # m
Point = tuple[Coordinate, Coordinate, Coordinate]
Radius = bounded("radius")  # m, section radii
Modulus = bounded("modulus")  # Pa, E and G
Density = bounded("density")  # kg/m³
AxialStiffness = bounded("axial_stiffness")  # N
BendingStiffness = bounded("bending_stiffness")  # N m²
Curvature = bounded("curvature")  # 1/m
Acceleration = bounded("acceleration")  # m/s²
Force = bounded("force")  # N
Moment = bounded("moment")  # N m
Component = bounded("direction")  # 1
Direction = tuple[Component, Component, Component]
Time = bounded("time")  # s


def check_nonzero(v, what: str):
    """A direction-like vector of length at least 1e-9 (its length does not matter otherwise)."""
    if v is not None and math.hypot(*v) < 1e-9:
        raise ValueError(
            f"{what} must not be the zero vector; allowed: a length of at least 1e-9 (its "
            "length does not matter otherwise)"
        )
    return v


Friction = bounded("friction")  # 1, Coulomb μ
# Cable, clip and body names: HDF5 group names and table entries (limits.check_name).
Name = Annotated[str, Strict(), Field(min_length=1), AfterValidator(check_name)]
