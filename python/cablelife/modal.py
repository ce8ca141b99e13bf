"""Modal analysis of the mounted cable: natural frequencies and mode shapes, linearised about
the static equilibrium at the clip poses of t = 0 (the tangent stiffness of the solver with
the geometric stiffness of the current loads, and the lumped masses).

The eigenproblem K φ = ω² M φ is solved in Rust on the block-tridiagonal structure
(``rod::modal``: shift-invert subspace iteration with a block LDLᵀ and its Sturm count, O(N)
memory); massless unknowns (swivel twists) need no condensation. ``cable_modes_dense`` is the
former dense LAPACK solver, kept for comparison (tests, benchmarks).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from cablelife.scene import Cable, Scene, SceneError
from cablelife.simulate import build_cable, clip_poses

#: The modal energy shares, in the order of ``Modes.shares``.
SHARE_NAMES = ("bending d1", "bending d2", "torsion", "axial")


@dataclass
class Modes:
    """Natural frequencies and mode shapes of one cable."""

    cable: str
    omega: np.ndarray  # (k,) rad/s
    shapes: np.ndarray  # (k, N+1, 3) node displacements, mass-normalised, global frame
    arc_length: np.ndarray  # (N+1,)
    equilibrium: np.ndarray  # (N+1, 3) node positions of the static equilibrium
    rotations: np.ndarray | None = None  # (k, N, 3) edge rotations, global frame
    #: (k, 4) shares of the modal energy: bending d1, bending d2, torsion, axial
    shares: np.ndarray | None = None
    kind: list[str] = field(default_factory=list)  # dominant share of each mode
    #: (k,) modal damping ratios of the Kelvin–Voigt section law (``cable_modes(damping=True)``)
    damping_ratio: np.ndarray | None = None

    @property
    def frequencies(self) -> np.ndarray:
        """Natural frequencies in Hz."""
        return self.omega / (2 * np.pi)


def _equilibrium(scene: Scene, cable: Cable):
    """The solver object at the static equilibrium with the clip poses of t = 0, with the
    contact term when ``[contact]`` is enabled (the run's own start: a cable resting on a
    surface is resting there for its modes and its damping calibration too)."""
    from cablelife.contact_settings import set_contact

    core = build_cable(scene, cable)
    pos, quat = clip_poses(scene, cable, np.array([0.0]), with_motion=True)
    try:
        set_contact(core, scene, cable, np.array([0.0]))
        out = core.run_sequence(pos, quat)
    except ValueError as err:
        raise SceneError(f"cable '{cable.name}': {err}") from None
    if out["error"]:
        raise SceneError(f"cable '{cable.name}': no static equilibrium: {out['error']}")
    return core, out


def cable_modes(scene: Scene, cable: Cable, count: int = 6, damping: bool = False) -> Modes:
    """The ``count`` lowest modes of ``cable`` at its static equilibrium with the clip poses
    of t = 0 (the banded Rust solver). With ``damping``, also each mode's damping ratio of the
    cable's Kelvin–Voigt damping (``retardation_times``): the Rayleigh quotient
    φᵀCφ / (2ω φᵀMφ) with the section law's damping matrix C (``rod::modal::damping_ratio``).
    A cable of a harness gets the harness's modes (``harness_modes``)."""
    if count < 1:
        raise SceneError(f"count = {count}: ask for at least 1 mode")
    if scene.junctions:
        return harness_modes(scene, count, damping)[cable.name]
    taus = {}
    if damping:
        shear, bend, _ = retardation_times(scene, cable)
        taus = {"shear_tau": list(shear), "bend_tau": list(bend)}
    core, out = _equilibrium(scene, cable)
    try:
        found = core.modes(count, **taus)
    except ValueError as err:
        raise SceneError(f"cable '{cable.name}': {err}") from None
    return Modes(
        cable=cable.name,
        omega=found["omega"],
        shapes=found["displacements"],
        arc_length=core.arc_length,
        equilibrium=out["positions"][0],
        rotations=found["rotations"],
        shares=found["shares"],
        kind=list(found["kind"]),
        damping_ratio=found.get("damping_ratio"),
    )


