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
    """Reads and checks a triangle mesh; ``what`` names the part in messages."""
    import trimesh

    if not path.is_file():
        raise SceneError(f"{what}: mesh file {str(path)!r} does not exist")
    try:
        loaded = trimesh.load(path, force="mesh", process=True)
    except Exception as err:  # trimesh raises many types for broken files
        raise SceneError(
            f"{what}: cannot read mesh file {str(path)!r} "
            f"({type(err).__name__}: {err}); allowed: STL (ascii or binary), OBJ, PLY"
        ) from None
    if not isinstance(loaded, trimesh.Trimesh) or len(loaded.faces) == 0:
        raise SceneError(f"{what}: mesh file {str(path)!r} has no triangles")
    mesh = loaded
    if not np.all(np.isfinite(mesh.vertices)):
        raise SceneError(f"{what}: mesh file {str(path)!r} has non-finite vertex coordinates")
    extent = float(np.ptp(mesh.vertices, axis=0).max())
    if scale is None and extent > MILLIMETRE_RATIO * max(scene_size, 1.0):
        raise SceneError(
            f"{what}: mesh {str(path)!r} spans {extent:.4g} units, {extent / scene_size:.0f}× "
            f"the scene ({scene_size:.3g} m): it is probably in millimetres; "
            "give scale = 0.001 (file units to metres)"
        )
    s = 1.0 if scale is None else scale
    vertices = np.asarray(mesh.vertices, float) * s
    faces = np.asarray(mesh.faces, np.int64)
    tri = vertices[faces]
    edges = np.linalg.norm(tri[:, [1, 2, 0]] - tri, axis=2)
    twice_area = np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1)
    # degenerate: height below 1e-9 of the mesh size (collinear or repeated vertices)
    longest = edges.max(axis=1)
    height = np.divide(twice_area, longest, out=np.zeros(len(faces)), where=longest > 0)
    bad = height <= 1e-9 * extent * s
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
        mesh = trimesh.Trimesh(mesh.vertices, faces[~bad], process=True)
        vertices = np.asarray(mesh.vertices, float) * s
        faces = np.asarray(mesh.faces, np.int64)
    watertight = bool(mesh.is_watertight)
    boundary = 0
    if watertight:
        if mesh.volume < 0:
            faces = faces[:, ::-1].copy()
            warnings.warn(
                f"{what}: the triangles of the closed mesh {str(path)!r} face inwards; "
                "flipped them (the solid is inside)",
                SurroundingsWarning,
                stacklevel=2,
            )
    else:
        from trimesh.grouping import group_rows

        boundary = len(group_rows(mesh.edges_sorted, require_count=1))
        normal = (mesh.face_normals * mesh.area_faces[:, None]).sum(axis=0)
        norm = np.linalg.norm(normal)
        side = (
            f"the area-weighted mean normal is ({', '.join(f'{x:.2f}' for x in normal / norm)})"
            if norm > 1e-9 * mesh.area
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
    if watertight and mesh.body_count > 1:
        from trimesh.graph import connected_component_labels, face_adjacency

        labels = connected_component_labels(face_adjacency(faces), node_count=len(faces))
        shells = [faces[labels == k] for k in range(labels.max() + 1)]
    return Mesh(vertices, faces, watertight, boundary, shells)
