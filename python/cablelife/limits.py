"""The documented limits of scene values (docs/scene.md, "Limits"): names that become HDF5
paths, ranges of physical parameters that keep the numerics meaningful, and the size of a run
checked before anything is allocated."""

from __future__ import annotations

import re

# Ranges (inclusive) of physical inputs. Outside them the double-precision solver loses its
# meaning (a radius of 1e-300 m gives a stiffness that underflows to zero; E = 1e300 Pa
# overflows the stiffness matrix), while every real cable, hose or harness lies well inside.
LIMITS: dict[str, tuple[float, float]] = {
    "length": (1e-3, 1e3),  # m, cable length
    "coordinate": (-1e4, 1e4),  # m, positions and origins
    "radius": (1e-5, 1.0),  # m, section radii (10 µm … 1 m)
    "modulus": (1e3, 1e13),  # Pa, Young's and shear modulus (soft foam … above diamond)
    "density": (1.0, 1e5),  # kg/m³
    "axial_stiffness": (1e-6, 1e15),  # N, EA and GA
    "bending_stiffness": (1e-15, 1e13),  # N m², EI and GJ
    "mass_per_length": (1e-9, 1e5),  # kg/m
    "rotary_inertia": (1e-20, 1e5),  # kg m
    "curvature": (-1e4, 1e4),  # 1/m, natural curvature (bend radius ≥ 0.1 mm)
    "acceleration": (-1e4, 1e4),  # m/s², gravity (1000 g)
    "force": (-1e9, 1e9),  # N, dead loads
    "moment": (-1e9, 1e9),  # N m, dead loads
    "direction": (-1e6, 1e6),  # 1, components of direction and normal vectors (any length)
    "damping_ratio": (0.0, 1e3),  # 1, fraction of critical damping
    "time": (0.0, 1e6),  # s, retardation times, fades (11 days)
    "friction": (0.0, 10.0),  # 1, Coulomb μ (rubber on rough surfaces ≈ 1–2)
    "extent": (1e-6, 2e4),  # m, sizes of geometry primitives (1 µm … 20 km)
    "mesh_scale": (1e-6, 1e3),  # 1, file units → m (0.001 for millimetres)
    "contact_length": (0.0, 1.0),  # m, barrier distance d̂ and stick distance (0: default)
    "contact_stiffness": (0.0, 1e15),  # N/m², barrier stiffness κ (0: automatic)
    "stick_velocity": (1e-9, 1e3),  # m/s, stick zone of dynamic friction
    "junction_mass": (0.0, 1e3),  # kg, tape or connector of a junction
    # kg m², a junction's rotary inertia: 0 (none) or within this range (a tape of 1 g at
    # 1 mm is 1e-9; below 1e-12 the inertia is rounding noise next to the branches' stiffness
    # and turned a dynamic step's matrix singular, measured)
    "junction_inertia": (1e-12, 1e2),
}

# Segments of one cable. Fewer than MIN_SEGMENTS cannot represent a cable bent between two
# clips (one segment is a straight bar; the hose of the tests is 16 % off in its bending
# moment at 4 segments, 1.5 % at 10, docs/scene.md). Beyond MAX_SEGMENTS the rod is finer
# than any cable's diameter could need, and results (13 numbers per segment and saved step)
# outgrow memory.
MIN_SEGMENTS = 4
MAX_SEGMENTS = 20_000

# Memory a run may plan for its signals and results (estimated before allocating).
MAX_RUN_BYTES = 4 * 2**30

NAME_MAX = 64
_NAME = re.compile(r"^[^\W][\w .+\-()#=,]*$")
NAME_RULE = (
    "letters, digits, space and _ - . + ( ) # = , (not starting with a space or one of the "
    f"signs), at most {NAME_MAX} characters"
)


def check_name(value: str) -> str:
    """A cable, clip or body name: it becomes an HDF5 group name (``/`` would split it, ``.``
    is the group itself) and is printed in tables, so only plain characters are allowed."""
    if len(value) > NAME_MAX or not _NAME.match(value) or value.strip() != value:
        bad = sorted({c for c in value if not re.match(r"[\w .+\-()#=,]", c)})
        why = f"contains {', '.join(map(repr, bad))}; " if bad else ""
        raise ValueError(f"name {value!r} {why}allowed: {NAME_RULE}")
    return value


def human_bytes(n: float) -> str:
    """``n`` bytes as e.g. '15.2 GiB'."""
    for unit in ("B", "KiB", "MiB", "GiB", "TiB", "PiB"):
        if n < 1024 or unit == "PiB":
            return f"{n:.3g} {unit}"
        n /= 1024
    return f"{n:.3g} PiB"  # pragma: no cover


# Bytes per time step for one clip's kinematics (positions, velocities, accelerations, angular
# velocities and accelerations: 5 × 3; frame 9; quaternion 4), one body's motion (translation,
# velocity, acceleration, angular velocity and acceleration 5 × 3, rotation 9, six channels'
# kinematics 18) and per node and saved step of the result (positions 3, quaternion 4, forces
# 3, moments 3), the result held twice (solver output and the Python copy).
_CLIP_STEP = 8 * (15 + 9 + 4)
_BODY_STEP = 8 * (15 + 9 + 18)
_NODE_STEP = 2 * 8 * 13


def run_bytes(steps: int, saved: int, cables: list[tuple[int, int]], bodies: int) -> float:
    """Estimated memory (bytes) of a run: ``steps`` time steps of the signals, ``saved`` result
    steps, ``cables`` as (segments, clips), ``bodies`` moving bodies."""
    per_step = bodies * _BODY_STEP + sum(c * _CLIP_STEP for _, c in cables)
    per_saved = sum((n + 1) * _NODE_STEP for n, _ in cables)
    return float(steps) * per_step + float(saved) * per_saved
