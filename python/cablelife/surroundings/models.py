"""Scene models of the surroundings: the geometry parts on bodies and the clearance settings.

A part is a triangle mesh file or an analytic primitive. Coordinates are global at the
reference configuration (as CAD exports them) unless ``frame = "body"`` (then in the body
frame: origin and axes of the body at rest).
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Any, Literal

from pydantic import BaseModel, ConfigDict, Discriminator, Field, Tag, field_validator

from cablelife.scene_types import (
    Coordinate,
    Direction,
    Friction,
    Point,
    Vec3,
    bounded,
    check_nonzero,
)

Extent = bounded("extent")  # m, sizes of primitives


class _Part(BaseModel):
    model_config = ConfigDict(extra="forbid", allow_inf_nan=False)

    name: Annotated[str, Field(min_length=1)] | None = None
    friction: Friction | None = None  # Coulomb μ of contact with this part
    frame: Literal["global", "body"] = "global"


class MeshPart(_Part):
    """A triangle mesh file (STL ascii or binary, OBJ, PLY), path relative to the scene."""

    mesh: Annotated[str, Field(min_length=1)]
    scale: bounded("mesh_scale") | None = None  # file units → m (0.001 for millimetres); default 1

    @field_validator("mesh")
    @classmethod
    def _suffix(cls, v):
        if Path(v).suffix.lower() not in MESH_SUFFIXES:
            raise ValueError(
                f"mesh file {v!r} has an unknown type; allowed: {', '.join(MESH_SUFFIXES)}"
            )
        return v


MESH_SUFFIXES = (".stl", ".obj", ".ply")


class PlanePart(_Part):
    """The half-space below a plane (``normal`` points out of the solid)."""

    shape: Literal["plane"]
    point: Point
    normal: Direction

    @field_validator("normal")
    @classmethod
    def _n(cls, v):
        return check_nonzero(v, "normal")


class BoxPart(_Part):
    """A box: centre, edge lengths along its axes, orientation rx, ry, rz (rad) of its axes
    as for bodies: R = Rz Ry Rx (rotations about the global axes, x first)."""

    shape: Literal["box"]
    center: Point
    size: tuple[Extent, Extent, Extent]
    orientation: Vec3 = (0.0, 0.0, 0.0)


class CylinderPart(_Part):
    """A solid cylinder with flat ends: centre, axis direction, radius, length."""

    shape: Literal["cylinder"]
    center: Point
    axis: Direction
    radius: Extent
    length: Extent

    @field_validator("axis")
    @classmethod
    def _a(cls, v):
        return check_nonzero(v, "axis")


class SpherePart(_Part):
    shape: Literal["sphere"]
    center: Point
    radius: Extent


def _kind(v: Any) -> str | None:
    if isinstance(v, dict):
        if "mesh" in v:
            return "mesh"
        return v.get("shape")
    if isinstance(v, MeshPart):
        return "mesh"
    return getattr(v, "shape", None)


GeometryPart = Annotated[
    Annotated[MeshPart, Tag("mesh")]
    | Annotated[PlanePart, Tag("plane")]
    | Annotated[BoxPart, Tag("box")]
    | Annotated[CylinderPart, Tag("cylinder")]
    | Annotated[SpherePart, Tag("sphere")],
    Discriminator(
        _kind,
        custom_error_type="geometry_part",
        custom_error_message=(
            "a geometry part needs mesh = 'file' or shape = 'plane' | 'box' | 'cylinder' | 'sphere'"
        ),
    ),
]


class ClearanceSettings(BaseModel):
    """``[clearance]``: cable length closer than ``min_clearance`` to the surroundings is
    reported (with the length in collision, clearance < 0)."""

    model_config = ConfigDict(extra="forbid", allow_inf_nan=False)

    min_clearance: Annotated[Coordinate, Field(ge=0.0)] = 0.0  # m


def part_label(body: str, index: int, part: _Part) -> str:
    """``body/name`` or ``body/<kind>#index``."""
    kind = "mesh" if isinstance(part, MeshPart) else part.shape
    return f"{body}/{part.name or f'{kind}#{index}'}"
