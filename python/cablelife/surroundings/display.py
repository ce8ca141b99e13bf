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
    ``max_faces`` non-degenerate triangles remain (for display only)."""
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
        cells *= 0.7


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
        n = np.asarray(part.normal, float)
        n /= np.linalg.norm(n)
        u = np.cross(n, np.eye(3)[int(np.argmin(np.abs(n)))])
        u /= np.linalg.norm(u)
        w = np.cross(n, u)
        p = np.asarray(part.point, float)
        if near is not None:
            p = near - n * (np.asarray(near, float) - p).dot(n)
        h = size / 2
        v = np.array([p + h * (a * u + b * w) for a, b in ((-1, -1), (1, -1), (1, 1), (-1, 1))])
        return v, np.array([[0, 1, 2], [0, 2, 3]])
    import trimesh  # 0.5 s to import: only for the solids (a plane needs none)

    from cablelife.simulate import euler_matrix

    t = np.eye(4)
    t[:3, 3] = part.center
    if part.shape == "box":
        t[:3, :3] = euler_matrix(part.orientation)
        m = trimesh.creation.box(extents=part.size, transform=t)
    elif part.shape == "cylinder":
        a = np.asarray(part.axis, float)
        t[:3, :3] = trimesh.geometry.align_vectors([0, 0, 1], a / np.linalg.norm(a))[:3, :3]
        m = trimesh.creation.cylinder(
            radius=part.radius, height=part.length, sections=48, transform=t
        )
    else:
        m = trimesh.creation.icosphere(subdivisions=3, radius=part.radius)
        m.apply_translation(part.center)
    return np.asarray(m.vertices, float), np.asarray(m.faces, np.int64)


def merge(meshes: list[tuple[np.ndarray, np.ndarray]]) -> tuple[np.ndarray, np.ndarray]:
    vs, fs, n = [], [], 0
    for v, f in meshes:
        vs.append(v)
        fs.append(f + n)
        n += len(v)
    if not vs:
        return np.zeros((0, 3)), np.zeros((0, 3), np.int64)
    return np.concatenate(vs), np.concatenate(fs)
