"""The whole ``cablelife run`` with a 1 M-triangle mesh, as a user runs it (issue 15): is
reading the STL (trimesh) and building the hierarchy the bottleneck, or the clearance itself?

The scene: the hose of examples/surroundings/hose-near-engine.toml (100 segments), dynamic,
5 s at 1 ms (5001 saved steps), next to a closed torus of 1 000 000 triangles (binary STL in
millimetres, ~1.1 mm edges, 1–10 cm from the hose) moving with the engine. Printed: the wall
time of the whole process (``cablelife run scene.toml -o result.h5 --quiet``, fresh
subprocess), and the split of one in-process run: import, scene, mesh file read and checks
(trimesh), hierarchy build, simulation, display decimation, clearance, result file; wall and
CPU time of all threads (on a shared machine the CPU time is the work itself).

    RAYON_NUM_THREADS=2 python benchmarks/bench_clearance_run.py [--repeat 3] [--duration 5]
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
BIN = Path(sys.executable).parent
CLI = (
    [str(BIN / "cablelife")]
    if (BIN / "cablelife").exists()
    else [sys.executable, "-m", "cablelife"]
)

SCENE = """
[simulation]
mode = "dynamic"
gravity = [0.0, 0.0, -9.81]
duration = {duration}
time_step = 0.001

[clearance]
min_clearance = 0.02

[[bodies]]
name = "engine"
origin = [0.6, 0.2, 0.0]
geometry = [ {{ mesh = "torus.stl", scale = 0.001, name = "block" }} ]

[[bodies.motion]]
channel = "z"
frame = "global"
signal = {{ type = "sine", amplitude = 0.005, frequency = 5.0, fade_in = 0.1 }}

[[cables]]
name = "hose"
length = 1.0
segments = 100
section = {{ shape = "tube", outer_radius = 0.008, inner_radius = 0.005 }}
material = {{ youngs_modulus = 2.0e7, poisson_ratio = 0.45, density = 1200.0 }}

[[cables.clips]]
name = "body-clip"
s = 0.01
position = [0.0, 0.0, 0.0]
direction = [1.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
type = "fixed"

[[cables.clips]]
name = "engine-bracket"
s = 1.0
body = "engine"
position = [0.75, 0.25, 0.0]
direction = [1.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
type = "fixed"
"""

# one in-process run, timed stage by stage by wrapping the functions simulate() calls
SPLIT = r"""
import json, sys, time
clock = lambda: (time.perf_counter(), time.process_time())
w0, c0 = clock()
import cablelife.simulate
from cablelife.scene import load_scene
sim = sys.modules["cablelife.simulate"]
w, c = clock()
times = {"import cablelife": [w - w0, c - c0]}

def add(name, w0, c0):
    w, c = clock()
    old = times.get(name, [0.0, 0.0])
    times[name] = [old[0] + w - w0, old[1] + c - c0]

def timed(name, f):
    def g(*a, **k):
        w0, c0 = clock()
        try:
            return f(*a, **k)
        finally:
            add(name, w0, c0)
    return g

import cablelife.surroundings.meshes as meshes
import cablelife.surroundings.clearance as clr
from cablelife.surroundings.build import Surroundings
w0, c0 = clock()
import trimesh  # noqa: F401  (imported by the mesh reader on first use)
add("import trimesh", w0, c0)
meshes.load_mesh = timed("mesh read + checks (trimesh)", meshes.load_mesh)
sim.load_surroundings = timed("surroundings total", sim.load_surroundings)
Surroundings.display_meshes = timed("display decimation", Surroundings.display_meshes)
clr.cable_clearance = timed("clearance", clr.cable_clearance)
w0, c0 = clock()
scene = load_scene(sys.argv[1])
add("scene", w0, c0)
w0, c0 = clock()
result = sim.simulate(scene)
add("simulate total", w0, c0)
w0, c0 = clock()
result.save(sys.argv[2])
add("result file", w0, c0)
total = times.pop("simulate total")
env = times.pop("surroundings total")
read = times["mesh read + checks (trimesh)"]
times["hierarchy build"] = [env[k] - read[k] for k in (0, 1)]
times["simulation"] = [
    total[k] - env[k] - times["display decimation"][k] - times["clearance"][k] for k in (0, 1)
]
c = next(iter(result.cables.values())).clearance
times["clearance min, max (mm)"] = [c.min() * 1e3, c.max() * 1e3]
print(json.dumps(times))
"""


def torus_stl(path: Path, triangles: int) -> int:
    """A closed torus (major radius 200 mm, minor 80 mm) of about ``triangles`` triangles."""
    import trimesh

    minor = int(round((triangles / 2 / 2.5) ** 0.5))
    mesh = trimesh.creation.torus(
        major_radius=200.0,
        minor_radius=80.0,
        major_sections=int(2.5 * minor),
        minor_sections=minor,
    )
    # centre below the hose's middle, axis z: the sagging hose passes above its ring
    mesh.apply_translation([375.0, 125.0, -290.0])
    mesh.export(path)
    return len(mesh.faces)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--duration", type=float, default=5.0)
    ap.add_argument("--triangles", type=int, default=1_000_000)
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        d = Path(tmp)
        n = torus_stl(d / "torus.stl", args.triangles)
        scene = d / "scene.toml"
        scene.write_text(SCENE.format(duration=args.duration))
        threads = os.environ.get("RAYON_NUM_THREADS", "(all cores)")
        print(
            f"mesh {n:,} triangles ({(d / 'torus.stl').stat().st_size / 1e6:.0f} MB binary STL);"
            f" hose 100 segments, dynamic {args.duration:g} s at 1 ms; RAYON_NUM_THREADS={threads}"
        )
        walls, cpus, splits = [], [], []
        for _ in range(args.repeat):
            t0, r0 = time.perf_counter(), resource.getrusage(resource.RUSAGE_CHILDREN)
            subprocess.run(
                [*CLI, "run", str(scene), "-o", str(d / "run.h5"), "--quiet"],
                check=True,
                stdout=subprocess.DEVNULL,
            )
            walls.append(time.perf_counter() - t0)
            r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
            cpus.append(r1.ru_utime + r1.ru_stime - r0.ru_utime - r0.ru_stime)
            out = subprocess.run(
                [sys.executable, "-c", SPLIT, str(scene), str(d / "split.h5")],
                capture_output=True,
                text=True,
            )
            if out.returncode:
                sys.exit(f"the in-process run failed:\n{out.stderr}")
            splits.append(json.loads(out.stdout.strip().splitlines()[-1]))
        med = statistics.median
        print(
            f"whole `cablelife run`             wall {med(walls):7.2f} s   CPU {med(cpus):7.2f} s"
        )
        print("split of one in-process run (medians; CPU = all threads):")
        for key in splits[0]:
            w, c = (med(s[key][k] for s in splits) for k in (0, 1))
            if "(mm)" in key:
                print(f"  {key:32s} {w:7.2f} … {c:.2f}")
            else:
                print(f"  {key:32s} wall {w:7.2f} s   CPU {c:7.2f} s")
        print(f"load average {os.getloadavg()[0]:.1f} (2 cores)")


if __name__ == "__main__":
    main()
