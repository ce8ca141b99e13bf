"""Dragging a body in the workbench: the rigid map of a body from its pose in the scene as
opened to its pose now, the new ``placement`` of its geometry in global coordinates, and Euler
angles back from a rotation matrix (the scene's ``orientation``: R = Rz Ry Rx)."""

from __future__ import annotations

import numpy as np

from cablelife.rotations import euler_matrix
from cablelife.scene import Body


def matrix_euler(r: np.ndarray) -> list[float]:
    """rx, ry, rz (rad) with R = Rz(rz) Ry(ry) Rx(rx) (inverse of ``euler_matrix``; ry in
    [−π/2, π/2])."""
    r = np.asarray(r, float)
    ry = float(np.arcsin(np.clip(-r[2, 0], -1.0, 1.0)))
    if abs(np.cos(ry)) > 1e-9:
        rx = float(np.arctan2(r[2, 1], r[2, 2]))
        rz = float(np.arctan2(r[1, 0], r[0, 0]))
    else:  # gimbal lock: rx and rz turn about the same axis; put it all in rz
        rx = 0.0
        rz = float(np.arctan2(-r[0, 1], r[1, 1]))
    return [rx, ry, rz]


def body_pose(body: Body) -> tuple[np.ndarray, np.ndarray]:
    """(origin (3,), rotation (3, 3)) of a body at rest."""
    return np.asarray(body.origin, float), euler_matrix(body.orientation)


def rigid_map(before: Body, after: Body) -> tuple[np.ndarray, np.ndarray]:
    """(A, b): a point of the body at rest as ``before`` goes to A x + b as ``after``."""
    o0, r0 = body_pose(before)
    o1, r1 = body_pose(after)
    a = r1 @ r0.T
    return a, o1 - a @ o0


def global_parts(body: Body) -> list:
    """The body's geometry parts given in global coordinates (placed by ``placement``)."""
    return [p for p in body.geometry if p.frame != "body"]


def moved_placement(body: Body, a: np.ndarray, o0: np.ndarray, o1: np.ndarray) -> dict | None:
    """The body's ``placement`` after the drag x ↦ o1 + a (x − o0), as written to the scene:
    {"position", "orientation"}; None when the body has no parts in global coordinates."""
    if not global_parts(body):
        return None
    p, rp = body.part_frame(global_parts(body)[0])
    return {
        "position": (o1 + a @ (p - o0)).tolist(),
        "orientation": matrix_euler(a @ rp),
    }
