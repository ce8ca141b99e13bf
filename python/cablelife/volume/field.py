"""Signed-distance fields of unions of capsules on voxel grids (the compiled kernel)."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from cablelife import _core, interrupt

#: Largest grid built without complaint (about 1.2 GB of float32).
MAX_VOXELS = 300_000_000
#: Voxels per call of the distance kernel (a fraction of a second).
SLAB_VOXELS = 2_000_000


@dataclass(frozen=True)
class Capsules:
    """Capsules: axis end points ``starts``, ``ends`` (M, 3) in m and radii (M,) in m."""

    starts: np.ndarray
    ends: np.ndarray
    radius: np.ndarray

    def __post_init__(self):
        for name in ("starts", "ends"):
            a = np.ascontiguousarray(getattr(self, name), dtype=np.float64)
            if a.ndim != 2 or a.shape[1] != 3:
                raise ValueError(f"{name} has shape {a.shape}: must be (M, 3)")
            object.__setattr__(self, name, a)
        r = np.ascontiguousarray(np.broadcast_to(self.radius, (len(self.starts),)), np.float64)
        object.__setattr__(self, "radius", r)
        if self.ends.shape != self.starts.shape:
            raise ValueError(
                f"ends has shape {self.ends.shape}: must match starts {self.starts.shape}"
            )

    def __len__(self) -> int:
        return len(self.starts)

    @property
    def bounding_box(self) -> np.ndarray:
        """Exact axis-aligned bounds of the union, (2, 3): rows min and max, m."""
        if len(self) == 0:
            raise ValueError("no capsules: the volume is empty")
        r = self.radius[:, None]
        lo = np.minimum(self.starts - r, self.ends - r).min(axis=0)
        hi = np.maximum(self.starts + r, self.ends + r).max(axis=0)
        return np.stack([lo, hi])

    def concat(self, other: Capsules) -> Capsules:
        return Capsules(
            np.concatenate([self.starts, other.starts]),
            np.concatenate([self.ends, other.ends]),
            np.concatenate([self.radius, other.radius]),
        )

    def distance(self, points) -> np.ndarray:
        """Exact signed distance of ``points`` (P, 3) to the union, (P,) m."""
        p = np.ascontiguousarray(points, dtype=np.float64).reshape(-1, 3)
        return _core.capsule_distance(self.starts, self.ends, self.radius, p)


@dataclass(frozen=True)
class VoxelField:
    """A signed distance sampled at origin + spacing·(i, j, k), clamped to ±band (m)."""

    values: np.ndarray
    origin: np.ndarray
    spacing: float
    band: float

    def points(self, index: np.ndarray) -> np.ndarray:
        """Coordinates (P, 3) of voxel indices (P, 3)."""
        return self.origin + self.spacing * np.asarray(index, dtype=np.float64)


def check_voxel(voxel: float) -> float:
    voxel = float(voxel)
    if not (np.isfinite(voxel) and voxel > 0):
        raise ValueError(f"voxel = {voxel}: must be a length > 0 in m (e.g. 0.002 for 2 mm)")
    return voxel


def grid_for(bounds: np.ndarray, voxel: float, pad: int = 2) -> tuple[np.ndarray, tuple]:
    """Origin and shape of a grid with spacing ``voxel`` covering ``bounds`` (2, 3) plus
    ``pad`` voxels on every side (so the border lies outside and meshes close)."""
    voxel = check_voxel(voxel)
    bounds = np.asarray(bounds, dtype=np.float64)
    origin = bounds[0] - pad * voxel
    shape = tuple(
        int(n) for n in np.ceil((bounds[1] - bounds[0]) / voxel).astype(int) + 2 * pad + 1
    )
    n = int(np.prod(shape, dtype=np.int64))
    if n > MAX_VOXELS:
        raise ValueError(
            f"voxel = {voxel * 1e3:g} mm gives a grid of {shape} = {n:.3g} voxels "
            f"(more than {MAX_VOXELS:.0e}): use a coarser voxel"
        )
    return origin, shape


def signed_distance(
    capsules: Capsules,
    origin,
    shape,
    voxel: float,
    band: float | None = None,
    progress: Callable[[int, int], None] | None = None,
) -> VoxelField:
    """The union's signed distance on a grid (parallel compiled kernel, GIL released).

    ``band`` (default 3 voxels) bounds the stored magnitude; values are exact inside it, which
    is all marching cubes needs (a vertex lies within one voxel of the surface).
    ``progress(done, total)``: grid rows (axis 0) computed so far."""
    voxel = check_voxel(voxel)
    band = 3.0 * voxel if band is None else float(band)
    origin = np.asarray(origin, dtype=np.float64)
    nx, ny, nz = (int(s) for s in shape)
    # Slabs of about SLAB_VOXELS per kernel call, so that Ctrl-C is seen between them.
    rows = max(1, SLAB_VOXELS // max(1, ny * nz))
    values = None
    for i0 in range(0, nx, rows):
        interrupt.check()  # Ctrl-C seen by another thread (cablelife demo)
        corner = [float(origin[0] + voxel * i0), float(origin[1]), float(origin[2])]
        n = min(rows, nx - i0)
        part = _core.capsule_signed_distance(
            capsules.starts, capsules.ends, capsules.radius, corner, voxel, [n, ny, nz], band
        )
        if n == nx:
            values = part
        else:
            if values is None:
                values = np.empty((nx, ny, nz), dtype=part.dtype)
            values[i0 : i0 + n] = part
        if progress is not None:
            progress(i0 + n, nx)
    return VoxelField(values=values, origin=origin, spacing=voxel, band=band)


def union_field(
    capsules: Capsules,
    voxel: float,
    bounds: np.ndarray | None = None,
    progress: Callable[[int, int], None] | None = None,
) -> VoxelField:
    """The union's signed distance on the grid that covers ``bounds`` (default: the capsules'
    own bounding box) at ``voxel``: ``grid_for`` and ``signed_distance`` together."""
    box = capsules.bounding_box if bounds is None else np.asarray(bounds, dtype=np.float64)
    return signed_distance(capsules, *grid_for(box, voxel), voxel, progress=progress)
