"""The workbench's local web server (tornado): the page and its scripts from the package's
``static`` folder, the scene and its state as JSON, and a websocket for moves and edits.

It listens on 127.0.0.1 only. Solves run in worker threads (the Rust solver releases the GIL),
so the event loop keeps serving; messages of one connection are handled in order. Ctrl-C ends
the event loop within a second (:data:`cablelife.interrupt.POLL_S` wake-ups)."""

from __future__ import annotations

import asyncio
import json
import socket
import time
from pathlib import Path

import tornado.web
import tornado.websocket

from cablelife.workbench.session import CLIP_TYPES, QUANTITIES, Session, WorkbenchError

STATIC = Path(__file__).parent / "static"


def _json(obj) -> str:
    return json.dumps(obj, allow_nan=False, separators=(",", ":"))


class _Base(tornado.web.RequestHandler):
    def initialize(self, app_state):
        self.app = app_state

    def set_default_headers(self):
        self.set_header("Cache-Control", "no-store")


class IndexHandler(_Base):
    def get(self):
        self.set_header("Content-Type", "text/html; charset=utf-8")
        self.write((STATIC / "index.html").read_bytes())


class SceneHandler(_Base):
    """Everything the page needs once: names, geometry, quantities, the first state."""

    def get(self):
        s: Session = self.app["session"]
        info = {
            "scene": str(s.path),
            "quantities": {k: {"label": a, "unit": b} for k, (a, b) in QUANTITIES.items()},
            "bendFactor": s.bend_factor,
            "geometry": s.geometry(),
            "clipTypes": list(CLIP_TYPES),
            "state": s.state(),
            "result": self.app.get("result_info"),
            "motion": s.motion_info(),
        }
        self.set_header("Content-Type", "application/json")
        self.write(_json(info))


class ResultStepHandler(_Base):
    """One saved step of the opened result file: node positions and colour values."""

    def get(self, step: str):
        player = self.app.get("player")
        if player is None:
            raise tornado.web.HTTPError(404, reason="no result file opened")
        try:
            data = player.step(int(step))
        except (ValueError, IndexError) as err:
            raise tornado.web.HTTPError(400, reason=str(err)) from None
        self.set_header("Content-Type", "application/json")
        self.write(_json(data))


