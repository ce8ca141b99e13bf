"""The surroundings for pictures: one triangle mesh per body (global coordinates at rest,
decimated to at most ``MAX_FACES`` triangles by vertex clustering; primitives tessellated)
and the body poses per saved step. Stored in the result (``/surroundings``) so that reports
and ParaView need neither the scene's folder nor the mesh files."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

MAX_FACES = 20_000


@dataclass
class SurroundingsGeometry:
    bodies: list[str]
    meshes: list[tuple[np.ndarray, np.ndarray]]  # per body: vertices (V, 3) m, faces (F, 3)
    time: np.ndarray  # (T,) s
    poses: np.ndarray  # (B, T, 3, 4): x = R X + t, [R | t], X the rest (global) position

    def at(self, body: int, step: int) -> np.ndarray:
        """Vertices of body ``body`` at saved step ``step``."""
        v, _ = self.meshes[body]
        p = self.poses[body, min(step, self.poses.shape[1] - 1)]
        return v @ p[:, :3].T + p[:, 3]

    def write(self, f) -> None:
        g = f.create_group("surroundings")
        g.attrs["bodies"] = np.array(self.bodies, dtype=object)
        g.create_dataset("time", data=self.time).attrs["unit"] = "s"
        ds = g.create_dataset("poses", data=self.poses, compression="gzip")
        ds.attrs["unit"] = "1, m"
        ds.attrs["definition"] = "x = R X + t with [R | t] per body and step; X at rest, global"
        for k, (v, fc) in enumerate(self.meshes):
            b = g.create_group(f"mesh_{k}")
            b.attrs["body"] = self.bodies[k]
            b.create_dataset("vertices", data=v, compression="gzip").attrs["unit"] = "m"
            b.create_dataset("faces", data=fc.astype(np.int32), compression="gzip")

    @classmethod
    def read(cls, f) -> SurroundingsGeometry | None:
        if "surroundings" not in f:
            return None
        g = f["surroundings"]
        bodies = [x.decode() if isinstance(x, bytes) else str(x) for x in g.attrs["bodies"]]
        meshes = [
            (g[f"mesh_{k}/vertices"][()], g[f"mesh_{k}/faces"][()].astype(np.int64))
            for k in range(len(bodies))
        ]
        return cls(bodies, meshes, g["time"][()], g["poses"][()])


def decimate(vertices: np.ndarray, faces: np.ndarray, max_faces: int = MAX_FACES):
    """Vertex-clustering decimation: vertices snapped to a grid whose cell grows until at most
    ``max_faces`` non-degenerate triangles remain (for display only). The triangles of a
    surface scale with the square of the cells across it, so a grid with too many is coarsened
    by that estimate (with 5 % to spare): 2–3 passes instead of one per ×0.7 before, and nearer
    to ``max_faces``."""
    if len(faces) <= max_faces:
        return vertices, faces
    lo = vertices.min(axis=0)
    extent = float(np.ptp(vertices, axis=0).max())
    cells = 2.0 * np.sqrt(max_faces)
    while True:
        size = extent / cells
        key = np.floor((vertices - lo) / size).astype(np.int64)
        _, inverse, counts = _unique_rows(key)
        sums = np.stack(
            [np.bincount(inverse, weights=vertices[:, k], minlength=counts.size) for k in range(3)],
            axis=1,
        )
        v = sums / counts[:, None]
        f = inverse[faces]
        keep = (f[:, 0] != f[:, 1]) & (f[:, 1] != f[:, 2]) & (f[:, 0] != f[:, 2])
        f = f[keep][_unique_rows(f[keep])[0]]
        if len(f) <= max_faces or cells < 4:
            used, f = np.unique(f, return_inverse=True)
            return v[used], f.reshape(-1, 3)
        cells *= next_cells(len(f), max_faces)


def next_cells(faces: int, max_faces: int) -> float:
    """The factor on the cells across the grid after a pass that left ``faces`` triangles
    (more than ``max_faces``): below 0.95, so the passes end."""
    return 0.95 * float(np.sqrt(max_faces / faces))


def _unique_rows(rows: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``np.unique(rows, axis=0, return_index, return_inverse, return_counts)`` of
    non-negative integer rows (n, 3) in the same (lexicographic) order: the rows packed into
    one int64 each, unique on that (several times faster than on rows)."""
    span = rows.max(axis=0).astype(np.int64) + 1 if len(rows) else np.ones(3, np.int64)
    if float(span[0]) * float(span[1]) * float(span[2]) >= 2.0**62:
        _, first, inverse, counts = np.unique(
            rows, axis=0, return_index=True, return_inverse=True, return_counts=True
        )
        return first, inverse.ravel(), counts
    packed = (rows[:, 0] * span[1] + rows[:, 1]) * span[2] + rows[:, 2]
    _, first, inverse, counts = np.unique(
        packed, return_index=True, return_inverse=True, return_counts=True
    )
    return first, inverse.ravel(), counts


