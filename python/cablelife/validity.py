"""Validity of a mechanical result: strains inside the model's range, pre-tensioned spans,
stability of the static states, snap-throughs (docs/solver.md, "Validity range").

The rod model is linear elastic in its section strains (C^Γ, C^K constant). Above a few
percent axial or shear strain real hoses and cables are no longer linear (rubber stiffens or
yields, braids lock, conductors yield at ~0.1–0.3 %), so the forces are not trustworthy there:
such runs warn (or fail with ``simulation.strain_limit = "error"``).
"""

from __future__ import annotations

import warnings

import numpy as np

from cablelife import _core
from cablelife.results import CableResult

#: Largest axial strain Γ₃ (= F3/EA at rest) inside the validity range.
AXIAL_STRAIN_LIMIT = 0.05
#: Largest shear strain |(Γ₁, Γ₂)| inside the validity range.
SHEAR_STRAIN_LIMIT = 0.05
#: Pre-strain of a taut span (clips farther apart than the cable between them) above which
#: the mounting is reported.
PRESTRAIN_WARNING = 0.01


#: Estimated condition of the Jacobi-scaled tangent stiffness above which a model is reported
#: ill-conditioned: 1e11 = 1/ZERO_PIVOT of the stability check (a pivot eigenvalue below 1e-11
#: of its block counts as zero there), and the soft directions of a solve carry a relative
#: round-off error ε·cond ≳ 1e-5. Normal cables measure 4e5 (bench_dynamic, N = 100) to 8e9
#: (a 1 mm steel wire, N = 400) (docs/solver.md).
CONDITION_WARNING = 1e11
#: Ratio GA/EA outside which the shear stiffness is named as a cause (a homogeneous isotropic
#: section has GA/EA = κ/(2(1 + ν)) ≈ 0.3–0.4; braided or stranded cables differ, but not by
#: orders of magnitude).
SHEAR_AXIAL_RANGE = (0.01, 10.0)
#: Longest / shortest segment above which the mesh is named as a cause.
SEGMENT_RATIO_WARNING = 100.0


class ConditioningWarning(UserWarning):
    """The tangent stiffness of a cable is ill-conditioned."""


class StrainLimitWarning(UserWarning):
    """A strain outside the model's validity range."""


class PrestrainWarning(UserWarning):
    """A span is mounted stretched (its clips are farther apart than its length)."""


class StabilityWarning(UserWarning):
    """A static state is unstable, or the cable snapped through."""


class ImpactWarning(UserWarning):
    """An impact on the geometry that the time step does not resolve."""


def strains(c: CableResult, steps: slice = slice(None)) -> tuple[np.ndarray, np.ndarray]:
    """Axial strain Γ₃ and shear strain |(Γ₁, Γ₂)| per step and edge (T, N) from the saved
    configuration, Γ = Rᵀ (x_{n+1} − x_n)/Δs − e₃ (the model's strain; unlike F/EA it holds no
    damping forces in dynamic runs); of the saved ``steps`` only."""
    t, n = c.quaternions[steps].shape[:2]
    if t == 0 or n == 0:
        return np.zeros((t, n)), np.zeros((t, n))
    # Rust kernel (rod::shear::saved_strain): the rotation matrices of every step and edge are
    # never formed; a dynamic run saves 1000s of steps (numpy took 9 ms per simulated second of
    # bench_harness.py's harness, 5 % of its simulate()).
    return _core.section_strains(*_saved_configuration(c, steps))


def _saved_configuration(c: CableResult, steps: slice = slice(None)):
    """Positions, quaternions (of the saved ``steps``) and arc lengths as the Rust strain
    kernels take them: C-contiguous float64."""
    return (
        np.ascontiguousarray(c.positions[steps], dtype=float),
        np.ascontiguousarray(c.quaternions[steps], dtype=float),
        np.ascontiguousarray(c.arc_length, dtype=float),
    )


def strain_extremes(c: CableResult) -> dict:
    """Largest tensile, compressive and shear strains with where (s) and when (t): the first
    of equal values, a NaN counts as largest (so a NaN in a result is reported)."""
    # one pass in Rust (rod::shear::saved_strain_extremes), no strain arrays: 2.4 ms per
    # simulated second of bench_harness.py's harness instead of 12 ms over 5 s through the
    # arrays and numpy's argmax
    found = _core.strain_extremes(*_saved_configuration(c))
    out = {}
    for key, extreme in zip(("axial", "compression", "shear"), found or (None,) * 3, strict=True):
        if extreme is None:
            out[key] = {"value": 0.0, "s": float("nan"), "t": float("nan")}
            continue
        value, k, e = extreme
        mid = 0.5 * (c.arc_length[e] + c.arc_length[e + 1])
        out[key] = {"value": value, "s": float(mid), "t": float(c.time[k])}
    out["compression"]["value"] = -out["compression"]["value"]
    return out


def strain_violations(c: CableResult) -> list[str]:
    """Messages for the strains outside the validity range (empty: inside)."""
    ext = strain_extremes(c)
    out = []
    for key, label, limit in (
        ("axial", "axial strain", AXIAL_STRAIN_LIMIT),
        ("shear", "shear strain", SHEAR_STRAIN_LIMIT),
    ):
        v = ext[key]
        if v["value"] > limit:
            out.append(
                f"cable '{c.name}': {label} {100 * v['value']:.3g} % at s = {v['s']:.3f} m, "
                f"t = {v['t']:.4g} s exceeds the model's validity range ({100 * limit:g} %): "
                "the forces there are not physical (check the clip positions and the cable "
                "length)"
            )
    v = ext["compression"]
    if -v["value"] > AXIAL_STRAIN_LIMIT:
        out.append(
            f"cable '{c.name}': compressive strain {100 * -v['value']:.3g} % at "
            f"s = {v['s']:.3f} m, t = {v['t']:.4g} s exceeds the model's validity range "
            f"({100 * AXIAL_STRAIN_LIMIT:g} %)"
        )
    return out


