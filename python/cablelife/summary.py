"""Key figures of a result, for the run summary and reports."""

from __future__ import annotations

import numpy as np

from cablelife.results import CableResult
from cablelife.validity import strain_extremes

#: The run summary warns when the viscous part of a peak section load exceeds this share of it:
#: the damping model, not the stiffness, then sets that load (docs/dynamics.md).
VISCOUS_SHARE_WARNING = 0.5


def viscous_share(c: CableResult) -> np.ndarray | None:
    """Peak of the viscous (Kelvin–Voigt) part of |F3|, |F1, F2|, |M1, M2|, |M3| over the
    saved steps of a dynamic run, as a share of the peak of the whole load (None for static
    runs)."""
    peak = c.solver.get("viscous_peak")
    if peak is None:
        return None
    f, m = c.forces, c.moments
    total = np.array(
        [
            np.abs(f[..., 2]).max(),
            np.hypot(f[..., 0], f[..., 1]).max(),
            np.hypot(m[..., 0], m[..., 1]).max(),
            np.abs(m[..., 2]).max(),
        ]
    )
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(total > 0, np.asarray(peak) / total, 0.0)


def cable_summary(c: CableResult, strains: bool = True) -> dict:
    """Maxima over time and arc length, the smallest bend radius, clip reaction maxima and the
    solver statistics of one cable; with ``strains`` the strain extremes (the ``max_*_strain``
    keys: a third of the cost, the report does not show them)."""
    f, m = c.forces, c.moments
    radius = c.bend_radius()
    i_min = np.unravel_index(np.argmin(radius), radius.shape)
    clips = {
        name: {
            "s": r.s,
            "max_force": float(np.linalg.norm(r.force, axis=-1).max()),
            "max_moment": float(np.linalg.norm(r.moment, axis=-1).max()),
        }
        for name, r in c.clips.items()
    }
    iters = np.asarray(c.solver.get("iterations", [0]))
    strain = strain_extremes(c) if strains else None
    unstable = np.asarray(c.solver.get("unstable", []))
    snap_t = np.atleast_1d(c.solver.get("snap_time", []))
    return {
        "steps": c.n_steps,
        "segments": int(c.arc_length.size - 1),
        "max_tension": float(f[..., 2].max()),
        "min_tension": float(f[..., 2].min()),
        "max_shear": float(np.hypot(f[..., 0], f[..., 1]).max()),
        "max_bending": float(np.hypot(m[..., 0], m[..., 1]).max()),
        "max_torsion": float(np.abs(m[..., 2]).max()),
        "min_bend_radius": float(radius[i_min]),
        "min_bend_radius_s": float(c.arc_length[i_min[1]]),
        "min_bend_radius_t": float(c.time[i_min[0]]),
        "clips": clips,
        "newton_iterations_mean": float(iters.mean()) if iters.size else 0.0,
        "newton_iterations_max": int(iters.max()) if iters.size else 0,
        "wall_time": float(c.solver.get("wall_time", float("nan"))),
        **(
            {}
            if strain is None
            else {
                "max_axial_strain": strain["axial"],
                "max_compressive_strain": strain["compression"],
                "max_shear_strain": strain["shear"],
            }
        ),
        "prestrain": float(c.solver.get("prestrain", 0.0)),
        "unstable_steps": int((unstable > 0).sum()),
        "snap_throughs": [
            {"t": float(t), "s": float(s_), "jump": float(j)}
            for t, s_, j in zip(
                snap_t,
                np.atleast_1d(c.solver.get("snap_s", [])),
                np.atleast_1d(c.solver.get("snap_jump", [])),
                strict=True,
            )
        ],
        "viscous_share": viscous_share(c),
    }
