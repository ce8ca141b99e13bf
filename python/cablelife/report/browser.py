"""A report as a person sees it: the page opened in headless Chromium (Debian's ``chromium``),
driven over the DevTools protocol with tornado's websocket client (tornado comes with
dask.distributed): time until every figure rendered (the page's own ``data-render-ms``),
figures rendered, script errors, overlapping text boxes, screenshots. Used by the report test
and ``benchmarks/bench_report.py``."""

from __future__ import annotations

import asyncio
import base64
import json
import os
import shutil
import socket
import subprocess
import tempfile
import time
import urllib.request
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import NamedTuple

BROWSERS = ("chromium", "chromium-browser", "google-chrome")
# Software WebGL (SwiftShader) so plotly's 3D scenes draw without a GPU; root needs no sandbox.
FLAGS = [
    "--headless",
    "--no-sandbox",
    "--use-angle=swiftshader",
    "--enable-unsafe-swiftshader",
    "--hide-scrollbars",
    "--no-first-run",
    "--disable-gpu-sandbox",
]

# The visible text boxes of every rendered plotly figure (SVG text), checked two ways:
# ``overlaps``, pairs whose rectangles overlap by more than 1 px in both directions; ``clipped``,
# text drawn (partly) outside its figure's box — cut off where the figure's margins are too
# small for its tick labels, titles or slider (a legend too long for the figure scrolls: not
# counted).
TEXT_JS = r"""
(function(){
 var overlaps=[],clipped=[];
 document.querySelectorAll('.js-plotly-plot').forEach(function(fig){
  var boxes=[],box=fig.getBoundingClientRect();
  fig.querySelectorAll('svg text').forEach(function(t){
   if(!t.textContent.trim())return;
   var s=getComputedStyle(t);
   if(s.display==='none'||s.visibility==='hidden'||+s.opacity===0||+s.fillOpacity===0)return;
   var p=t.parentElement,hidden=false;
   while(p&&p!==fig){var ps=getComputedStyle(p);
    if(ps.display==='none'||+ps.opacity===0){hidden=true;break}p=p.parentElement}
   if(hidden)return;
   var r=t.getBoundingClientRect();
   if(r.width<1||r.height<1)return;
   boxes.push({t:t.textContent.trim(),r:r,legend:!!t.closest('g.legend')});});
  for(var i=0;i<boxes.length;i++){
   var a=boxes[i].r;
   if(!boxes[i].legend&&(a.left<box.left-1||a.right>box.right+1||a.top<box.top-1||
      a.bottom>box.bottom+1))clipped.push({figure:fig.id,text:boxes[i].t});
   for(var j=i+1;j<boxes.length;j++){
    var b=boxes[j].r;
    var w=Math.min(a.right,b.right)-Math.max(a.left,b.left);
    var h=Math.min(a.bottom,b.bottom)-Math.max(a.top,b.top);
    if(w>1&&h>1)overlaps.push({figure:fig.id,a:boxes[i].t,b:boxes[j].t});}}
 });
 return JSON.stringify({overlaps:overlaps,clipped:clipped});
})()
"""


def find_browser() -> str | None:
    return next((b for b in map(shutil.which, BROWSERS) if b), None)


@dataclass
class PageCheck:
    """What the browser saw."""

    load_s: float  # first screen drawn (data-render-ms) + every other figure's drawing time
    wall_s: float  # navigate command → the page reported its first screen drawn
    expected: int
    rendered: int
    errors: list[str]
    overlaps: list[dict] = field(default_factory=list)
    clipped: list[dict] = field(default_factory=list)  # text outside its figure's box
    screenshots: list[Path] = field(default_factory=list)
    values: dict = field(default_factory=dict)
    first_screen_s: float = -1.0  # navigation start → the figures on the first screen drawn
    on_demand_ms: list[int] = field(default_factory=list)  # drawing time of each other figure
    # CPU time (s) of all of chromium's processes from the navigation until every figure was
    # drawn: what the page costs, independent of other load on the machine (-1: no /proc)
    cpu_s: float = -1.0