def harness_modes(scene: Scene, count: int = 6, damping: bool = False) -> dict[str, Modes]:
    """The ``count`` lowest modes of a harness (a scene with ``[[junctions]]``) about its
    static equilibrium with the clip poses of t = 0: modes of the whole tree (``rod::
    harness_modal``), so every cable's ``Modes`` has the same frequencies and its part of each
    mode shape (mass-normalised over the harness; ``shares`` and ``kind`` of the whole). With
    ``damping``, also each mode's damping ratio with every cable's Kelvin–Voigt damping
    (``retardation_times``): the Rayleigh quotient over the whole harness
    (``rod::harness_modal::harness_damping_ratio``)."""
    from cablelife.harness import harness_equilibrium

    if count < 1:
        raise SceneError(f"count = {count}: ask for at least 1 mode")
    core, cables, cores, out = harness_equilibrium(scene)
    try:
        taus = {}
        if damping:
            mode1 = None
            if any(map(uses_mode1, cables)):
                mode1 = mode1_bending_damping(core, len(cables))
            times = [retardation_times(scene, c, mode1) for c in cables]
            taus = {
                "shear_tau": [list(t[0]) for t in times],
                "bend_tau": [list(t[1]) for t in times],
            }
        found = core.modes(count, **taus)
    except ValueError as err:
        raise SceneError(f"harness: {err}") from None
    return {
        c.name: Modes(
            cable=c.name,
            omega=found["omega"],
            shapes=fc["displacements"],
            arc_length=co.arc_length,
            equilibrium=o["positions"][0],
            rotations=fc["rotations"],
            shares=found["shares"],
            kind=list(found["kind"]),
            damping_ratio=found.get("damping_ratio"),
        )
        for c, co, o, fc in zip(cables, cores, out["cables"], found["cables"], strict=True)
    }


def cable_modes_dense(scene: Scene, cable: Cable, count: int = 6) -> Modes:
    """The former dense solver (LAPACK on the (6N)² matrices, static condensation of the
    massless unknowns): O(N²) memory, O(N³) time. For comparison only."""
    import scipy.linalg

    if count < 1:
        raise SceneError(f"count = {count}: ask for at least 1 mode")
    if scene.junctions:
        raise SceneError("cable_modes_dense: harnesses (scenes with [[junctions]]) not supported")
    core, out = _equilibrium(scene, cable)
    lin = core.linearize()
    k = lin["stiffness"]
    k = 0.5 * (k + k.T)  # symmetric at equilibrium up to round-off (and dead moments)
    m = lin["mass"]
    massive = m > 0
    k_mm = k[np.ix_(massive, massive)]
    if not massive.all():
        # Static condensation of the massless unknowns: K* = K_mm − K_m0 K_00⁻¹ K_0m.
        k_m0 = k[np.ix_(massive, ~massive)]
        k_00 = k[np.ix_(~massive, ~massive)]
        k_mm = k_mm - k_m0 @ np.linalg.solve(k_00, k_m0.T)
        k_mm = 0.5 * (k_mm + k_mm.T)
    n = k_mm.shape[0]
    count = min(count, n)
    w2, vec = scipy.linalg.eigh(k_mm, np.diag(m[massive]), subset_by_index=[0, count - 1])
    if w2[0] < -1e-8 * abs(w2[-1]):
        raise SceneError(
            f"cable '{cable.name}': the equilibrium is unstable (negative stiffness "
            f"eigenvalue {w2[0]:.3g}); its modes are not defined"
        )
    omega = np.sqrt(np.clip(w2, 0.0, None))
    blocks, slots = lin["block"][massive], lin["slot"][massive]
    n_nodes = core.arc_length.size
    shapes = np.zeros((count, n_nodes, 3))
    disp = slots < 3
    for i in range(count):
        shapes[i, blocks[disp], slots[disp]] = vec[disp, i]
    return Modes(
        cable=cable.name,
        omega=omega,
        shapes=shapes,
        arc_length=core.arc_length,
        equilibrium=out["positions"][0],
    )


