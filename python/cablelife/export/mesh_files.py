"""Triangle meshes as binary STL (geometry only) and binary PLY (geometry plus optional vertex
scalars), written atomically. Coordinates are written in metres unless ``unit="mm"``."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from cablelife.atomic import write_atomic

UNIT_SCALE = {"m": 1.0, "mm": 1000.0}


def _scale(unit: str) -> float:
    if unit not in UNIT_SCALE:
        raise ValueError(f"unit = {unit!r}: allowed are {', '.join(map(repr, UNIT_SCALE))}")
    return UNIT_SCALE[unit]


def _check(vertices, faces) -> tuple[np.ndarray, np.ndarray]:
    v = np.asarray(vertices, dtype=np.float64)
    f = np.asarray(faces)
    if v.ndim != 2 or v.shape[1] != 3:
        raise ValueError(f"vertices has shape {v.shape}: must be (V, 3)")
    if f.ndim != 2 or f.shape[1] != 3 or (f.size and (f.min() < 0 or f.max() >= len(v))):
        raise ValueError(f"faces has shape {f.shape}: must be (F, 3) indices into the vertices")
    return v, f.astype(np.int64)


def write_stl(path: str | os.PathLike, vertices, faces, *, unit: str = "m") -> Path:
    """Binary STL with facet normals from the vertex order (right-hand rule, outward)."""
    v, f = _check(vertices, faces)
    v = v * _scale(unit)
    tri = v[f]
    n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    length = np.linalg.norm(n, axis=1, keepdims=True)
    n = np.divide(n, length, out=np.zeros_like(n), where=length > 0)
    rec = np.zeros(len(f), dtype=[("n", "<f4", 3), ("v", "<f4", (3, 3)), ("attr", "<u2")])
    rec["n"] = n
    rec["v"] = tri
    header = f"cablelife mesh, unit {unit}".encode().ljust(80, b" ")

    def write(fh):
        fh.write(header)
        fh.write(np.uint32(len(f)).tobytes())
        fh.write(rec.tobytes())

    return write_atomic(path, write)


def read_stl(path: str | os.PathLike) -> tuple[np.ndarray, np.ndarray]:
    """Reads a binary STL: (vertices (3F, 3), faces (F, 3)); vertices are not merged."""
    data = Path(path).read_bytes()
    count = int(np.frombuffer(data, "<u4", 1, 80)[0])
    rec = np.frombuffer(
        data, dtype=[("n", "<f4", 3), ("v", "<f4", (3, 3)), ("attr", "<u2")], count=count, offset=84
    )
    vertices = rec["v"].reshape(-1, 3).astype(np.float64)
    return vertices, np.arange(3 * count).reshape(-1, 3)


def write_ply(
    path: str | os.PathLike,
    vertices,
    faces,
    *,
    vertex_data: dict[str, np.ndarray] | None = None,
    unit: str = "m",
) -> Path:
    """Binary little-endian PLY; ``vertex_data`` adds float32 scalar properties per vertex
    (e.g. a distance to another volume, for colouring in a viewer)."""
    v, f = _check(vertices, faces)
    v = v * _scale(unit)
    fields = [("x", "<f4"), ("y", "<f4"), ("z", "<f4")]
    extra = dict(vertex_data or {})
    for name, values in extra.items():
        if not name.isidentifier():
            raise ValueError(f"vertex_data name {name!r}: must be an identifier")
        if np.shape(values) != (len(v),):
            raise ValueError(
                f"vertex_data[{name!r}] has shape {np.shape(values)}: must be ({len(v)},)"
            )
        fields.append((name, "<f4"))
    vert = np.zeros(len(v), dtype=fields)
    vert["x"], vert["y"], vert["z"] = v.T
    for name, values in extra.items():
        vert[name] = values
    face = np.zeros(len(f), dtype=[("n", "u1"), ("i", "<i4", 3)])
    face["n"] = 3
    face["i"] = f
    props = "".join(f"property float {name}\n" for name, _ in fields)
    header = (
        "ply\nformat binary_little_endian 1.0\n"
        f"comment cablelife mesh, unit {unit}\n"
        f"element vertex {len(v)}\n{props}"
        f"element face {len(f)}\nproperty list uchar int vertex_indices\nend_header\n"
    ).encode("ascii")

    def write(fh):
        fh.write(header)
        fh.write(vert.tobytes())
        fh.write(face.tobytes())

    return write_atomic(path, write)


def read_ply(path: str | os.PathLike) -> tuple[np.ndarray, np.ndarray, dict[str, np.ndarray]]:
    """Reads a PLY written by :func:`write_ply`: (vertices, faces, vertex_data)."""
    data = Path(path).read_bytes()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    lines = data[:end].decode("ascii").splitlines()
    names, n_vert, n_face = [], 0, 0
    for line in lines:
        parts = line.split()
        if parts[:2] == ["element", "vertex"]:
            n_vert = int(parts[2])
        elif parts[:2] == ["element", "face"]:
            n_face = int(parts[2])
        elif parts[:2] == ["property", "float"]:
            names.append(parts[2])
    vert = np.frombuffer(data, dtype=[(n, "<f4") for n in names], count=n_vert, offset=end)
    face = np.frombuffer(
        data, dtype=[("n", "u1"), ("i", "<i4", 3)], count=n_face, offset=end + vert.nbytes
    )
    vertices = np.stack([vert["x"], vert["y"], vert["z"]], axis=1).astype(np.float64)
    extra = {n: vert[n].astype(np.float64) for n in names if n not in ("x", "y", "z")}
    return vertices, face["i"].astype(np.int64), extra
