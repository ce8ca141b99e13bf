"""Start-up time of the whole process a user runs (issue 14): ``import cablelife``,
``cablelife --help`` and a small static ``cablelife run`` (examples/hose-three-clips.toml, 50
segments), each the median of several fresh subprocesses; plus the modules ``import cablelife``
pulls in that take longest (``python -X importtime``).

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


def wall(cmd: list[str]) -> float:
    # as a user runs it: bytecode caches written on the first run and used after it (this
    # machine's environment sets PYTHONDONTWRITEBYTECODE, which makes every start compile)
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    env["COLUMNS"] = "100"
    t0 = time.perf_counter()
    subprocess.run(cmd, check=True, capture_output=True, env=env)
    return time.perf_counter() - t0


def slowest_imports(n: int = 8) -> list[tuple[float, str]]:
    """The ``n`` top-level packages with the largest cumulative import time."""
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    p = subprocess.run(
        [sys.executable, "-X", "importtime", "-c", "import cablelife.cli"],
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
        if not name.startswith(" ") and "." not in name.strip():
            rows[name.strip()] = max(rows.get(name.strip(), 0), int(cum) / 1e6)
    return sorted(((t, m) for m, t in rows.items()), reverse=True)[:n]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=7)
    args = ap.parse_args()
    for name, cmd in CASES.items():
        wall(cmd)  # warm the file cache
        times = [wall(cmd) for _ in range(args.repeat)]
        print(
            f"{name:40s} median {statistics.median(times):6.3f} s  "
            f"(min {min(times):.3f}, max {max(times):.3f}, n = {args.repeat})"
        )
    print("largest top-level imports of `import cablelife.cli` (cumulative, one run):")
    for t, m in slowest_imports():
        print(f"  {m:30s} {t:6.3f} s")


if __name__ == "__main__":
    main()