def modes(scene: Scene, count: int = 6) -> dict[str, Modes]:
    """Modes of every cable of the scene (of the whole harness if it has junctions)."""
    if scene.junctions:
        return harness_modes(scene, count)
    return {c.name: cable_modes(scene, c, count) for c in scene.cables}


#: The least share of bending in the first mode's stiffness for which the default damping
#: gives that mode its damping ratio ζ (``retardation_times``); below, the bending retardation
#: time is held at 2ζ/(ω₁ · this) and the mode gets ζ · share / this.
MIN_BENDING_SHARE = 0.9

#: Loss factor η = ωτ of the default damping of extension, torsion and shear on their lowest
#: mode (ζ = η/2 = 0.05): a typical polymer's (cable insulation, hose rubber: 0.05 … 0.3).
DEFAULT_LOSS_FACTOR = 0.1


def longest_span(cable: Cable) -> float:
    """The effective length of the longest free span: between two consecutive clips, or twice
    a span from a clip to a free end (a cantilever's lowest axial and torsion mode is a
    quarter wave)."""
    s = sorted(c.s for c in cable.clips)
    spans = [b - a for a, b in zip(s, s[1:], strict=False)]
    ends = [s[0], cable.length - s[-1]] if s else [cable.length]
    return max(spans + [2 * e for e in ends] + [0.0]) or cable.length


def lowest_frequencies(cable: Cable) -> dict[str, float]:
    """Estimates (rad/s) of the lowest extension, torsion and shear modes of the mounted cable,
    from the continuous rod on its longest free span ``L``: ω = π/L √(EA/ρA) and
    π/L √(GJ/ρI₃) (waves along the span); the shear branch starts at its cut-off frequency
    √(GA/ρI) (Timoshenko's second spectrum)."""
    p = cable.properties()
    span = longest_span(cable)
    ga, ea = p.shear_stiffness[0], p.shear_stiffness[2]
    gj = p.bend_stiffness[2]
    rho_i, rho_i3 = p.rotary_inertia[0], p.rotary_inertia[2]
    inf = float("inf")
    return {
        "extension": math.pi / span * math.sqrt(ea / p.mass_per_length),
        "torsion": math.pi / span * math.sqrt(gj / rho_i3) if rho_i3 > 0 else inf,
        "shear": math.sqrt(ga / rho_i) if rho_i > 0 else inf,
    }


def uses_mode1(cable: Cable) -> bool:
    """Whether the cable's default bending damping needs the first mode (a damping ratio, no
    retardation time given for bending)."""
    return cable.damping.retardation_time is None and cable.damping.bending is None


#: The modal solver's stopping tolerance for the damping's calibration on mode 1: ω₁ and ζ₁
#: to about 1e-8 instead of the modal analysis's 1e-11 (fewer refined iterations and a smaller
#: subspace: the harness benchmark's calibration 3.4 → 1.3 ms; τ changes by ~1e-8 of itself).
CALIBRATION_TOLERANCE = 1e-9


def mode1_bending_damping(core, cables: int | None = None) -> tuple[float, float]:
    """ω₁ of the solver object ``core`` at its last static equilibrium (a ``Cable``, or a
    ``Harness`` of ``cables`` cables) and mode 1's Rayleigh damping ratio per second of bending
    retardation time: ζ₁ for τ = 1 s on EI₁ and EI₂ of every cable (torsion, extension, shear
    undamped). ζ₁ is linear in τ, so τ = ζ / (this value) damps mode 1 at ζ. A ValueError of
    the modal solver passes through."""
    shear, bend = [0.0, 0.0, 0.0], [1.0, 1.0, 0.0]
    if cables is not None:
        shear, bend = [shear] * cables, [bend] * cables
    found = core.modes(1, shear_tau=shear, bend_tau=bend, tolerance=CALIBRATION_TOLERANCE)
    return float(found["omega"][0]), float(found["damping_ratio"][0])


def bending_damping_of_mode1(scene: Scene, cable: Cable) -> tuple[float, float]:
    """``mode1_bending_damping`` of the mounted cable at t = 0."""
    core, _ = _equilibrium(scene, cable)
    try:
        return mode1_bending_damping(core)
    except ValueError as err:
        raise SceneError(f"cable '{cable.name}': {err}") from None