def prestrain_messages(name: str, spans: list[tuple[str, str, float, float]]) -> list[str]:
    """Messages for the spans mounted stretched above ``PRESTRAIN_WARNING``."""
    out = []
    for a, b, chord, length in spans:
        eps = chord / length - 1.0
        if eps > PRESTRAIN_WARNING:
            out.append(
                f"cable '{name}': the span between clips '{a}' and '{b}' is mounted stretched "
                f"by {100 * eps:.3g} % (the clips are {chord:.4g} m apart, the cable between "
                f"them is {length:.4g} m long)"
            )
    return out


def snap_events(
    times: np.ndarray, arc: np.ndarray, fraction: np.ndarray, jump: np.ndarray, node: np.ndarray
) -> dict[str, np.ndarray]:
    """Snap-throughs of the saved steps: time (interpolated inside the step), arc length of the
    largest jump and its size (m)."""
    k = np.flatnonzero(node >= 0)
    prev = times[np.maximum(k - 1, 0)]
    t = prev + fraction[k] * (times[k] - prev)
    return {
        "snap_time": t.astype(float),
        "snap_s": arc[node[k]].astype(float),
        "snap_jump": jump[k].astype(float),
    }


def impact_messages(
    name: str, gains: np.ndarray, times: np.ndarray, given_back: np.ndarray | None = None
) -> list[str]:
    """The warnings for impacts the dynamic time step does not resolve (docs/contact.md): per
    saved step (T,), the largest energy gain, relative to the energies at play, of a sub-step
    split down to the deepest level (1/64 of the time step) since the saved step before, 0
    where none gained more than the guard's tolerance — ``given_back`` the gains the guard gave
    back from the motion near the contact (counted as dissipated), ``gains`` those it had to
    accept unresolved (the motion held less)."""
    out = []
    for values, what in (
        (
            given_back,
            "and was given back from the cable's motion near the contact (counted as dissipated "
            "energy: no step gains energy); the motion right after these impacts carries that "
            "correction (compare a run with a smaller time_step; docs/contact.md)",
        ),
        (
            gains,
            "and was accepted: the cable's motion held less energy than the gain; the contact "
            "forces and the motion right after these impacts are not reliable (compare a run "
            "with another time_step or contact damping; docs/contact.md)",
        ),
    ):
        if values is None:
            continue
        values = np.asarray(values, dtype=float)
        bad = np.flatnonzero(values > 0.0)
        if bad.size == 0:
            continue
        k = int(bad[np.argmax(values[bad])])
        out.append(
            f"{name}: an impact on the geometry is not resolved by the time step in {bad.size} "
            f"saved step(s): split down to 1/64 of the step, a sub-step still gained up to "
            f"{100 * values[k]:.3g} % of the energies at play (by t = {times[k]:.4g} s) {what}"
        )
    return out


def report(messages: list[str], category: type[Warning]) -> None:
    for m in messages:
        warnings.warn(m, category, stacklevel=3)


def conditioning_message(name: str, props, arc_length: np.ndarray, condition: float) -> str | None:
    """The warning for an ill-conditioned tangent (estimated ``condition`` of the Jacobi-scaled
    tangent stiffness, ``_core.Cable.condition``), with the causes found in the section ``props``
    and the mesh, or None below ``CONDITION_WARNING`` — and for a singular tangent (infinite
    estimate): a free rigid-body motion or a zero stiffness is an error of the solve, which
    names it."""
    if condition < CONDITION_WARNING or not np.isfinite(condition):
        return None
    causes = []
    ea = props.EA
    for label, ga in (("GA1", props.GA1), ("GA2", props.GA2)):
        ratio = ga / ea if ea > 0 else np.inf
        if not SHEAR_AXIAL_RANGE[0] <= ratio <= SHEAR_AXIAL_RANGE[1]:
            causes.append(
                f"{label} = {ratio:.3g}·EA (a homogeneous section has GA ≈ 0.3–0.4·EA; "
                f"allowed without this warning: {SHEAR_AXIAL_RANGE[0]:g}–"
                f"{SHEAR_AXIAL_RANGE[1]:g})"
            )
            break
    ds = np.diff(np.asarray(arc_length, dtype=float))
    if ds.size and ds.min() > 0 and ds.max() / ds.min() > SEGMENT_RATIO_WARNING:
        causes.append(
            f"segment lengths from {ds.min():.3g} to {ds.max():.3g} m (ratio "
            f"{ds.max() / ds.min():.3g}; clips or loads very close together)"
        )
    if not causes:
        causes.append(
            f"{ds.size} segments: a slender, finely meshed cable (the condition grows with the "
            "ratio of shear to bending stiffness at the segment scale, GA·Δs²/EI, and with N)"
        )
    return (
        f"cable '{name}': the tangent stiffness is ill-conditioned (estimated condition "
        f"≈ {condition:.2g}, "
        f"above {CONDITION_WARNING:.0e}): {'; '.join(causes)}. Round-off then reaches "
        "~1e-5 of the soft (bending) response and the stability verdict may be wrong"
    )