def primitive_mesh(part, size: float, near=None) -> tuple[np.ndarray, np.ndarray]:
    """A triangle mesh of an analytic part (in its own coordinates); a plane becomes a square
    of side ``size`` around the projection of ``near`` (default: its point)."""
    if part.shape == "plane":
        u, w, n = _basis(part.normal)
        p = np.asarray(part.point, float)
        if near is not None:
            p = near - n * (np.asarray(near, float) - p).dot(n)
        h = size / 2
        v = np.array([p + h * (a * u + b * w) for a, b in ((-1, -1), (1, -1), (1, 1), (-1, 1))])
        return v, np.array([[0, 1, 2], [0, 2, 3]])
    # The solids are tessellated here rather than by trimesh.creation: importing trimesh takes
    # 0.3–0.5 s (scipy.spatial with it), a quarter of a small `cablelife run` whose scene has
    # only primitives (tests compare these meshes with trimesh's).
    from cablelife.rotations import euler_matrix

    c = np.asarray(part.center, float)
    if part.shape == "box":
        return box_mesh(c, euler_matrix(part.orientation), part.size)
    if part.shape == "cylinder":
        return cylinder_mesh(c, part.axis, part.radius, part.length)
    return sphere_mesh(c, part.radius)


# The cube [−½, ½]³: corners by bits (x, y, z), two outward triangles per face.
_CUBE = np.array([[(i >> 0) & 1, (i >> 1) & 1, (i >> 2) & 1] for i in range(8)], float) - 0.5
_CUBE_FACES = np.array(
    [[0, 2, 1], [1, 2, 3], [4, 5, 6], [5, 7, 6], [0, 1, 4], [1, 5, 4],
     [2, 6, 3], [3, 6, 7], [0, 4, 2], [2, 4, 6], [1, 3, 5], [3, 7, 5]],
    np.int64,
)  # fmt: skip


def box_mesh(center, rotation, size) -> tuple[np.ndarray, np.ndarray]:
    """The box of edge lengths ``size`` (its axes the columns of ``rotation``) around
    ``center``: 8 vertices, 12 triangles, normals outward."""
    v = (_CUBE * np.asarray(size, float)) @ np.asarray(rotation, float).T + center
    return v, _CUBE_FACES.copy()


def _basis(axis) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Unit vectors u, w, a with a along ``axis`` and (u, w, a) right-handed."""
    a = np.asarray(axis, float)
    a = a / np.linalg.norm(a)
    u = np.cross(a, np.eye(3)[int(np.argmin(np.abs(a)))])
    u /= np.linalg.norm(u)
    return u, np.cross(a, u), a


def cylinder_mesh(center, axis, radius, length, sections: int = 48):
    """The closed cylinder (a prism of ``sections`` sides, corners on the circle): two rings
    and a centre on each end cap; normals outward."""
    u, w, a = _basis(axis)
    phi = 2 * np.pi * np.arange(sections) / sections
    ring = radius * (np.cos(phi)[:, None] * u + np.sin(phi)[:, None] * w)
    half = 0.5 * length * a
    v = np.concatenate([ring - half, ring + half, [-half, half]]) + center
    k = np.arange(sections)
    k1 = (k + 1) % sections
    n = sections
    faces = np.concatenate(
        [
            np.stack([k, k1, n + k], 1),  # side
            np.stack([k1, n + k1, n + k], 1),
            np.stack([np.full(n, 2 * n), k1, k], 1),  # bottom cap (normal −a)
            np.stack([np.full(n, 2 * n + 1), n + k, n + k1], 1),  # top cap (normal +a)
        ]
    )
    return v, faces.astype(np.int64)


def sphere_mesh(center, radius, rings: int = 16, sectors: int = 32):
    """The sphere as a latitude–longitude mesh with its poles: ``rings`` bands of ``sectors``
    quads (triangle fans at the poles); vertices on the sphere, normals outward."""
    theta = np.pi * np.arange(1, rings) / rings  # polar angles of the inner rings
    phi = 2 * np.pi * np.arange(sectors) / sectors
    st, ct = np.sin(theta)[:, None], np.cos(theta)[:, None]
    ring = np.stack([st * np.cos(phi), st * np.sin(phi), ct * np.ones_like(phi)], -1)
    v = np.concatenate([[[0.0, 0.0, 1.0]], ring.reshape(-1, 3), [[0.0, 0.0, -1.0]]])
    idx = 1 + np.arange((rings - 1) * sectors).reshape(rings - 1, sectors)
    nxt = np.roll(idx, -1, axis=1)
    south = len(v) - 1
    faces = [np.stack([np.zeros(sectors, np.int64), idx[0], nxt[0]], 1)]
    for r in range(rings - 2):
        a, b, c, d = idx[r], nxt[r], idx[r + 1], nxt[r + 1]
        faces += [np.stack([a, c, b], 1), np.stack([b, c, d], 1)]
    faces.append(np.stack([np.full(sectors, south), nxt[-1], idx[-1]], 1))
    return radius * v + np.asarray(center, float), np.concatenate(faces).astype(np.int64)


def merge(meshes: list[tuple[np.ndarray, np.ndarray]]) -> tuple[np.ndarray, np.ndarray]:
    vs, fs, n = [], [], 0
    for v, f in meshes:
        vs.append(v)
        fs.append(f + n)
        n += len(v)
    if not vs:
        return np.zeros((0, 3)), np.zeros((0, 3), np.int64)
    return np.concatenate(vs), np.concatenate(fs)