class SocketHandler(tornado.websocket.WebSocketHandler):
    """Requests {id, op, ...} → replies {id, ok, state | error}. Ops: move (moves: [{cable,
    clip, position, quaternion?}]), moveBody, edit (cable, item, key, value), addClip (cable, s,
    type, body), removeClip (cable, clip), undo, save (path?),
    time (step: the bodies' motion at a step of the quasistatic grid), rest, state."""

    def initialize(self, app_state):
        self.app = app_state

    def check_origin(self, origin):
        """Only the workbench's own page may connect: its origin is this server, addressed as
        127.0.0.1 or localhost (a page of another site, also one whose name was re-pointed to
        127.0.0.1, is refused)."""
        host = self.request.headers.get("Host", "")
        name = host.rsplit(":", 1)[0]
        return name in ("127.0.0.1", "localhost") and origin.split("//", 1)[-1] == host

    async def on_message(self, message):
        try:
            req = json.loads(message)
            rid = req.get("id")
        except (ValueError, AttributeError, TypeError):
            self.write_message(_json({"ok": False, "error": "a request must be a JSON object"}))
            return
        loop = asyncio.get_running_loop()
        try:
            reply = await loop.run_in_executor(self.app["worker"], self._handle, req)
        except (WorkbenchError, ValueError) as err:
            reply = {"ok": False, "error": str(err)}
        except Exception as err:  # never leave the page waiting for an answer
            reply = {"ok": False, "error": f"the workbench failed: {type(err).__name__}: {err}"}
        reply["id"] = rid
        try:
            text = _json(reply)
        except ValueError as err:  # a non-finite number: say so instead of sending NaN
            text = _json({"id": rid, "ok": False, "error": f"the reply cannot be sent: {err}"})
        try:
            self.write_message(text)
        except tornado.websocket.WebSocketClosedError:
            pass

    def _handle(self, req: dict) -> dict:
        s: Session = self.app["session"]
        op = req.get("op")
        if op == "move":
            moves = req.get("moves")
            if (
                not isinstance(moves, list)
                or not moves
                or not all(isinstance(m, dict) for m in moves)
            ):
                raise WorkbenchError(
                    f"move: moves = {str(moves)[:80]}; give [{{cable, clip, position}}, ...]"
                )
            start = time.perf_counter()
            errors = s.move_clips(moves, mark=bool(req.get("mark", True)))
            ms = (time.perf_counter() - start) * 1e3
            failed = "; ".join(e for e in errors.values() if e)
            return {"ok": not failed, "error": failed, "state": s.state(), "solveMs": ms}
        if op == "moveBody":
            start = time.perf_counter()
            errors = s.move_body(req.get("body"), req.get("position"), req.get("quaternion"),
                                 mark=bool(req.get("mark", True)))  # fmt: skip
            ms = (time.perf_counter() - start) * 1e3
            failed = "; ".join(e for e in errors.values() if e)
            return {"ok": not failed, "error": failed, "state": s.state(), "solveMs": ms}
        if op == "edit":
            s.edit(str(req.get("cable")), str(req.get("item") or ""), str(req.get("key")),
                   req.get("value"))  # fmt: skip
            return {"ok": True, "state": s.state()}
        if op == "undo":
            done = s.undo()
            return {"ok": True, "state": s.state(), "error": "" if done else "nothing to undo"}
        if op == "save":
            path = s.save(req.get("path") or None)
            return {"ok": True, "saved": str(path), "state": s.state()}
        if op == "addClip":
            name = s.add_clip(str(req.get("cable")), req.get("s"), str(req.get("type") or "fixed"),
                              str(req.get("body") or "world"))  # fmt: skip
            return {"ok": True, "clip": name, "state": s.state()}
        if op == "removeClip":
            s.remove_clip(str(req.get("cable")), str(req.get("clip")))
            return {"ok": True, "state": s.state()}
        if op == "time":
            start = time.perf_counter()
            errors = s.show_time(req.get("step"))
            ms = (time.perf_counter() - start) * 1e3
            failed = "; ".join(e for e in errors.values() if e)
            return {"ok": not failed, "error": failed, "state": s.state(), "solveMs": ms}
        if op == "rest":
            errors = s.back_to_rest()
            failed = "; ".join(e for e in errors.values() if e)
            return {"ok": not failed, "error": failed, "state": s.state()}
        if op == "state":
            return {"ok": True, "state": s.state()}
        raise WorkbenchError(
            f"op = {op!r}; allowed: move, moveBody, edit, addClip, removeClip, undo, save, "
            "time, rest, state"
        )


def make_app(session: Session, player=None) -> tornado.web.Application:
    from concurrent.futures import ThreadPoolExecutor

    state = {
        "session": session,
        "worker": ThreadPoolExecutor(max_workers=1),  # requests in order, solves in its pool
        "player": player,
        "result_info": player.info() if player is not None else None,
    }
    args = {"app_state": state}
    return tornado.web.Application(
        [
            (r"/", IndexHandler, args),
            (r"/api/scene", SceneHandler, args),
            (r"/api/result/(\d+)", ResultStepHandler, args),
            (r"/ws", SocketHandler, args),
            (r"/static/(.*)", tornado.web.StaticFileHandler, {"path": str(STATIC)}),
        ],
        websocket_max_message_size=2**24,
    )


def listen(app: tornado.web.Application, port: int = 0):
    """Binds 127.0.0.1:port (0: a free port); returns (server, port)."""
    from tornado.httpserver import HTTPServer
    from tornado.netutil import bind_sockets

    try:
        sockets = bind_sockets(port, address="127.0.0.1", family=socket.AF_INET)
    except OSError as err:
        raise WorkbenchError(
            f"--port {port}: cannot listen on 127.0.0.1:{port} ({err.strerror}); give a free "
            "port between 1024 and 65535, or leave it out for a random free one"
        ) from None
    server = HTTPServer(app)
    server.add_sockets(sockets)
    return server, sockets[0].getsockname()[1]


def serve(session: Session, port: int = 0, open_browser: bool = True, player=None, say=print):
    """Serves until Ctrl-C (KeyboardInterrupt propagates to the caller)."""
    from cablelife.interrupt import POLL_S

    async def main():
        app = make_app(session, player)
        server, bound = listen(app, port)
        url = f"http://127.0.0.1:{bound}/"
        say(url)
        if open_browser:
            import webbrowser

            webbrowser.open(url)
        try:
            while True:  # short sleeps: Ctrl-C is seen within POLL_S
                await asyncio.sleep(POLL_S)
        finally:
            server.stop()

    try:
        asyncio.run(main())
    finally:
        session.close()
