"""Mesh files of the surroundings: reading (trimesh) and the checks that report problems
instead of guessing: missing or unreadable file, no triangles, degenerate triangles, a mesh in
millimetres without ``scale``, inverted or open meshes."""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from cablelife.scene import SceneError

# more degenerate triangles than this fraction is an error (a broken export), fewer are dropped
MAX_DEGENERATE_FRACTION = 0.1
# a mesh this many times larger than the scene (and over this many metres) without ``scale``
# is taken for a file in millimetres
MILLIMETRE_RATIO = 20.0


class SurroundingsWarning(UserWarning):
    """A mesh that is usable but not what it should be (dropped triangles, open surface)."""


@dataclass
class Mesh:
    vertices: np.ndarray  # (V, 3) m, merged
    faces: np.ndarray  # (F, 3) int64
    watertight: bool
    boundary_edges: int
    # closed meshes of several shells (overlapping solids exported together): the faces of
    # each shell, measured as separate solids (their union) so that overlaps stay inside
    shells: list[np.ndarray] | None = None


def load_mesh(path: Path, scale: float | None, what: str, scene_size: float) -> Mesh:
    """Reads and checks a triangle mesh; ``what`` names the part in messages.

    trimesh reads the file (its binary STL reader is numpy); merging the vertices and the
    edge topology are passes in Rust (``merge_vertices``, ``_core.mesh_topology``), the other
    checks vectorised: a 1 M-triangle STL takes a fraction of a second instead of seconds of
    trimesh's general processing."""
    from cablelife import interrupt

    if not path.is_file():
        raise SceneError(f"{what}: mesh file {str(path)!r} does not exist")
    try:
        # trimesh swallows KeyboardInterrupt while it imports (interrupt.deferred)
        with interrupt.deferred():
            import trimesh

            raw, faces = read_triangles(path, trimesh)
    except Exception as err:  # trimesh raises many types for broken files
        raise SceneError(
            f"{what}: cannot read mesh file {str(path)!r} "
            f"({type(err).__name__}: {err}); allowed: STL (ascii or binary), OBJ, PLY"
        ) from None
    if raw is None or len(faces) == 0:
        raise SceneError(f"{what}: mesh file {str(path)!r} has no triangles")
    if not np.all(np.isfinite(raw)):
        raise SceneError(f"{what}: mesh file {str(path)!r} has non-finite vertex coordinates")
    vertices, faces = merge_vertices(raw, faces)
    extent = float(np.ptp(vertices, axis=0).max())
    if scale is None and extent > MILLIMETRE_RATIO * max(scene_size, 1.0):
        raise SceneError(
            f"{what}: mesh {str(path)!r} spans {extent:.4g} units, {extent / scene_size:.0f}× "
            f"the scene ({scene_size:.3g} m): it is probably in millimetres; "
            "give scale = 0.001 (file units to metres)"
        )
    s = 1.0 if scale is None else scale
    vertices = vertices * s
    v0, v1, v2 = (vertices[faces[:, k]] for k in range(3))
    e0, e2 = v1 - v0, v2 - v0
    cross = np.cross(e0, e2)
    twice_area = np.sqrt(np.einsum("ij,ij->i", cross, cross))
    e1 = v2 - v1
    longest2 = np.maximum(
        np.einsum("ij,ij->i", e0, e0),
        np.maximum(np.einsum("ij,ij->i", e1, e1), np.einsum("ij,ij->i", e2, e2)),
    )
    # degenerate: height (twice the area over the longest edge) below 1e-9 of the mesh size
    # (collinear or repeated vertices)
    bad = twice_area <= 1e-9 * extent * s * np.sqrt(longest2)
    n_bad = int(bad.sum())
    if n_bad:
        frac = n_bad / len(faces)
        if frac > MAX_DEGENERATE_FRACTION:
            raise SceneError(
                f"{what}: {n_bad} of {len(faces)} triangles of {str(path)!r} are degenerate "
                f"(zero area), more than {MAX_DEGENERATE_FRACTION:.0%}: re-export the mesh"
            )
        warnings.warn(
            f"{what}: dropped {n_bad} degenerate (zero-area) triangles of {len(faces)} in "
            f"{str(path)!r}",
            SurroundingsWarning,
            stacklevel=2,
        )
        if n_bad == len(faces):
            raise SceneError(f"{what}: mesh file {str(path)!r} has no triangles")
        vertices, faces = drop_unused(vertices, faces[~bad])
        v0, cross, twice_area = v0[~bad], cross[~bad], twice_area[~bad]
    from cablelife import _core

    # closed (every edge in two faces), boundary edges, shells (faces joined by shared edges):
    # one pass in Rust (geometry::topology)
    watertight, boundary, labels, n_shells = _core.mesh_topology(
        np.ascontiguousarray(faces, np.int64), len(vertices)
    )
    if watertight:
        # signed volume: the sum of the tetrahedra from the origin, ∝ Σ v0·(v1 × v2)
        if np.einsum("ij,ij->", v0, cross) < 0:
            faces = faces[:, ::-1].copy()
            warnings.warn(
                f"{what}: the triangles of the closed mesh {str(path)!r} face inwards; "
                "flipped them (the solid is inside)",
                SurroundingsWarning,
                stacklevel=2,
            )
    else:
        normal = cross.sum(axis=0)  # area-weighted normals (twice the area)
        norm = np.linalg.norm(normal)
        side = (
            f"the area-weighted mean normal is ({', '.join(f'{x:.2f}' for x in normal / norm)})"
            if norm > 1e-9 * twice_area.sum()
            else "its normals point to both sides equally"
        )
        warnings.warn(
            f"{what}: mesh {str(path)!r} is open ({boundary} boundary edges): the clearance "
            "is measured to its surface, and the side its triangle normals point to counts "
            f"as outside ({side})",
            SurroundingsWarning,
            stacklevel=2,
        )
    shells = None
    if watertight and n_shells > 1:  # a closed mesh of several solids: each its own
        shells = [faces[labels == k] for k in range(n_shells)]
    return Mesh(vertices, faces, watertight, boundary, shells)


