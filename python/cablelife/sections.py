"""Effective section properties of a cable from geometry and material, or from measured values.

Conventions: d3 is the cable axis, d1 and d2 the principal axes of the section.
C^Γ = diag(GA₁, GA₂, EA) includes the shear coefficient; C^K = diag(EI₁, EI₂, GJ).
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass


@dataclass(frozen=True)
class SectionProperties:
    """Stiffnesses and inertia per unit length of a cable section (SI units)."""

    EA: float  # N
    GA1: float  # N, shear stiffness incl. shear coefficient
    GA2: float
    EI1: float  # N m²
    EI2: float
    GJ: float  # N m²
    mass_per_length: float  # kg/m
    rotary_inertia: tuple[float, float, float]  # ρ(I₁, I₂, I₁+I₂), kg m
    shape: str  # "circle" | "tube"
    outer_radius: float  # m
    inner_radius: float  # m
    poisson_ratio: float
    from_measured: bool

    @property
    def shear_stiffness(self) -> list[float]:
        return [self.GA1, self.GA2, self.EA]

    @property
    def bend_stiffness(self) -> list[float]:
        return [self.EI1, self.EI2, self.GJ]

    def as_attrs(self) -> dict:
        """Flat attributes for the result file."""
        d = asdict(self)
        d["rotary_inertia"] = list(self.rotary_inertia)
        return d


def shear_coefficient(poisson_ratio: float, beta: float = 0.0) -> float:
    """Timoshenko shear coefficient of a solid circle (β = 0) or a tube (β = inner/outer radius),
    Cowper (1966): κ = 6(1+ν)(1+β²)² / ((7+6ν)(1+β²)² + (20+12ν)β²)."""
    nu = poisson_ratio
    b2 = beta * beta
    return 6 * (1 + nu) * (1 + b2) ** 2 / ((7 + 6 * nu) * (1 + b2) ** 2 + (20 + 12 * nu) * b2)


def from_material(
    shape: str,
    outer_radius: float,
    inner_radius: float,
    youngs_modulus: float,
    poisson_ratio: float,
    density: float,
) -> SectionProperties:
    """Homogeneous circle or tube of an isotropic material."""
    a, b = outer_radius, inner_radius
    area = math.pi * (a * a - b * b)
    inertia = math.pi * (a**4 - b**4) / 4
    g = youngs_modulus / (2 * (1 + poisson_ratio))
    kappa = shear_coefficient(poisson_ratio, b / a)
    return SectionProperties(
        EA=youngs_modulus * area,
        GA1=kappa * g * area,
        GA2=kappa * g * area,
        EI1=youngs_modulus * inertia,
        EI2=youngs_modulus * inertia,
        GJ=g * 2 * inertia,
        mass_per_length=density * area,
        rotary_inertia=(density * inertia, density * inertia, density * 2 * inertia),
        shape=shape,
        outer_radius=a,
        inner_radius=b,
        poisson_ratio=poisson_ratio,
        from_measured=False,
    )


def from_measured(
    EA: float,
    GA: float | None,
    EI1: float,
    EI2: float,
    GJ: float,
    mass_per_length: float,
    radius: float,
    rotary_inertia: float | None = None,
    polar_rotary_inertia: float | None = None,
) -> SectionProperties:
    """Effective measured stiffnesses (as cable suppliers give them) on a round section of
    ``radius`` (used for stresses and pictures: the equivalent homogeneous circle).

    Without GA, GA is that of the equivalent homogeneous circle: G = GJ/J and the shear
    coefficient at the equivalent Poisson ratio ν = EA/(2·G·A) − 1 (clipped to [0, 0.5]).
    Without ``rotary_inertia`` (ρI per length, kg m) it is that of a homogeneous circle, m r²/4;
    without ``polar_rotary_inertia`` (ρI₃ about the axis) it is twice ``rotary_inertia`` (a
    round section: I₃ = I₁ + I₂).
    """
    area = math.pi * radius * radius
    polar = math.pi * radius**4 / 2
    e_eq = EA / area
    g_eq = GJ / polar
    nu = min(max(e_eq / (2 * g_eq) - 1, 0.0), 0.5)
    if GA is None:
        GA = shear_coefficient(nu) * g_eq * area
    rho_i = rotary_inertia if rotary_inertia is not None else mass_per_length * radius**2 / 4
    rho_i3 = polar_rotary_inertia if polar_rotary_inertia is not None else 2 * rho_i
    return SectionProperties(
        EA=EA,
        GA1=GA,
        GA2=GA,
        EI1=EI1,
        EI2=EI2,
        GJ=GJ,
        mass_per_length=mass_per_length,
        rotary_inertia=(rho_i, rho_i, rho_i3),
        shape="circle",
        outer_radius=radius,
        inner_radius=0.0,
        poisson_ratio=nu,
        from_measured=True,
    )
