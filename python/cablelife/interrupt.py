"""Stopping long runs on Ctrl-C.

Python raises ``KeyboardInterrupt`` in its main thread only, while the solvers run in worker
threads with the GIL released. Each :func:`~cablelife.simulate.simulate` call therefore hands
its solver threads a :class:`cablelife._core.StopFlag`, read after every step; the thread that
catches Ctrl-C sets it. :func:`request_stop` sets every flag in use (runs in other threads, as
in ``cablelife demo``) and makes runs started afterwards stop at once; Python loops in worker
threads call :func:`check` between their steps.
"""

from __future__ import annotations

import signal
import sys
import threading
from collections.abc import Callable, Iterator
from concurrent.futures import FIRST_EXCEPTION, wait
from contextlib import contextmanager

from cablelife import _core

#: The reason a run stopped early because it was asked to (``Result.message``).
INTERRUPTED: str = _core.INTERRUPTED

#: Exit code of a command ended by Ctrl-C (128 + SIGINT), as shells report it.
EXIT_CODE = 130

#: Longest wait of the main thread before it looks for Ctrl-C again (s).
POLL_S = 0.05

_lock = threading.Lock()
_flags: set = set()
_requested = threading.Event()
_reported = False  # the command line said "interrupted" already


def request_stop() -> None:
    """Asks every running simulation (in any thread) to stop after its current step, and every
    one started later to stop at once, keeping what they computed."""
    _requested.set()
    with _lock:
        for flag in _flags:
            flag.set()


def stop_requested() -> bool:
    """Whether :func:`request_stop` was called (and not :func:`reset`)."""
    return _requested.is_set()


def reset() -> None:
    """Withdraws :func:`request_stop` for runs started from now on."""
    _requested.clear()


def check() -> None:
    """Raises ``KeyboardInterrupt`` if a stop was requested (for loops in worker threads)."""
    if _requested.is_set():
        raise KeyboardInterrupt


@contextmanager
def _ctrl_c_as_flag() -> Iterator[threading.Event]:
    """While the block runs in the main thread, Ctrl-C sets the returned event instead of
    raising ``KeyboardInterrupt`` wherever the main thread happens to be: raised inside the
    lock handling of ``concurrent.futures.wait`` it can leave a future's lock taken, and the
    worker that finishes then blocks for ever setting its result (a run that never ended after
    Ctrl-C, seen once in the test suite). Elsewhere the previous handler is in place."""
    pressed = threading.Event()
    if threading.current_thread() is not threading.main_thread():
        yield pressed
        return
    previous = signal.getsignal(signal.SIGINT)
    signal.signal(signal.SIGINT, lambda *_: pressed.set())
    try:
        yield pressed
    finally:
        signal.signal(signal.SIGINT, previous)


@contextmanager
def deferred() -> Iterator[None]:
    """Ctrl-C in the block is held until the block ends and then raised (KeyboardInterrupt):
    for third-party code that swallows it. trimesh imports its optional dependencies under
    ``except BaseException``, so a Ctrl-C while a mesh was being read was lost and the run went
    on to its end (exit 0). Main thread only; elsewhere the block runs as it is."""
    with _ctrl_c_as_flag() as pressed:
        yield
    if pressed.is_set():
        raise KeyboardInterrupt


def wait_stopping(futures, stop: Callable[[], None], stop_on_error: bool = True) -> bool:
    """Waits for every future of a thread pool; on Ctrl-C (and, with ``stop_on_error``, when
    one of them fails) calls ``stop()`` once and goes on waiting. Returns whether Ctrl-C came.

    It waits in slices of :data:`POLL_S`: Python runs signal handlers in the main thread only,
    and a signal the kernel delivers to a solver thread does not wake a blocked wait. Ctrl-C
    sets a flag read between the slices (``_ctrl_c_as_flag``)."""
    pending = set(futures)
    ctrl_c = stopped = False
    with _ctrl_c_as_flag() as pressed:
        while pending:
            done: set = set()
            try:
                done, pending = wait(pending, timeout=POLL_S, return_when=FIRST_EXCEPTION)
            except KeyboardInterrupt:  # not the main thread: raised as before
                pressed.set()
            ctrl_c = ctrl_c or pressed.is_set()
            failed = stop_on_error and any(f.exception() for f in done)
            if not stopped and (ctrl_c or failed):
                stopped = True
                stop()
    return ctrl_c


@contextmanager
def stop_flag() -> Iterator[_core.StopFlag]:
    """A fresh stop flag, set by :func:`request_stop` while the block runs."""
    flag = _core.StopFlag()
    with _lock:
        _flags.add(flag)
        if _requested.is_set():
            flag.set()
    try:
        yield flag
    finally:
        with _lock:
            _flags.discard(flag)


def interrupted(detail: str = ""):
    """For commands: Ctrl-C arrived. Stops runs still going in other threads, says so on
    stderr (with ``detail``: what was kept), and returns the ``typer.Exit`` (code 130) to raise."""
    import typer
    from rich.console import Console
    from rich.markup import escape

    global _reported
    request_stop()
    if not _reported:
        text = "interrupted" + (f": {detail}" if detail else "")
        Console(stderr=True).print(f"[yellow]{escape(text)}[/]", highlight=False, soft_wrap=True)
        _reported = True
    return typer.Exit(EXIT_CODE)


def report_exit(code) -> None:
    """For the command line's entry point: the process ends with ``code``; after Ctrl-C (130)
    stop runs in other threads (the interpreter waits for them) and say so once."""
    global _reported
    if code != EXIT_CODE:
        return
    request_stop()
    if not _reported:
        _reported = True
        sys.stderr.write("interrupted\n")