def tree_cpu(root: int) -> float:
    """CPU time (user + system, s) of process ``root`` and all its descendants (Linux /proc;
    -1 elsewhere); children that ended and were waited for are in their parent's figures."""
    try:
        names = [d for d in os.listdir("/proc") if d.isdigit()]
    except OSError:
        return -1.0
    parent, cpu = {}, {}
    for d in names:
        try:
            with open(f"/proc/{d}/stat") as f:
                fields = f.read().rsplit(")", 1)[1].split()
        except OSError:
            continue
        parent[int(d)] = int(fields[1])
        cpu[int(d)] = sum(int(x) for x in fields[11:15])  # utime stime cutime cstime
    tree, todo = set(), [root]
    while todo:
        pid = todo.pop()
        tree.add(pid)
        todo += [c for c, p in parent.items() if p == pid and c not in tree]
    return sum(cpu.get(p, 0) for p in tree) / os.sysconf("SC_CLK_TCK")


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class _Cdp:
    def __init__(self, ws):
        self.ws, self.n = ws, 0

    async def call(self, method: str, **params):
        self.n += 1
        await self.ws.write_message(json.dumps({"id": self.n, "method": method, "params": params}))
        while True:
            msg = json.loads(await self.ws.read_message())
            if msg.get("id") == self.n:
                if "error" in msg:
                    raise RuntimeError(f"{method}: {msg['error']}")
                return msg.get("result", {})

    async def evaluate(self, expr: str, await_promise: bool = False, strict: bool = False):
        """The value of a JavaScript expression (with ``await_promise``: of the promise it
        gives); a script error gives None, or with ``strict`` raises RuntimeError (its text)."""
        r = await self.call(
            "Runtime.evaluate", expression=expr, returnByValue=True, awaitPromise=await_promise
        )
        if strict and "exceptionDetails" in r:
            d = r["exceptionDetails"]
            raise RuntimeError(d.get("exception", {}).get("description") or d.get("text"))
        return r.get("result", {}).get("value")


# Figures whose div meets the viewport and are not drawn yet (data-state unset or drawing).
PENDING_JS = r"""
[...document.querySelectorAll('.plot')].filter(function(d){var r=d.getBoundingClientRect();
 return r.top<innerHeight&&r.bottom>0&&d.dataset.state!=='rendered'&&d.dataset.state!=='failed'})
 .length"""


async def _scroll_through(cdp: _Cdp, height: int, t0: float, timeout: float) -> list[int]:
    """Scrolls down the page a screen at a time as a reader would, waiting at each screen until
    the figures in view are drawn (the page draws them lazily); back to the top. Returns the
    drawing time (ms, the page's own data-ms) of every figure not on the first screen; none
    for a page that draws everything at once (no data-first-screen-figures)."""
    listed = await cdp.evaluate("document.body.dataset.firstScreenFigures")
    if listed is None:
        return []
    first = set(json.loads(listed))
    top = 0
    while top < await cdp.evaluate("document.documentElement.scrollHeight"):
        await cdp.evaluate(f"window.scrollTo(0, {top})")
        await asyncio.sleep(0.05)  # the observer's callback
        while await cdp.evaluate(PENDING_JS):
            if time.perf_counter() - t0 > timeout:
                raise TimeoutError(f"the report did not draw its figures within {timeout} s")
            await asyncio.sleep(0.02)
        top += height
    await cdp.evaluate("window.scrollTo(0, 0)")
    drawn = json.loads(
        await cdp.evaluate(
            "JSON.stringify([...document.querySelectorAll('.plot[data-ms]')]"
            ".map(d => [d.id, +d.dataset.ms]))"
        )
    )
    return [ms for fid, ms in drawn if fid not in first]


