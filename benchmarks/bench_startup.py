"""Start-up time of the whole process a user runs (issue 14): ``import cablelife``,
``cablelife --help`` and a small static ``cablelife run`` (examples/hose-three-clips.toml, 50
segments), each the median of several fresh subprocesses: wall time and the process's CPU time
(user + system, from ``os.wait4``), with the load average. On a shared machine the wall time
grows with the load (the process gets a share of a core) while the CPU time does not: on an
idle machine the wall time is the CPU time plus a few ms. Plus the modules ``import
cablelife.cli`` pulls in that take longest (``python -X importtime``).

    python benchmarks/bench_startup.py [--repeat 7]

Before/after figures of a change: run it with ``PYTHONPATH=<old checkout>/python`` (and the
built extension copied there) for the old code.
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
BIN = Path(sys.executable).parent
CLI = (
    [str(BIN / "cablelife")]
    if (BIN / "cablelife").exists()
    else [sys.executable, "-m", "cablelife"]
)

CASES = {
    "import cablelife": [sys.executable, "-c", "import cablelife"],
    "cablelife --help": [*CLI, "--help"],
    "cablelife run (static, 50 segments)": [
        *CLI,
        "run",
        str(ROOT / "examples/hose-three-clips.toml"),
        "--quiet",
    ],
}


def wall(cmd: list[str]) -> tuple[float, float]:
    """(wall, CPU) seconds of one fresh process running ``cmd``."""
    # as a user runs it: bytecode caches written on the first run and used after it (this
    # machine's environment sets PYTHONDONTWRITEBYTECODE, which makes every start compile)
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    env["COLUMNS"] = "100"
    t0 = time.perf_counter()
    p = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, env=env)
    err = p.stderr.read()
    _, status, usage = os.wait4(p.pid, 0)
    seconds = time.perf_counter() - t0
    p.returncode = os.waitstatus_to_exitcode(status)
    if p.returncode:
        raise RuntimeError(f"{cmd} failed ({p.returncode}): {err.decode()[-500:]}")
    return seconds, usage.ru_utime + usage.ru_stime


def slowest_imports(n: int = 8) -> list[tuple[float, str]]:
    """The ``n`` top-level packages with the largest cumulative import time in the small
    ``cablelife run``."""
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    run = CASES["cablelife run (static, 50 segments)"][len(CLI) :]
    p = subprocess.run(
        [sys.executable, "-X", "importtime", "-m", "cablelife", *run],
        env=env,
        capture_output=True,
        text=True,
        check=True,
    )
    rows = {}
    for line in p.stderr.splitlines():
        if not line.startswith("import time:") or "cumulative" in line:
            continue
        _, cum, name = (x.strip() for x in line[len("import time:") :].split("|"))
        if not name.startswith(" "):
            rows[name.strip()] = max(rows.get(name.strip(), 0), int(cum) / 1e6)
    return sorted(((t, m) for m, t in rows.items()), reverse=True)[:n]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=7)
    args = ap.parse_args()
    med = statistics.median
    for name, cmd in CASES.items():
        wall(cmd)  # warm the file cache
        load = os.getloadavg()[0]
        walls, cpus = zip(*(wall(cmd) for _ in range(args.repeat)), strict=True)
        print(
            f"{name:37s} wall median {med(walls):6.3f} s (min {min(walls):.3f}), CPU median "
            f"{med(cpus):6.3f} s (min {min(cpus):.3f}), n = {args.repeat}, load {load:.1f}"
        )
    print("largest top-level imports of the small `cablelife run` (cumulative, one run):")
    for t, m in slowest_imports():
        print(f"  {m:30s} {t:6.3f} s")


if __name__ == "__main__":
    main()
