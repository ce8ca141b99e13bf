"""Dask preload of the workers of a study's local cluster (``distributed.worker.preload``).

- Ctrl-C in a terminal reaches the whole process group: the study's own process stops the study
  and closes the cluster; the workers ignore SIGINT, so none dies with a KeyboardInterrupt
  traceback in the middle of a variant.
- No HTTP server: a worker starts one (metrics, health) even without a dashboard; it is
  unauthenticated, so it is stopped before the worker takes tasks.
"""

from __future__ import annotations

import signal
import threading

if threading.current_thread() is threading.main_thread():
    signal.signal(signal.SIGINT, signal.SIG_IGN)


def dask_setup(worker) -> None:
    server = getattr(worker, "http_server", None)
    if server is not None:
        server.stop()
