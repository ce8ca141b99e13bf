"""Driving the workbench as a user would, for the tests and benchmarks/bench_workbench.py: the
``cablelife workbench`` command in its own process, its page in headless Chromium (the
DevTools client of :mod:`cablelife.report.browser`), the page's test hook
``window.cablelifeWorkbench`` called over the DevTools protocol."""

from __future__ import annotations

import asyncio
import json
import os
import re
import signal
import subprocess
import sys
import threading
import time
from contextlib import contextmanager
from pathlib import Path

URL = re.compile(r"http://127\.0\.0\.1:\d+/")


@contextmanager
def workbench_process(scene: str | Path, *args: str, timeout: float = 120.0):
    """Runs ``cablelife workbench SCENE --no-browser *args``; yields (process, URL). Stopped
    with Ctrl-C (SIGINT) at the end of the block."""
    env = dict(os.environ, PYTHONUNBUFFERED="1", COLUMNS="200")
    proc = subprocess.Popen(
        [sys.executable, "-m", "cablelife", "workbench", str(scene), "--no-browser", *args],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=env,
    )
    lines: list[str] = []
    found = threading.Event()

    def read():
        for line in proc.stdout:
            lines.append(line)
            if URL.search(line):
                found.set()

    threading.Thread(target=read, daemon=True).start()
    try:
        deadline = time.monotonic() + timeout
        while not found.wait(0.1):
            if proc.poll() is not None or time.monotonic() > deadline:
                proc.kill()
                raise RuntimeError(
                    "the workbench did not start: " + "".join(lines) + proc.stderr.read()
                )
        url = URL.search("".join(lines)).group(0)
        yield proc, url
    finally:
        if proc.poll() is None:
            proc.send_signal(signal.SIGINT)
            try:
                proc.wait(10)
            except subprocess.TimeoutExpired:
                proc.kill()
                proc.wait()


def stop_time(proc: subprocess.Popen) -> tuple[float, int]:
    """Sends Ctrl-C (SIGINT); returns (seconds until the process ended, its exit code)."""
    t0 = time.perf_counter()
    proc.send_signal(signal.SIGINT)
    code = proc.wait(30)
    return time.perf_counter() - t0, code


class Page:
    """The workbench page in Chromium, through its DevTools session ``cdp``."""

    def __init__(self, cdp):
        self.cdp = cdp

    async def open(self, url: str, width: int = 1200, height: int = 800, timeout: float = 60):
        await self.cdp.call("Emulation.setDeviceMetricsOverride", width=width, height=height,
                            deviceScaleFactor=1, mobile=False)  # fmt: skip
        await self.cdp.call("Page.navigate", url=url)
        t0 = time.monotonic()
        while True:
            ready = await self.cdp.evaluate("document.body && document.body.dataset.ready")
            if ready == "yes":
                return
            if ready == "failed" or time.monotonic() - t0 > timeout:
                text = await self.cdp.evaluate("document.getElementById('message').textContent")
                raise RuntimeError(f"the workbench page did not load: {text}")
            await asyncio.sleep(0.05)

    async def call(self, expr: str):
        """Awaits a hook call, e.g. ``moveClip("hose", "end", [0, 0, 0])``; returns its value,
        or {"error": message} when its promise is rejected."""
        js = (
            "Promise.resolve().then(() => window.cablelifeWorkbench." + expr + ")"
            ".then(v => JSON.stringify({value: v === undefined ? null : v}),"
            " e => JSON.stringify({error: String(e && e.message || e)}))"
        )
        out = json.loads(await self.cdp.evaluate(js, await_promise=True, strict=True))
        return out if "error" in out else out["value"]

    async def text(self, element_id: str) -> str:
        return await self.cdp.evaluate(f"document.getElementById({element_id!r}).textContent")

    async def screenshot(self, path: Path) -> Path:
        import base64

        await asyncio.sleep(0.3)
        png = await self.cdp.call("Page.captureScreenshot", format="png")
        path = Path(path)
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_bytes(base64.b64decode(png["data"]))
        return path


def run_page(url: str, script, width: int = 1200, height: int = 800):
    """Opens ``url`` in a fresh headless Chromium and runs ``await script(page)``; returns its
    value."""
    from cablelife.report.browser import chromium, connect

    async def main(port):
        cdp = await connect(port)
        try:
            page = Page(cdp)
            await page.open(url, width, height)
            return await script(page)
        finally:
            cdp.ws.close()

    with chromium(width, height) as browser:
        return asyncio.run(main(browser.port))
