"""Dragging a body in the workbench: the rigid map of a body from its pose in the scene as
opened to its pose now, the check that a moved body can be saved, and Euler angles back from a
rotation matrix (the scene's ``orientation``: R = Rz Ry Rx)."""

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


def unsaveable_geometry(body: Body) -> str:
    """Why a drag of ``body`` could not be saved ("" when it can): the scene format moves a
    body's geometry with its ``origin``/``orientation`` only for parts given in the body frame
    (``frame = "body"``); parts in global coordinates (meshes as CAD exports them) have no
    placement to write."""
    fixed = [p for p in body.geometry if getattr(p, "frame", "global") != "body"]
    if not fixed:
        return ""
    names = ", ".join(
        repr(getattr(p, "name", None) or str(getattr(p, "mesh", None) or p.shape))
        for p in fixed[:3]
    )
    return (
        f"body '{body.name}' cannot be dragged: its geometry part(s) {names} are in global "
        "coordinates, and the scene format has no placement for them (a moved body could not "
        'be saved); give them frame = "body" (coordinates in the body\'s axes) to drag it'
    )
