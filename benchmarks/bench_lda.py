"""LDA benchmark: 2000 comparison-stress series × 5000 samples, stress recovery to damage map.

A synthetic but realistic dynamic result: a 1 m cable (r = 4 mm, ν = 0.3) with 41 edges
(42 nodes = cross sections), 5 s at a 1 ms output step. Its section loads are modal responses:
four bending modes (12, 31, 58, 95 Hz, resonant second-order filters of white noise, random
shapes per direction) plus a quasistatic 1.5 Hz swing; torsion, tension and the shear forces
(dM/ds) follow. Counting every node at 8 surface points × 6 planes (30°) gives
42 × 48 = 2016 series; the default resolution (16 points × 18 planes) gives 12096.

With ``--demo`` (the default) the result is instead a real dynamic simulation: variant A of the
application example (examples/clip-variants: a 1.25 m harness, 100 segments, ISO 16750-3 engine
vibration, 5 s at 1 ms, 5001 saved steps), 42 of its 101 cross sections (evenly spaced) so that
8 points × 6 planes again give 2016 series; ``--synthetic`` uses the modal model above.

Timed: the whole pipeline (``cablelife.lda.analyse``: loads → stresses → planes → rainflow →
Miner → damage map) on 1 and 2 threads, and counting + Miner alone on the materialised series,
side by side with the PyPI peers ``rainflow``, ``fatpack`` and ``pylife`` doing the same
counting (ASTM, residue as half cycles) and Miner sum (k = 5), with the agreement of the damage.

    python benchmarks/bench_lda.py [--synthetic] [--peer-series N] [--skip-peers]
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np
from cablelife.lda import analyse, damage, plane_angles, plane_weights, surface_angles
from cablelife.lda.stations import section_loads
from cablelife.lda.stress import CircularSection
from cablelife.lda.wohler import pseudo_damage_curve
from cablelife.results import CableResult, Result
from cablelife.simulate import simulate

RADIUS, NU, EDGES, STEPS, DT = 0.004, 0.3, 41, 5000, 1e-3
K = 5.0


def resonant_noise(rng, f0: float, zeta: float, n: int, dt: float) -> np.ndarray:
    """White noise through a second-order resonance at f0 (frequency domain), unit RMS."""
    f = np.fft.rfftfreq(n, dt)
    h = 1.0 / (1 - (f / f0) ** 2 + 2j * zeta * f / f0)
    x = np.fft.irfft(np.fft.rfft(rng.normal(size=n)) * h, n)
    return x / x.std()


def synthetic_result(seed: int = 1) -> Result:
    rng = np.random.default_rng(seed)
    s = np.linspace(0.0, 1.0, EDGES + 1)
    t = np.arange(STEPS) * DT
    inertia = math.pi * RADIUS**4 / 4
    m_scale = 3e6 * inertia / RADIUS  # moment of a 3 MPa bending stress
    moments = np.zeros((STEPS, EDGES + 1, 3))
    for j, (f0, amp) in enumerate([(12.0, 1.0), (31.0, 0.6), (58.0, 0.35), (95.0, 0.2)]):
        for d in (0, 1):
            shape = np.sin((j + 1) * np.pi * s + rng.uniform(0, np.pi))
            q = resonant_noise(rng, f0, 0.04, STEPS, DT)
            moments[:, :, d] += amp * m_scale * q[:, None] * shape[None, :]
    swing = np.sin(2 * np.pi * 1.5 * t)
    moments[:, :, 0] += 0.8 * m_scale * swing[:, None] * np.cos(np.pi * s)[None, :]
    moments[:, :, 2] = (
        0.3 * m_scale * resonant_noise(rng, 31.0, 0.05, STEPS, DT)[:, None] * (1 - s)[None, :]
    )
    forces = np.zeros((STEPS, EDGES, 3))
    ds = np.diff(s)
    # shear forces from moment equilibrium m' + d3 × n = 0: F1 = M2', F2 = −M1'
    forces[:, :, 0] = np.diff(moments[:, :, 1], axis=1) / ds
    forces[:, :, 1] = -np.diff(moments[:, :, 0], axis=1) / ds
    forces[:, :, 2] = 20.0 + 5.0 * resonant_noise(rng, 12.0, 0.1, STEPS, DT)[:, None]
    quats = np.zeros((STEPS, EDGES, 4))
    quats[..., 0] = 1.0
    cable = CableResult(
        name="cable",
        time=t,
        arc_length=s,
        positions=np.zeros((STEPS, EDGES + 1, 3)),
        quaternions=quats,
        forces=forces,
        moments=moments,
        section={"shape": "circle", "outer_radius": RADIUS, "poisson_ratio": NU},
    )
    return Result(mode="dynamic", cables={"cable": cable})


def timed(fn, repeat: int = 3):
    best, out = math.inf, None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t0)
    return best, out


def demo_result() -> Result:
    """Variant A of the application example, simulated dynamically (5 s at 1 ms)."""
    from cablelife.demo import demo_runs

    variant = demo_runs(quasistatic=False)[0]
    t0 = time.perf_counter()
    result = simulate(variant.validated())
    print(f"simulated {variant.name} of examples/clip-variants in {time.perf_counter() - t0:.2f} s")
    return result


def series_matrix(result: Result, n_points: int, step_deg: float, sections) -> np.ndarray:
    """Materialise all comparison-stress series (n_series, T): one matrix product per section."""
    sec = CircularSection.from_attrs(result.cable.section)
    w = plane_weights(sec, surface_angles(n_points), plane_angles(step_deg))
    _, _, loads = section_loads(result.cable, 1, sections)
    return np.ascontiguousarray(np.concatenate([w @ ld.T for ld in loads]))


def peer_rainflow(x: np.ndarray, alpha: float) -> np.ndarray:
    import rainflow

    return np.array(
        [sum(n * r**K for r, _, n, _, _ in rainflow.extract_cycles(row)) / alpha for row in x]
    )


def peer_fatpack(x: np.ndarray, alpha: float) -> np.ndarray:
    import fatpack

    out = np.empty(len(x))
    for i, row in enumerate(x):
        # fatpack classifies the signal into k levels; 2^16 levels make the quantisation
        # error of the ranges ~1e-5 of the signal range
        rev, _ = fatpack.find_reversals(row, k=2**16)
        cycles, residue = fatpack.find_rainflow_cycles(rev)
        closed = np.abs(cycles[:, 1] - cycles[:, 0]) if len(cycles) else np.zeros(0)
        out[i] = (np.sum(closed**K) + 0.5 * np.sum(np.abs(np.diff(residue)) ** K)) / alpha
    return out


def peer_pylife(x: np.ndarray, alpha: float) -> np.ndarray:
    from pylife.stress.rainflow import FourPointDetector, LoopValueRecorder

    out = np.empty(len(x))
    for i, row in enumerate(x):
        det = FourPointDetector(recorder=LoopValueRecorder()).process(row, flush=True)
        rec = det.recorder
        closed = np.abs(rec.values_to - rec.values_from)
        out[i] = (np.sum(closed**K) + 0.5 * np.sum(np.abs(np.diff(det.residuals)) ** K)) / alpha
    return out


PEERS = {"rainflow": peer_rainflow, "fatpack": peer_fatpack, "pylife": peer_pylife}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--peer-series", type=int, default=None, help="series per peer [all]")
    ap.add_argument("--skip-peers", action="store_true")
    ap.add_argument("--synthetic", action="store_true", help="synthetic modal loads, no solver")
    args = ap.parse_args()

    result = synthetic_result() if args.synthetic else demo_result()
    curve = pseudo_damage_curve(K)
    n_nodes = result.cable.arc_length.size
    sections = np.unique(np.linspace(0, n_nodes - 1, EDGES + 1).round().astype(int))
    n_sec = sections.size
    steps = result.cable.n_steps
    print(f"{n_sec} of {n_nodes} cross sections × {steps} steps (dt = {DT * 1e3:g} ms)")

    print("\n== whole pipeline (loads → stresses → planes → rainflow → Miner → damage map)")
    for label, pts, step in [
        ("8 points × 6 planes (30°)", 8, 30.0),
        ("16 points × 18 planes (10°, default)", 16, 10.0),
    ]:
        n_series = n_sec * pts * int(round(180 / step))
        for threads in (1, 2):
            t, res = timed(
                lambda pts=pts, step=step, threads=threads: analyse(
                    result, n_points=pts, plane_step_deg=step, threads=threads, sections=sections
                )
            )
            print(
                f"{label:38s} {n_series:6d} series  {threads} thread(s): {t:7.3f} s"
                f"   max pseudo-damage {res.max_damage:.4g}"
            )
        f_max = next(iter(res.cables.values())).sampling
        print(
            f"   sampling check: f_max ≈ {f_max.f_max:.0f} Hz, "
            f"{f_max.samples_per_period:.0f} samples per period"
        )

    print("\n== counting + Miner on materialised series (8 points × 6 planes)")
    t_mat, x = timed(lambda: series_matrix(result, 8, 30.0, sections))
    print(f"series matrix {x.shape[0]} × {x.shape[1]} (one matmul per section): {t_mat:.3f} s")
    ours = {}
    for threads in (1, 2):
        t, ours[threads] = timed(lambda threads=threads: damage(x, curve, threads=threads))
        print(f"cablelife (Rust, rayon)   {threads} thread(s): {t:8.3f} s")
    d_ours = ours[1]
    assert np.array_equal(ours[1], ours[2])
    if args.skip_peers:
        return
    run_peers(x, d_ours, curve.alpha, args.peer_series)

    print("\n== worst case for counting: white-noise series (2/3 of the samples are reversals)")
    w = np.random.default_rng(2).normal(size=x.shape) * 1e6
    for threads in (1, 2):
        t, d_w = timed(lambda threads=threads: damage(w, curve, threads=threads))
        print(f"cablelife (Rust, rayon)   {threads} thread(s): {t:8.3f} s")
    run_peers(w, d_w, curve.alpha, args.peer_series)


def run_peers(x: np.ndarray, d_ours: np.ndarray, alpha: float, peer_series: int | None) -> None:
    # Constant or monotone series (held sections inside clips, the free end) have no closed
    # cycles and fatpack cannot take them (no reversal): compare on the others.
    slope = np.sign(np.diff(x, axis=1))
    reversals = (slope[:, 1:] * slope[:, :-1] < 0).sum(axis=1)
    live = reversals >= 2
    if not live.all():
        print(f"  ({(~live).sum()} constant or monotone series left out of the comparison)")
    x, d_ours = x[live], d_ours[live]
    n_peer = x.shape[0] if peer_series is None else min(peer_series, x.shape[0])
    print(f"peers on {n_peer} series (1 thread; time scaled to {x.shape[0]} series):")
    for name, fn in PEERS.items():
        try:
            __import__(name)
        except ImportError:
            print(f"  {name:10s} not installed: skipped (pip install {name})")
            continue
        t0 = time.perf_counter()
        d = fn(x[:n_peer], alpha)
        t = (time.perf_counter() - t0) * x.shape[0] / n_peer
        rel = np.abs(d - d_ours[:n_peer]) / d_ours[:n_peer]
        print(
            f"  {name:10s} {t:8.2f} s   max |ΔD|/D = {rel.max():.1e}, "
            f"max D ratio = {d.max() / d_ours[:n_peer].max():.6f}"
        )


if __name__ == "__main__":
    main()
