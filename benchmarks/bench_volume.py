"""Motion volume benchmarks.

1. A 0.6 m cable, r = 5 mm, 400 saved steps, 2 mm voxels. The motion is kinematic (no solver
   in the loop): a sagging cable between a fixed end and an end moving on a closed 3D path,
   resampled to equal arc length (0.6 m, 60 edges). The voxel series shows the convergence of
   the volume; the pure-Python reference (reference/NOTES.md) took 24 s at 2 mm.
2. A dense dynamic result: a 1.25 m cable of 100 edges along a gentle 3D curve, 5001 saved
   steps of 1 ms, every node moving ~2 mm (sines at 10–60 Hz), r = 6 mm: 500 k capsules that
   nearly coincide step to step (as crates/volume/examples/bench_volume.rs, which also times
   the kernel before the speed-up).

    python benchmarks/bench_volume.py
"""

from __future__ import annotations

import time

import numpy as np
from cablelife.volume import motion_volume

LENGTH, RADIUS, STEPS, EDGES = 0.6, 0.005, 400, 60


def cable_motion() -> np.ndarray:
    """Node positions (STEPS, EDGES+1, 3): each step a smooth curve of length LENGTH."""
    t = np.linspace(0.0, 1.0, STEPS, endpoint=False)
    u = np.linspace(0.0, 1.0, 2001)
    out = np.empty((STEPS, EDGES + 1, 3))
    for k, tk in enumerate(t):
        end = np.array(
            [
                0.42 + 0.03 * np.sin(2 * np.pi * tk),
                0.05 * np.sin(4 * np.pi * tk),
                0.04 * np.cos(2 * np.pi * tk),
            ]
        )
        curve = u[:, None] * end
        curve[:, 1] += 0.06 * np.sin(np.pi * u) * np.cos(2 * np.pi * tk)
        # Sag chosen so the curve is LENGTH long (bisection on the amplitude).
        lo, hi = 0.0, 0.5
        for _ in range(50):
            a = 0.5 * (lo + hi)
            c = curve.copy()
            c[:, 2] -= a * np.sin(np.pi * u)
            if np.linalg.norm(np.diff(c, axis=0), axis=1).sum() < LENGTH:
                lo = a
            else:
                hi = a
        s = np.concatenate([[0], np.cumsum(np.linalg.norm(np.diff(c, axis=0), axis=1))])
        target = np.linspace(0, s[-1], EDGES + 1)
        out[k] = np.stack([np.interp(target, s, c[:, i]) for i in range(3)], axis=1)
    return out


def dynamic_motion(steps: int = 5001, edges: int = 100) -> np.ndarray:
    """Node positions (steps, edges+1, 3) of the dense dynamic case (1 ms steps)."""
    t = np.arange(steps)[:, None] * 1e-3
    u = np.linspace(0.0, 1.0, edges + 1)[None, :]
    out = np.empty((steps, edges + 1, 3))
    out[..., 0] = 1.2 * u
    out[..., 1] = 0.12 * np.sin(np.pi * u)
    out[..., 2] = 0.08 * np.sin(2 * np.pi * u) - 0.05 * u
    # (axis, frequency Hz, amplitude m, spatial wave number, phase)
    waves = [
        (0, 11, 1.0e-3, 1.0, 0.3),
        (0, 27, 0.6e-3, 2.0, 1.1),
        (0, 53, 0.3e-3, 3.0, 2.0),
        (1, 13, 1.1e-3, 1.0, 0.7),
        (1, 31, 0.5e-3, 2.5, 0.2),
        (1, 47, 0.3e-3, 4.0, 1.7),
        (2, 10, 0.9e-3, 1.5, 2.2),
        (2, 23, 0.7e-3, 2.0, 0.9),
        (2, 59, 0.3e-3, 3.5, 0.4),
    ]
    for axis, f, a, kappa, phase in waves:
        out[..., axis] += a * np.sin(2 * np.pi * f * t + phase) * np.sin(np.pi * kappa * u + phase)
    return out


def dense_dynamic() -> None:
    positions = dynamic_motion()
    radius = 0.006
    print(f"dynamic: 1.25 m, r = 6 mm, {positions.shape[0]} steps × {positions.shape[1] - 1} edges")
    for voxel, stride in ((0.004, 1), (0.002, 1), (0.004, 5), (0.002, 5)):
        t0 = time.perf_counter()
        mv = motion_volume(positions, voxel, radius=radius, steps=slice(None, None, stride))
        wall = time.perf_counter() - t0
        tm = mv.timings
        print(
            f"voxel {voxel * 1e3:g} mm, every {stride}: {mv.volume * 1e6:8.1f} cm³, "
            f"{tm['voxels'] / 1e6:5.2f} M voxels, "
            f"distance {tm['distance_s']:.2f} s + mesh {tm['mesh_s']:.2f} s = {wall:.2f} s"
        )


def main() -> None:
    positions = cable_motion()
    print(f"cable {LENGTH} m, r = {RADIUS * 1e3:g} mm, {STEPS} steps × {EDGES} edges")
    motion_volume(positions[:10], 0.004, radius=RADIUS)  # warm up the thread pool
    for voxel in (0.004, 0.002, 0.001):
        t0 = time.perf_counter()
        mv = motion_volume(positions, voxel, radius=RADIUS)
        wall = time.perf_counter() - t0
        tm = mv.timings
        print(
            f"voxel {voxel * 1e3:g} mm: {mv.volume * 1e6:8.1f} cm³, "
            f"{tm['voxels'] / 1e6:5.1f} M voxels, "
            f"distance {tm['distance_s']:.2f} s + mesh {tm['mesh_s']:.2f} s = {wall:.2f} s, "
            f"watertight {mv.mesh.is_watertight()}"
        )
    sparse = motion_volume(positions[::10], 0.002, radius=RADIUS)
    print(f"every 10th step only at 2 mm: {sparse.volume * 1e6:.1f} cm³")
    dense_dynamic()


if __name__ == "__main__":
    main()
