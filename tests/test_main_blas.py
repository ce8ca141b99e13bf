"""The command line runs numpy's and scipy's BLAS on one thread unless the user chose
otherwise (cablelife's matrices are small; thread pools would take CPU from the clearance)."""

from __future__ import annotations

import os
import subprocess
import sys

SHOW = (
    "import atexit, os, sys\n"
    "atexit.register(lambda: print('BLAS', os.environ.get('OPENBLAS_NUM_THREADS')))\n"
    "sys.argv = ['cablelife', '--help']\n"
    "from cablelife.__main__ import main\n"
    "main()\n"
)


def blas_threads(env: dict) -> str:
    out = subprocess.run(
        [sys.executable, "-c", SHOW], env=env, capture_output=True, text=True, timeout=120
    )
    assert out.returncode == 0, out.stderr
    return out.stdout.strip().splitlines()[-1]


def test_the_command_line_sets_one_blas_thread():
    env = {k: v for k, v in os.environ.items() if k != "OPENBLAS_NUM_THREADS"}
    assert blas_threads(env) == "BLAS 1"


def test_the_users_choice_of_blas_threads_is_kept():
    env = dict(os.environ, OPENBLAS_NUM_THREADS="3")
    assert blas_threads(env) == "BLAS 3"