def read_triangles(path: Path, trimesh) -> tuple[np.ndarray | None, np.ndarray]:
    """Vertices (float64) and faces (int64) as the file stores them (not merged); None when
    the file holds no mesh. STL by trimesh's reader alone (numpy; its general loader wraps the
    result in a scene and copies it), other formats by ``trimesh.load``."""
    if path.suffix.lower() == ".stl":
        from trimesh.exchange.stl import load_stl

        with open(path, "rb") as f:
            kw = load_stl(f)
        return np.asarray(kw["vertices"], float), np.asarray(kw["faces"], np.int64)
    loaded = trimesh.load(path, force="mesh", process=False)
    if not isinstance(loaded, trimesh.Trimesh):
        return None, np.zeros((0, 3), np.int64)
    return np.asarray(loaded.vertices, float), np.asarray(loaded.faces, np.int64)


def merge_vertices(vertices: np.ndarray, faces: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Merges vertices that agree to 8 decimals of the file's unit, as trimesh does (an STL
    repeats each shared vertex per triangle, exports leave float noise at seams), keeping the
    order and coordinates of first appearance; faces re-indexed (``_core.weld_vertices``: one
    hash-map pass in Rust; reading a 1 M-triangle STL 0.61 → 0.46 s, docs/environment.md)."""
    from cablelife import _core

    v = np.ascontiguousarray(vertices, float)
    return _core.weld_vertices(v, np.ascontiguousarray(faces, np.int64))


def drop_unused(vertices: np.ndarray, faces: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The vertices the faces use, faces re-indexed."""
    used = np.zeros(len(vertices), bool)
    used[faces] = True
    new = np.cumsum(used) - 1
    return vertices[used], new[faces]
