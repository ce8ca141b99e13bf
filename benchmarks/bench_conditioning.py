"""Estimated condition of the Jacobi-scaled tangent stiffness (issue 13): normal cables against
the ill-conditioned examples (extreme GA/EA, tiny EI or rotary inertia, extreme segment
ratios), with the time of the estimate. Run: python benchmarks/bench_conditioning.py
"""

from __future__ import annotations

import copy
import sys
import time
import warnings
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent))
from bench_dynamic import scene as dynamic_scene  # noqa: E402
from cablelife.scene import scene_from_dict  # noqa: E402
from cablelife.simulate import build_cable  # noqa: E402

HOSE = {
    "simulation": {"mode": "static", "gravity": [0.0, 0.0, -9.81]},
    "cables": [
        {
            "name": "hose",
            "length": 1.0,
            "segments": 40,
            "stiffness": {
                "EA": 3927.0,
                "GA": 1300.0,
                "EI": 0.0245,
                "GJ": 0.017,
                "mass_per_length": 0.118,
                "radius": 0.005,
            },
            "clips": [
                {"name": "a", "s": 0.0, "position": [0, 0, 0], "direction": [1, 0, 0]},
                {"name": "b", "s": 1.0, "position": [0.8, 0.2, 0], "direction": [1, 0, 0]},
            ],
        }
    ],
}


def hose(segments=40, loads=None, **stiffness) -> dict:
    d = copy.deepcopy(HOSE)
    c = d["cables"][0]
    c["segments"] = segments
    c["stiffness"].update(stiffness)
    if loads:
        c["loads"] = loads
    return d


def wire(segments: int) -> dict:
    d = copy.deepcopy(HOSE)
    c = d["cables"][0]
    del c["stiffness"]
    c["segments"] = segments
    c["section"] = {"shape": "circle", "radius": 0.001}
    c["material"] = {"youngs_modulus": 2e11, "poisson_ratio": 0.3, "density": 7800.0}
    return d


CASES = [
    ("bench_dynamic cable", dynamic_scene(100, 1.0)),
    ("hose", hose()),
    ("hose", hose(200)),
    ("hose", hose(1000)),
    ("steel wire r = 1 mm", wire(400)),
    ("hose, GA = 100·EA", hose(GA=100 * 3927.0)),
    ("hose, GA = 1000·EA", hose(GA=1000 * 3927.0)),
    ("hose, GA = 1e4·EA", hose(GA=1e4 * 3927.0)),
    ("hose, GA = 100·EA", hose(1000, GA=100 * 3927.0)),
    ("hose, EI = GJ = 1e-9", hose(EI=1e-9, GJ=1e-9)),
    ("hose, rotary inertia 1e-12", hose(rotary_inertia=1e-12)),
    ("hose, load 1e-6 m from a clip", hose(loads=[{"s": 1e-6, "force": [0, 0, -0.01]}])),
]


def main() -> None:
    print(f"{'model':34s} {'N':>5s} {'condition':>10s} {'estimate':>9s}")
    for label, d in CASES:
        sc = scene_from_dict(d)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            core = build_cable(sc, sc.cables[0])
        times = []
        for _ in range(5):
            t0 = time.perf_counter()
            cond = core.condition()[0]
            times.append(time.perf_counter() - t0)
        n = core.arc_length.size - 1
        print(f"{label:34s} {n:5d} {cond:10.2e} {sorted(times)[2] * 1e3:7.1f} ms")


if __name__ == "__main__":
    main()
