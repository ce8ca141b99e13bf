"""``python -m cablelife`` and the ``cablelife`` script: the command line.

Ctrl-C ends every command with exit code 130 and no traceback, also while the modules are
still being imported (which takes a moment: numpy, scipy, h5py, pydantic, rich, typer)."""

import os
import sys

EXIT_INTERRUPTED = 130


def _exit_interrupted() -> None:
    """Ends the process with 130 at once. Not ``sys.exit``: CPython ends a process by SIGINT
    instead when a KeyboardInterrupt passed through an extension module's import, even if it
    was caught; the command has already stopped its threads and closed its files and clusters."""
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except (OSError, ValueError):
            pass
    os._exit(EXIT_INTERRUPTED)


def _quiet_unraisable(unraisable) -> None:
    """Ctrl-C while the interpreter shuts down lands in callbacks Python can only report
    ("Exception ignored in: <function WeakValueDictionary…>" with a traceback, seen once with
    ``cablelife demo``): dropped; every other unraisable exception is reported as before."""
    if issubclass(unraisable.exc_type, KeyboardInterrupt):
        return
    sys.__unraisablehook__(unraisable)


def single_threaded_blas() -> None:
    """One BLAS thread unless the user chose otherwise, set before numpy loads. cablelife's
    matrices are small (the solvers are Rust); numpy's and scipy's OpenBLAS pools would start a
    thread per core each at import and spin after their calls, taking CPU from the clearance's
    threads on a small machine (benchmarks/bench_clearance_run.py: import 0.25 → 0.16 s CPU,
    hierarchy build 0.74 → 0.63 s CPU)."""
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")


def main() -> None:
    single_threaded_blas()
    sys.unraisablehook = _quiet_unraisable
    try:
        from cablelife.cli import app
        from cablelife.interrupt import report_exit
    except KeyboardInterrupt:
        sys.stderr.write("interrupted\n")
        _exit_interrupted()
    try:
        app(prog_name="cablelife")
    except SystemExit as exit_:
        report_exit(exit_.code)
        if exit_.code == EXIT_INTERRUPTED:
            _exit_interrupted()
        raise
    except KeyboardInterrupt:  # outside the command (typer turns it into exit code 130 inside)
        report_exit(EXIT_INTERRUPTED)
        _exit_interrupted()


if __name__ == "__main__":
    main()
