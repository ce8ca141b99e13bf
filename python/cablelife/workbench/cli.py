"""``cablelife workbench SCENE.toml``: the interactive page (docs/workbench.md)."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Annotated

import typer


def workbench_command(
    scene: Annotated[Path, typer.Argument(help="scene TOML file")],
    port: Annotated[
        int, typer.Option(help="port on 127.0.0.1 (default 0: a random free port)")
    ] = 0,
    no_browser: Annotated[
        bool, typer.Option("--no-browser", help="only print the URL, do not open a browser")
    ] = False,
    result: Annotated[
        Path | None,
        typer.Option("--result", help="an HDF5 result file (cablelife run -o) to play"),
    ] = None,
    bend_factor: Annotated[
        float, typer.Option(help="bend radius rule: at least this × the diameter")
    ] = 10.0,
) -> None:
    """Move clips in the browser and watch the cables' static equilibrium (Ctrl-C stops)."""
    from cablelife.cli import console, fail
    from cablelife.interrupt import interrupted
    from cablelife.scene import SceneError
    from cablelife.signals.errors import SignalError
    from cablelife.workbench.session import Session, WorkbenchError

    if not 0 <= port <= 65535:
        raise fail(f"--port {port}: allowed: 0 (a random free port) or 1 … 65535")
    if not (math.isfinite(bend_factor) and bend_factor > 0):
        raise fail(f"--bend-factor {bend_factor}: give a positive number")
    try:
        player = None
        if result is not None:
            from cablelife.workbench.player import Player

            player = Player.open(result, bend_factor)
        session = Session.open(scene, bend_factor=bend_factor)
    except (SceneError, SignalError, WorkbenchError) as err:
        raise fail(str(err)) from None
    except KeyboardInterrupt:
        raise interrupted() from None
    from cablelife.workbench.server import serve

    def say(url: str) -> None:
        console.print(f"cablelife workbench: {url}  (Ctrl-C stops)", soft_wrap=True)

    try:
        serve(session, port=port, open_browser=not no_browser, player=player, say=say)
    except WorkbenchError as err:
        raise fail(str(err)) from None
    except KeyboardInterrupt:
        raise interrupted("workbench stopped") from None
