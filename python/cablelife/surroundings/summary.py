"""Key figures of the clearance: per body the minimum and where (s) and when (t) it occurs;
the cable length in collision (clearance < 0) and closer than ``min_clearance``."""

from __future__ import annotations

import numpy as np


def node_lengths(arc_length: np.ndarray) -> np.ndarray:
    """Length of cable each node stands for (half of each adjacent segment)."""
    ds = np.diff(arc_length)
    w = np.zeros(arc_length.size)
    w[:-1] += ds / 2
    w[1:] += ds / 2
    return w


def clearance_summary(c) -> dict:
    """Per body: minimum clearance, s and t of it; the largest length (over time) in
    collision and closer than min_clearance, and when."""
    cl = c.surroundings
    w = node_lengths(c.arc_length)
    bodies = {}
    for b, name in enumerate(cl.bodies):
        mask = cl.body == b
        if not mask.any():
            bodies[name] = None
            continue
        masked = np.where(mask, cl.value, np.inf)
        i = np.unravel_index(np.argmin(masked), masked.shape)
        bodies[name] = {
            "min": float(masked[i]),
            "s": float(c.arc_length[i[1]]),
            "t": float(c.time[i[0]]),
            "part": cl.parts[int(cl.part[i])],
        }
    colliding = ((cl.value < 0) * w).sum(axis=1)
    close = ((cl.value < cl.min_clearance) * w).sum(axis=1)
    return {
        "bodies": bodies,
        "min_clearance": cl.min_clearance,
        "length_in_collision": float(colliding.max()),
        "length_in_collision_t": float(c.time[int(np.argmax(colliding))]),
        "length_below_min": float(close.max()),
        "length_below_min_t": float(c.time[int(np.argmax(close))]),
    }


def clearance_tables(c) -> list:
    """Rich tables of :func:`clearance_summary` (for ``cablelife run``)."""
    from rich.markup import escape
    from rich.table import Table

    s = clearance_summary(c)
    t = Table(title="clearance to the surroundings (cable surface)", title_justify="left")
    t.add_column("body")
    t.add_column(escape("min clearance [m]"), justify="right")
    t.add_column(escape("at s [m]"), justify="right")
    t.add_column(escape("at t [s]"), justify="right")
    t.add_column("nearest part")
    for name, v in s["bodies"].items():
        if v is None:
            t.add_row(escape(name), "never nearest", "", "", "")
        else:
            t.add_row(
                escape(name), f"{v['min']:.4g}", f"{v['s']:.3f}", f"{v['t']:.4g}", escape(v["part"])
            )
    lengths = Table(
        title="cable length near the surroundings (max over time)", title_justify="left"
    )
    lengths.add_column("")
    lengths.add_column(escape("length [m]"), justify="right")
    lengths.add_column(escape("at t [s]"), justify="right")
    lengths.add_row(
        "in collision (clearance < 0)",
        f"{s['length_in_collision']:.4g}",
        f"{s['length_in_collision_t']:.4g}",
    )
    lengths.add_row(
        f"closer than min_clearance = {s['min_clearance']:g} m",
        f"{s['length_below_min']:.4g}",
        f"{s['length_below_min_t']:.4g}",
    )
    return [t, lengths]
