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

from cablelife.results import CableResult

#: Largest axial strain Γ₃ (= F3/EA at rest) inside the validity range.
AXIAL_STRAIN_LIMIT = 0.05
#: Largest shear strain |(Γ₁, Γ₂)| inside the validity range.
SHEAR_STRAIN_LIMIT = 0.05
#: Pre-strain of a taut span (clips farther apart than the cable between them) above which
#: the mounting is reported.
PRESTRAIN_WARNING = 0.01


class StrainLimitWarning(UserWarning):
    """A strain outside the model's validity range."""


class PrestrainWarning(UserWarning):
    """A span is mounted stretched (its clips are farther apart than its length)."""


class StabilityWarning(UserWarning):
    """A static state is unstable, or the cable snapped through."""


def strains(c: CableResult) -> tuple[np.ndarray, np.ndarray]:
    """Axial strain Γ₃ and shear strain |(Γ₁, Γ₂)| per step and edge (T, N) from the saved
    configuration, Γ = Rᵀ (x_{n+1} − x_n)/Δs − e₃ (the model's strain; unlike F/EA it holds no
    damping forces in dynamic runs)."""
    from cablelife.export.frames import rotation_matrices

    t, n = c.quaternions.shape[:2]
    if t == 0 or n == 0:
        return np.zeros((t, n)), np.zeros((t, n))
    tangent = np.diff(c.positions, axis=1) / np.diff(c.arc_length)[None, :, None]
    gamma = np.einsum("...ji,...j->...i", rotation_matrices(c.quaternions), tangent)  # Rᵀ t
    return gamma[..., 2] - 1.0, np.hypot(gamma[..., 0], gamma[..., 1])


def _largest(values: np.ndarray, c: CableResult) -> dict:
    """The largest entry of (T, N) edge values with its time and arc length (edge midpoint)."""
    if values.size == 0:
        return {"value": 0.0, "s": float("nan"), "t": float("nan")}
    k, e = np.unravel_index(int(np.argmax(values)), values.shape)
    mid = 0.5 * (c.arc_length[e] + c.arc_length[e + 1])
    return {"value": float(values[k, e]), "s": float(mid), "t": float(c.time[k])}


def strain_extremes(c: CableResult) -> dict:
    """Largest tensile, compressive and shear strains with where (s) and when (t)."""
    axial, shear = strains(c)
    return {
        "axial": _largest(axial, c),
        "compression": {**(d := _largest(-axial, c)), "value": -d["value"]},
        "shear": _largest(shear, c),
    }


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


def report(messages: list[str], category: type[Warning]) -> None:
    for m in messages:
        warnings.warn(m, category, stacklevel=3)
