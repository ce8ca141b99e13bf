"""Runs the bad-input suite (tests/test_bad_input_*.py) against a checkout, surviving aborts:
each crash marks the test that was running as failed and the run goes on with the rest.

Usage (the "before" figure of the suite, against the code before the fixes):
    git archive <commit> | tar -x -C /tmp/orig
    cp python/cablelife/_core.abi3.so /tmp/orig/python/cablelife/
    cp tests/badinput.py tests/test_bad_input_*.py /tmp/orig/tests/
    python scripts/bad_input_before.py /tmp/orig "$(which python)"
Memory is limited to 8 GB per run (ulimit -v) so the old allocations fail instead of swapping.
"""

import os
import re
import subprocess
import sys

root, py = sys.argv[1], sys.argv[2]
files = [
    "tests/test_bad_input_generated.py",
    "tests/test_bad_input_scenes.py",
    "tests/test_bad_input_files.py",
    "tests/test_bad_input_more.py",
]
env = dict(os.environ, PYTHONPATH=f"{root}/python")
ids = [
    line.strip()
    for line in subprocess.run(
        [py, "-m", "pytest", "-p", "no:cacheprovider", "--collect-only", "-q", *files],
        cwd=root,
        capture_output=True,
        text=True,
        env=env,
    ).stdout.splitlines()
    if "::" in line
]
results = {}
todo = list(ids)
while todo:
    p = subprocess.run(
        [
            "bash",
            "-c",
            f"ulimit -v 8000000; exec {py} -m pytest -p no:cacheprovider -v "
            "-o console_output_style=classic " + " ".join(f"'{t}'" for t in todo),
        ],
        cwd=root,
        capture_output=True,
        text=True,
        env=env,
        timeout=1800,
    )
    for m in re.finditer(r"^(tests/\S+::\S+) (PASSED|FAILED|ERROR)", p.stdout, re.M):
        results[m.group(1)] = m.group(2)
    rest = [t for t in todo if t not in results]
    if p.returncode in (0, 1) or not rest:
        for t in rest:
            results[t] = "NOT RUN"
        break
    results[rest[0]] = f"CRASH rc={p.returncode}"
    todo = rest[1:]
bad = {t: r for t, r in results.items() if r != "PASSED"}
print(f"tests: {len(ids)}, passed: {len(ids) - len(bad)}, failed: {len(bad)}")
for t, r in sorted(bad.items()):
    print(r, t)