def retardation_times(
    scene: Scene, cable: Cable, mode1: tuple[float, float] | None = None
) -> tuple[list[float], list[float], dict]:
    """Kelvin–Voigt retardation times (GA₁, GA₂, EA) and (EI₁, EI₂, GJ) of a cable, with how
    they were set.

    Default (``ratio`` ζ, 1 unless given): bending gets the τ that gives the first natural
    mode of the mounted cable the damping ratio ζ (ζ = 1: critical), τ = ζ / ζ₁(τ = 1 s) with
    ζ₁ the mode's Rayleigh damping ratio φᵀC_bφ / (2ω φᵀMφ) (``mode1_bending_damping``).
    The beam rule 2ζ/ω₁ is right only where the mode's bending stiffness is its whole
    stiffness: where the loads' geometric stiffness lowers ω₁ (a curved or compressed span)
    it would give several times ζ. Where gravity or extension stiffen mode 1 (a slack span's
    swing: ``info["bending_share"]`` below ``MIN_BENDING_SHARE``) no bending damping can give
    it ζ without over-damping the bending modes above it: τ is held at 2ζ/(ω₁ ·
    MIN_BENDING_SHARE) and the mode gets ζ · share / MIN_BENDING_SHARE. A harness's cables
    are calibrated on the whole tree's mode 1 (``mode1`` of the harness): with one ζ on every
    cable that mode gets ζ exactly. Extension, torsion and shear get a material-like damping:
    the loss factor η = ``DEFAULT_LOSS_FACTOR`` on their own lowest mode, τ_i = min(τ, η/ω_i)
    (``lowest_frequencies``). One τ on all modes would damp extension, torsion and shear
    hundreds of times over-critically and let the viscous forces dominate the section loads
    (docs/dynamics.md). A given ``retardation_time`` applies to all modes. Per-mode values
    override either. ``mode1``: (ω₁, ζ₁ per second of bending τ) when known (a harness: the
    whole tree's), else computed for the cable alone."""
    from cablelife.scene import DEFAULT_DAMPING_RATIO

    d = cable.damping
    info: dict = {}
    if d.retardation_time is not None:
        tau = d.retardation_time
        info["source"] = "retardation_time"
        own = {"extension": tau, "torsion": tau, "shear": tau}
    else:
        zeta = d.ratio if d.ratio is not None else DEFAULT_DAMPING_RATIO
        omega1, per_tau = mode1 if mode1 is not None else bending_damping_of_mode1(scene, cable)
        beam = 2 * zeta / omega1 if omega1 > 0 else 0.0  # a pure bending mode at ω₁ gets ζ
        # Mode 1's Rayleigh damping ratio from bending is ζ exactly — while at least
        # MIN_BENDING_SHARE of its stiffness is bending. A mode stiffened by gravity (a slack
        # span's swing) or by extension is only partly bending, and the τ that would damp it at
        # ζ over-damps every bending mode above it (bench_contact's draped hose, 45 % bending:
        # τ = 0.15 s, ζ ≈ 46 at 100 Hz, and Newton failed at 0.53 s); it then gets
        # ζ · share / MIN_BENDING_SHARE (a run hint says so).
        cap = beam / MIN_BENDING_SHARE
        tau = min(zeta / per_tau, cap) if per_tau > 0 else beam
        share = 2 * per_tau / omega1 if omega1 > 0 else float("nan")
        info.update(source="ratio", ratio=zeta, omega1=omega1, bending_share=share)
        own = {k: min(tau, DEFAULT_LOSS_FACTOR / w) for k, w in lowest_frequencies(cable).items()}
    info["tau"] = tau
    pick = lambda v, default: default if v is None else v  # noqa: E731
    t_ext = pick(d.extension, own["extension"])
    t_shear = pick(d.shear, own["shear"])
    t_bend = pick(d.bending, tau)
    t_tors = pick(d.torsion, own["torsion"])
    return [t_shear, t_shear, t_ext], [t_bend, t_bend, t_tors], info