async def _check(
    url, port, width, height, timeout, shots, scroll_shots, evaluate, pid
) -> PageCheck:
    cdp = await connect(port)
    ws = cdp.ws
    await cdp.call("Emulation.setDeviceMetricsOverride", width=width, height=height,
                   deviceScaleFactor=1, mobile=False)  # fmt: skip
    t0 = time.perf_counter()
    cpu0 = tree_cpu(pid)
    await cdp.call("Page.navigate", url=url)
    while True:
        done = await cdp.evaluate("document.body && document.body.dataset.checked")
        if done == "yes":
            break
        if time.perf_counter() - t0 > timeout:
            raise TimeoutError(f"the report did not finish rendering within {timeout} s")
        await asyncio.sleep(0.02)
    wall = time.perf_counter() - t0
    on_demand = await _scroll_through(cdp, height, t0, timeout)
    cpu = tree_cpu(pid) - cpu0 if cpu0 >= 0 else -1.0
    data = await cdp.evaluate("JSON.stringify(document.body.dataset)")
    d = json.loads(data)
    texts = json.loads(await cdp.evaluate(TEXT_JS))
    overlaps, clipped = texts["overlaps"], texts["clipped"]
    values = {k: await cdp.evaluate(js) for k, js in (evaluate or {}).items()}
    files = []
    if shots is not None:
        shots.mkdir(parents=True, exist_ok=True)
        total = await cdp.evaluate("document.documentElement.scrollHeight")
        tops = [0] if not scroll_shots else list(range(0, int(total), height))
        for k, top in enumerate(tops):
            await cdp.evaluate(f"window.scrollTo(0, {top})")
            await asyncio.sleep(0.3)
            png = await cdp.call("Page.captureScreenshot", format="png")
            path = shots / f"report-{k:02d}.png"
            path.write_bytes(base64.b64decode(png["data"]))
            files.append(path)
    ws.close()
    first = int(d.get("renderMs", -1)) / 1e3
    return PageCheck(
        load_s=first + sum(on_demand) / 1e3 if first >= 0 else first,
        first_screen_s=first,
        on_demand_ms=on_demand,
        wall_s=wall,
        expected=int(d.get("expectedFigures", 0)),
        rendered=int(d.get("renderedFigures", 0)),
        errors=json.loads(d.get("errors", "[]")),
        overlaps=overlaps,
        clipped=clipped,
        screenshots=files,
        values=values,
        cpu_s=cpu,
    )


def check_page(
    path: str | Path,
    *,
    width: int = 1200,
    height: int = 900,
    timeout: float = 120.0,
    screenshots: Path | None = None,
    scroll_shots: bool = True,
    evaluate: dict[str, str] | None = None,
) -> PageCheck:
    """Opens ``path`` in a fresh headless Chromium and reports what it saw; with
    ``screenshots`` (a folder) one PNG per screen height down the page; ``evaluate``: name →
    JavaScript expression, their values in ``values``."""
    with chromium(width, height) as browser:
        return asyncio.run(
            _check(
                Path(path).resolve().as_uri(),
                browser.port,
                width,
                height,
                timeout,
                screenshots,
                scroll_shots,
                evaluate,
                browser.pid,
            )  # fmt: skip
        )


class Browser(NamedTuple):
    """A running headless Chromium: its DevTools port and its process id."""

    port: int
    pid: int


@contextmanager
def chromium(width: int = 1200, height: int = 900) -> Iterator[Browser]:
    """A fresh headless Chromium with its own profile; yields its DevTools port and process id
    (connect to its page with :func:`connect`). Ended when the block ends."""
    browser = find_browser()
    if browser is None:
        raise FileNotFoundError("chromium not found (Debian package 'chromium')")
    port = _free_port()
    # Chromium's helper processes may still write to the profile after the browser ended
    with tempfile.TemporaryDirectory(ignore_cleanup_errors=True) as profile:
        proc = subprocess.Popen(
            [browser, *FLAGS, f"--remote-debugging-port={port}", f"--user-data-dir={profile}",
             f"--window-size={width},{height}", "about:blank"],
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
        )  # fmt: skip
        try:
            yield Browser(port, proc.pid)
        finally:
            proc.terminate()
            try:
                proc.wait(10)
            except subprocess.TimeoutExpired:
                proc.kill()


async def connect(port: int, timeout: float = 20.0) -> _Cdp:
    """A DevTools session on the first page of the Chromium listening on ``port``."""
    from tornado.websocket import websocket_connect

    deadline = time.monotonic() + timeout
    while True:
        try:
            with urllib.request.urlopen(f"http://127.0.0.1:{port}/json/list") as r:
                pages = [t for t in json.load(r) if t["type"] == "page"]
            if pages:
                break
        except OSError:
            pass
        if time.monotonic() > deadline:
            raise RuntimeError("chromium did not open its DevTools port")
        await asyncio.sleep(0.1)
    ws = await websocket_connect(pages[0]["webSocketDebuggerUrl"], max_message_size=2**30)
    return _Cdp(ws)
