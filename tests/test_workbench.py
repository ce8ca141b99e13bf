"""The workbench (docs/workbench.md): warm static solves of dragged clips equal cold batch
solves of the same pose; edits, undo and saving back to TOML; bad requests; the page in
headless Chromium driven through its test hook; Ctrl-C."""

from __future__ import annotations

import os
import shutil
from pathlib import Path

import numpy as np
import pytest
from cablelife.scene import SceneError, load_scene, scene_from_dict
from cablelife.workbench.session import Session, WorkbenchError, batch_equilibrium

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "examples" / "hose-three-clips.toml"
CLIP = "engine-bracket"  # on the engine body, global frame, at s = 1 (the cable's end)
START = np.array([0.75, 0.25, 0.0])


def path_points(n: int = 50) -> np.ndarray:
    """A drag path of the bracket clip: a quarter circle of 4 cm up and sideways, then back
    half way (the warm start follows a path, not a jump)."""
    a = np.linspace(0.0, np.pi / 2, n)
    return START + 0.04 * np.column_stack([np.zeros(n), 1 - np.cos(a), np.sin(a)])


@pytest.fixture
def scene_copy(tmp_path):
    target = tmp_path / "scene.toml"
    shutil.copy(EXAMPLE, target)
    return target


def clip_node(session: Session, cable: str, clip: str) -> int:
    live = session.cables[cable]
    s = next(c.s for c in session.cable_spec(cable).clips if c.name == clip)
    return int(np.argmin(np.abs(live.arc_length - s)))


def edited_scene(session: Session):
    return scene_from_dict(session.doc.unwrap(), base_dir=session.path.parent.resolve())


def test_dragged_clip_equilibrium_equals_batch_solve(scene_copy):
    session = Session.open(scene_copy)
    node = clip_node(session, "hose", CLIP)
    for p in path_points(20):
        errors = session.move_clips([{"cable": "hose", "clip": CLIP, "position": p.tolist()}])
        assert errors == {"hose": ""}
        x = session.cables["hose"].state.positions
        np.testing.assert_allclose(x[node], p, atol=1e-12)
    ref = batch_equilibrium(edited_scene(session), "hose")
    assert np.abs(session.cables["hose"].state.positions - ref).max() < 1e-9
    # the path changed the shape: the check above compares two different equilibria otherwise
    first = batch_equilibrium(load_scene(EXAMPLE), "hose")
    assert np.abs(ref - first).max() > 0.02


def test_turning_a_clip_is_a_batch_pose_too(scene_copy):
    session = Session.open(scene_copy)
    from cablelife.rotations import matrix_quaternions
    from cablelife.simulate import frame_matrix

    turn = 0.3  # rad about the global z axis
    rz = np.array([[np.cos(turn), -np.sin(turn), 0], [np.sin(turn), np.cos(turn), 0], [0, 0, 1]])
    frame = rz @ frame_matrix([1.0, 0.0, 0.0], [0.0, 0.0, 1.0])  # columns d1, d2, d3
    q = matrix_quaternions(frame[None])[0].tolist()
    session.move_clips([{"cable": "hose", "clip": CLIP, "position": START.tolist(),
                         "quaternion": q}])  # fmt: skip
    clip = session.cable_spec("hose").clips[2]
    np.testing.assert_allclose(clip.direction, [np.cos(turn), np.sin(turn), 0.0], atol=1e-12)
    np.testing.assert_allclose(clip.normal, [0.0, 0.0, 1.0], atol=1e-12)
    ref = batch_equilibrium(edited_scene(session), "hose")
    assert np.abs(session.cables["hose"].state.positions - ref).max() < 1e-9


def test_failed_solve_keeps_the_last_good_state(scene_copy):
    session = Session.open(scene_copy)
    before = session.cables["hose"].state.positions.copy()
    text = session.scene_text()
    # the 1 m hose's end pulled 5 km away: Newton does not converge, even sub-stepped
    errors = session.move_clips([{"cable": "hose", "clip": CLIP, "position": [5000.0, 0, 0]}])
    assert "cable 'hose': no equilibrium at the new clip pose" in errors["hose"]
    assert np.array_equal(session.cables["hose"].state.positions, before)
    assert session.scene_text() == text  # the clip stays where it was
    np.testing.assert_allclose(session.cables["hose"].clip_positions[2], START)
    # and the session goes on
    assert session.move_clips([{"cable": "hose", "clip": CLIP, "position": [0.75, 0.26, 0]}]) \
        == {"hose": ""}  # fmt: skip


@pytest.mark.parametrize(
    ("move", "expected"),
    [
        ({"cable": "pipe", "clip": CLIP, "position": [0, 0, 0]},
         "cable 'pipe' is not in the scene; allowed: 'hose'"),
        ({"cable": "hose", "clip": "top", "position": [0, 0, 0]},
         "cable 'hose' has no clip 'top'; allowed: 'body-clip', 'middle', 'engine-bracket'"),
        ({"cable": "hose", "clip": CLIP, "position": [0, "a", 0]},
         "position = [0, 'a', 0]: give three numbers"),
        ({"cable": "hose", "clip": CLIP, "position": [0, float("nan"), 0]},
         "allowed: finite coordinates"),
        ({"cable": "hose", "clip": CLIP, "position": [0, 0, 0], "quaternion": [0, 0, 0, 0]},
         "quaternion = [0.0, 0.0, 0.0, 0.0]: give a non-zero [w, x, y, z]"),
    ],
)  # fmt: skip
def test_bad_moves_are_refused_by_name(scene_copy, move, expected):
    session = Session.open(scene_copy)
    with pytest.raises(WorkbenchError, match=None) as err:
        session.move_clips([move])
    assert expected in str(err.value)
    assert session.undo_stack == []


def test_edits_rebuild_the_cable_and_undo_restores(scene_copy):
    session = Session.open(scene_copy)
    session.edit("hose", "middle", "s", 0.45)
    session.edit("hose", "middle", "type", "ball")
    session.edit("hose", "", "length", 1.05)
    spec = session.cable_spec("hose")
    assert (spec.length, spec.clips[1].s, spec.clips[1].type) == (1.05, 0.45, "ball")
    assert np.isclose(session.cables["hose"].arc_length[-1], 1.05)
    ref = batch_equilibrium(edited_scene(session), "hose")
    assert np.abs(session.cables["hose"].state.positions - ref).max() < 1e-9
    for _ in range(3):
        assert session.undo()
    assert not session.undo()
    assert session.scene_text() == EXAMPLE.read_text()
    assert session.cable_spec("hose").clips[1].type == "swivel"


@pytest.mark.parametrize(
    ("args", "expected"),
    [
        (("hose", "middle", "type", "glued"),
         "clip 'middle': type = 'glued'; allowed: fixed, swivel, ball"),
        (("hose", "middle", "s", "far"), "s = 'far'; give a number in m"),
        (("hose", "middle", "colour", 1), "'colour' cannot be edited here; allowed: s, type"),
        (("hose", "", "length", 0.5), "covers s = [1.0, 1.0] m, outside the cable [0, 0.5] m"),
        (("hose", "middle", "s", 1.5), "covers s = [1.5, 1.5] m, outside the cable"),
    ],
)  # fmt: skip
def test_bad_edits_change_nothing(scene_copy, args, expected):
    session = Session.open(scene_copy)
    text = session.scene_text()
    x = session.cables["hose"].state.positions.copy()
    with pytest.raises((WorkbenchError, SceneError)) as err:
        session.edit(*args)
    assert expected in str(err.value)
    assert session.scene_text() == text and session.undo_stack == []
    assert np.array_equal(session.cables["hose"].state.positions, x)


def test_save_round_trips_and_keeps_comments(scene_copy, tmp_path):
    session = Session.open(scene_copy)
    target = path_points(5)[-1]
    session.move_clips([{"cable": "hose", "clip": CLIP, "position": target.tolist()}])
    session.edit("hose", "middle", "length", 0.03)
    out = session.save(tmp_path / "edited.toml")
    text = out.read_text()
    for comment in ("# The engine rocks: 5 mm vertical sine", "# the clip centre: it holds"):
        assert comment in text
    again = load_scene(out)
    clip = again.cables[0].clips[2]
    np.testing.assert_allclose(clip.position, target, atol=1e-12)
    assert again.cables[0].clips[1].length == 0.03
    # the saved scene solves to what the workbench showed
    ref = batch_equilibrium(again, "hose")
    assert np.abs(session.cables["hose"].state.positions - ref).max() < 1e-9
    with pytest.raises(WorkbenchError, match="give a .toml file"):
        session.save(tmp_path / "edited.txt")


def test_body_frame_clip_moves_in_global_coordinates(tmp_path):
    text = EXAMPLE.read_text().replace(
        'body = "engine"\nposition = [0.75, 0.25, 0.0]',
        'body = "engine"\nframe = "body"\nposition = [0.15, 0.05, 0.0]',
    )
    text = text.replace(
        "origin = [0.6, 0.2, 0.0]", "origin = [0.6, 0.2, 0.0]\norientation = [0.0, 0.0, 0.3]"
    )
    path = tmp_path / "body.toml"
    path.write_text(text)
    session = Session.open(path)
    goal = np.array([0.74, 0.3, 0.02])
    assert session.move_clips([{"cable": "hose", "clip": CLIP, "position": goal.tolist()}]) \
        == {"hose": ""}  # fmt: skip
    node = clip_node(session, "hose", CLIP)
    np.testing.assert_allclose(session.cables["hose"].state.positions[node], goal, atol=1e-12)
    ref = batch_equilibrium(edited_scene(session), "hose")
    assert np.abs(session.cables["hose"].state.positions - ref).max() < 1e-9


def test_state_has_the_panel_figures(scene_copy):
    session = Session.open(scene_copy)
    st = session.state()["cables"]["hose"]
    f = st["figures"]
    n = len(st["positions"])
    assert set(st["values"]) == {"bending", "torsion", "tension", "bend_ratio"}
    assert all(len(v) == n for v in st["values"].values())
    assert [c["name"] for c in f["clips"]] == ["body-clip", "middle", "engine-bracket"]
    live = session.cables["hose"]
    m = live.state.moments
    kappa = np.hypot(m[:, 0] / live.stiffness[0], m[:, 1] / live.stiffness[1])
    assert np.isclose(f["minBendRadius"], 1 / kappa.max())
    assert np.isclose(f["bendRule"], 10 * 2 * 0.008)
    np.testing.assert_allclose(f["clips"][0]["force"], live.state.reaction_force[0])


def test_clearance_with_surroundings():
    pytest.importorskip("trimesh")
    scene = ROOT / "examples" / "surroundings" / "hose-near-engine.toml"
    if not (scene.parent / "engine.stl").exists():
        pytest.skip("example meshes not generated")
    session = Session.open(scene)
    st = session.state()["cables"]["hose"]
    geo = session.geometry()
    assert [b["name"] for b in geo["bodies"]] == ["engine", "car-body"]
    c = np.array(st["values"]["clearance"]) / 1e3
    from cablelife.simulate import simulate
    from cablelife.workbench.session import at_rest

    ref = simulate(at_rest(session.scene), mode="static").cables["hose"].clearance[0]
    np.testing.assert_allclose(c, ref, atol=1e-9)
    assert np.isclose(st["figures"]["minClearance"], ref.min())


# ----------------------------------------------------------------------- in the browser


def _browser():
    from cablelife.report.browser import find_browser

    if find_browser() is None:
        pytest.skip("chromium not installed")


def test_page_follows_a_dragged_clip(scene_copy, tmp_path):
    """50 moveClip calls along a path: after each the clip's node is where the clip went; the
    last equilibrium equals a batch solve of that pose; the update rate is printed."""
    _browser()
    import time

    from cablelife.simulate import build_cable
    from cablelife.workbench.drive import run_page, stop_time, workbench_process

    points = path_points(50)
    scene0 = load_scene(scene_copy)
    arc = np.asarray(build_cable(scene0, scene0.cables[0]).arc_length)
    node = int(np.argmin(np.abs(arc - 1.0)))
    shots = Path(os.environ.get("CABLELIFE_SCREENSHOTS", tmp_path))

    async def script(page):
        poses = [await page.call(f"clipPose('hose', '{c}')") for c in
                 ("body-clip", "middle", CLIP)]  # fmt: skip
        seen = []
        t0 = time.perf_counter()
        for p in points:
            await page.call(f"moveClip('hose', '{CLIP}', {p.tolist()})")
            seen.append(np.array((await page.call("state()"))["cables"]["hose"]["positions"]))
        wall = time.perf_counter() - t0
        stats = await page.call("stats()")
        await page.call("setQuantity('bend_ratio')")
        shot = await page.screenshot(shots / "workbench.png")
        bad = await page.call("moveClip('hose', 'nowhere', [0, 0, 0])")
        bad_cable = await page.call(f"moveClip('pipe', '{CLIP}', [0, 0, 0])")
        message = await page.text("message")
        failed = await page.call(f"moveClip('hose', '{CLIP}', [5000, 0, 0])")
        after = np.array((await page.call("state()"))["cables"]["hose"]["positions"])
        saved = await page.call(f"save({str(tmp_path / 'saved.toml')!r})")
        return poses, seen, wall, stats, bad, bad_cable, message, failed, after, shot, saved

    with workbench_process(scene_copy) as (proc, url):
        poses, seen, wall, stats, bad, bad_cable, message, failed, after, shot, saved = run_page(
            url, script
        )
        stopped_s, code = stop_time(proc)
    print(f"\nworkbench: 50 moveClip calls in {wall:.2f} s = {50 / wall:.1f} updates/s "
          f"(page stats {stats}); Ctrl-C stopped it in {stopped_s:.2f} s")  # fmt: skip
    # the clip frames are drawn (and a turn is sent) with the scene's orientation
    from cablelife.simulate import clip_poses

    pos, quat = clip_poses(scene0, scene0.cables[0], np.array([0.0]), with_motion=False)
    for j, pose in enumerate(poses):
        np.testing.assert_allclose(pose["position"], pos[0, j], atol=1e-12)
        q = np.array(pose["quaternion"])
        assert min(np.abs(q - quat[0, j]).max(), np.abs(q + quat[0, j]).max()) < 1e-7
    for p, x in zip(points, seen, strict=True):
        np.testing.assert_allclose(x[node], p, atol=1e-12)
    assert set(stats) == {"solvesPerSecond", "lastSolveMs", "framesPerSecond"}
    assert stats["solvesPerSecond"] > 0 and stats["lastSolveMs"] > 0
    # the page shows what a cold batch solve of the final pose gives
    edited = load_scene(tmp_path / "saved.toml")
    np.testing.assert_allclose(edited.cables[0].clips[2].position, points[-1], atol=1e-12)
    assert np.abs(seen[-1] - batch_equilibrium(edited, "hose")).max() < 1e-9
    assert saved["ok"] and saved["saved"] == str(tmp_path / "saved.toml")
    assert "# The engine rocks" in (tmp_path / "saved.toml").read_text()
    # bad input: a clear error, the state kept
    assert bad == {
        "error": "cable 'hose' has no clip 'nowhere'; allowed: 'body-clip', 'middle', "
        "'engine-bracket'"
    }
    assert bad_cable == {"error": "cable 'pipe' is not in the scene; allowed: 'hose'"}
    assert "cable 'pipe' is not in the scene" in message
    # a failed solve: its reason, the last good state kept
    assert "cable 'hose': no equilibrium at the new clip pose" in failed["error"]
    assert np.array_equal(after, seen[-1])
    assert shot.stat().st_size > 20_000
    assert code == 130  # Ctrl-C


def test_workbench_command_errors(tmp_path):
    from cablelife.cli import app
    from typer.testing import CliRunner

    runner = CliRunner()
    r = runner.invoke(app, ["workbench", str(tmp_path / "none.toml"), "--no-browser"])
    assert r.exit_code == 2 and "does not exist" in r.output
    r = runner.invoke(app, ["workbench", str(EXAMPLE), "--port", "70000"])
    assert r.exit_code == 2 and "--port 70000" in r.output
    r = runner.invoke(app, ["workbench", str(EXAMPLE), "--result", str(EXAMPLE)])
    assert r.exit_code == 2 and "--result" in r.output
    import socket

    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        port = taken.getsockname()[1]
        r = runner.invoke(app, ["workbench", str(EXAMPLE), "--no-browser", "--port", str(port)])
    assert r.exit_code == 2 and f"cannot listen on 127.0.0.1:{port}" in r.output


@pytest.fixture(scope="module")
def near_engine_run(tmp_path_factory):
    """A quasistatic run of the surroundings example (1 s), saved."""
    from cablelife.simulate import simulate

    scene = ROOT / "examples" / "surroundings" / "hose-near-engine.toml"
    if not (scene.parent / "engine.stl").exists():
        pytest.skip("example meshes not generated")
    sc = load_scene(scene)
    sc.simulation.duration = 1.0
    sc.simulation.time_step = 0.05
    path = tmp_path_factory.mktemp("run") / "run.h5"
    simulate(sc, mode="quasistatic").save(path)
    return scene, path


def test_player_gives_the_saved_steps(near_engine_run):
    from cablelife.results import load_result
    from cablelife.workbench.player import Player

    _, path = near_engine_run
    player = Player.open(path)
    res = load_result(path)
    c = res.cables["hose"]
    assert player.info()["steps"] == c.n_steps == 21
    k = 7
    d = player.step(k)
    assert d["time"] == pytest.approx(c.time[k])
    np.testing.assert_allclose(d["cables"]["hose"]["positions"], c.positions[k])
    np.testing.assert_allclose(d["cables"]["hose"]["values"]["clearance"], c.clearance[k] * 1e3)
    m = c.moments[k]
    np.testing.assert_allclose(d["cables"]["hose"]["values"]["bending"], np.hypot(m[:, 0], m[:, 1]))
    geo = res.surroundings
    assert set(d["bodies"]) == {"engine", "car-body"}
    np.testing.assert_allclose(d["bodies"]["engine"], geo.poses[0, k])
    with pytest.raises(IndexError, match="step 21: the result has steps 0 … 20"):
        player.step(21)
    with pytest.raises(WorkbenchError, match="--result"):
        Player.open(ROOT / "examples" / "hose-three-clips.toml")


def test_page_plays_a_result_file_with_the_surroundings(near_engine_run, tmp_path):
    """The surroundings example with its bodies' geometry, coloured by clearance; a result
    file scrubbed step by step (the page draws the saved nodes)."""
    _browser()
    from cablelife.results import load_result
    from cablelife.workbench.drive import run_page, workbench_process

    scene, path = near_engine_run
    shots = Path(os.environ.get("CABLELIFE_SCREENSHOTS", tmp_path))
    positions = load_result(path).cables["hose"].positions

    async def script(page):
        await page.call("setQuantity('clearance')")
        live = await page.screenshot(shots / "workbench-clearance.png")
        bodies = await page.cdp.evaluate("document.querySelector('#quantity').options.length")
        steps = [await page.call(f"showResultStep({k})") for k in (0, 5, 20)]
        label = await page.text("player-time")
        await page.call("setQuantity('bending')")
        played = await page.screenshot(shots / "workbench-result.png")
        return live, bodies, steps, label, played

    with workbench_process(scene, "--result", str(path)) as (_, url):
        live, options, steps, label, played = run_page(url, script)
    assert options == 5  # clearance offered: the scene has geometry
    for k, d in zip((0, 5, 20), steps, strict=True):
        np.testing.assert_allclose(d["cables"]["hose"]["positions"], positions[k])
    assert label == "t = 1.000 s (step 20)"
    assert live.stat().st_size > 20_000 and played.stat().st_size > 20_000


def test_mouse_drag_of_a_clip_is_one_undo_step(scene_copy):
    """A drag with the mouse on the clip's handle (TransformControls): the cable follows
    while dragging, its end node stays on the clip, and one undo restores the start."""
    _browser()

    from cablelife.workbench.drive import run_page, workbench_process

    async def script(page):
        x0 = np.array((await page.call("state()"))["cables"]["hose"]["positions"])
        x, y = await page.call(f"clipOnScreen('hose', '{CLIP}')")
        mouse = page.cdp.call
        await mouse("Input.dispatchMouseEvent", type="mouseMoved", x=x, y=y)
        await mouse("Input.dispatchMouseEvent", type="mousePressed", x=x, y=y, button="left",
                    clickCount=1)  # fmt: skip
        during = []
        for k in range(1, 21):
            await mouse("Input.dispatchMouseEvent", type="mouseMoved", x=x - 3 * k, y=y + 2 * k,
                        button="left", buttons=1)  # fmt: skip
            await page.call("settled()")  # still pressed: the cable answered this pose
            during.append(np.array((await page.call("state()"))["cables"]["hose"]["positions"]))
        await mouse("Input.dispatchMouseEvent", type="mouseReleased", x=x - 60, y=y + 40,
                    button="left", clickCount=1)  # fmt: skip
        await page.call("settled()")  # the drag's last pose solved and drawn
        x1 = np.array((await page.call("state()"))["cables"]["hose"]["positions"])
        await page.call("undo()")
        x2 = np.array((await page.call("state()"))["cables"]["hose"]["positions"])
        return x0, during, x1, x2

    with workbench_process(scene_copy) as (_, url):
        x0, during, x1, x2 = run_page(url, script)
    shapes = {round(float(d[-1][1]), 9) for d in during}
    assert len(shapes) > 3  # updates arrived while dragging
    assert np.linalg.norm(x1[-1] - x0[-1]) > 0.02
    # one drag, one undo step: solved back warm to the start pose (the same equilibrium)
    assert np.abs(x2 - x0).max() < 1e-9


def test_server_listens_on_loopback_and_refuses_foreign_pages(scene_copy):
    """Without a browser: the scene JSON over HTTP, a move over the websocket, and a
    websocket from another site's page refused."""
    import asyncio
    import json
    import urllib.request

    from cablelife.workbench.server import listen, make_app
    from tornado.httpclient import HTTPClientError, HTTPRequest
    from tornado.websocket import websocket_connect

    session = Session.open(scene_copy)

    async def main():
        server, port = listen(make_app(session))
        try:
            assert server._sockets and all(
                s.getsockname()[0] == "127.0.0.1" for s in server._sockets.values()
            )
            loop = asyncio.get_running_loop()
            url = f"http://127.0.0.1:{port}"
            info = await loop.run_in_executor(
                None, lambda: json.load(urllib.request.urlopen(f"{url}/api/scene"))
            )
            ws = await websocket_connect(HTTPRequest(f"ws://127.0.0.1:{port}/ws",
                                                     headers={"Origin": url}))  # fmt: skip
            await ws.write_message(json.dumps({"id": 7, "op": "move", "moves": [
                {"cable": "hose", "clip": CLIP, "position": [0.75, 0.27, 0.01]}]}))  # fmt: skip
            reply = json.loads(await ws.read_message())
            await ws.write_message(json.dumps({"id": 8, "op": "fly"}))
            bad = json.loads(await ws.read_message())
            await ws.write_message(json.dumps({"id": 9, "op": "move", "moves": [1]}))
            bad_moves = json.loads(await ws.read_message())
            await ws.write_message("[1, 2")
            not_json = json.loads(await ws.read_message())
            ws.close()
            refused = None
            try:
                foreign = {"Origin": "http://evil.example"}
                await websocket_connect(HTTPRequest(f"ws://127.0.0.1:{port}/ws", headers=foreign))
            except HTTPClientError as err:
                refused = err.code
            return info, reply, bad, bad_moves, not_json, refused
        finally:
            server.stop()

    info, reply, bad, bad_moves, not_json, refused = asyncio.run(main())
    session.close()
    assert info["state"]["cables"]["hose"]["figures"]["clips"][2]["name"] == CLIP
    assert reply["id"] == 7 and reply["ok"] and reply["solveMs"] > 0
    assert reply["state"]["cables"]["hose"]["positions"][-1] == [0.75, 0.27, 0.01]
    allowed = "move, moveBody, edit, addClip, removeClip, undo, save, time, rest, state"
    assert bad == {"id": 8, "ok": False, "error": f"op = 'fly'; allowed: {allowed}"}
    assert bad_moves["ok"] is False
    assert bad_moves["error"] == "move: moves = [1]; give [{cable, clip, position}, ...]"
    assert not_json == {"ok": False, "error": "a request must be a JSON object"}
    assert refused == 403


def test_panel_edit_and_undo_buttons(scene_copy):
    """Typing a clip's s in the side panel re-solves the cable (a new mesh); the undo
    button restores it; a refused value shows the validator's message."""
    _browser()

    from cablelife.workbench.drive import run_page, workbench_process

    set_input = (
        '(() => {{ const e = document.querySelector(\'input[data-item="middle"]'
        "[data-key=\"s\"]'); e.value = '{0}'; e.dispatchEvent(new Event('change', "
        "{{bubbles: true}})); }})()"
    )

    async def script(page):
        async def settle():
            await page.call("settled()")  # every request answered and drawn
            return await page.cdp.evaluate(
                'document.querySelector(\'input[data-item="middle"][data-key="s"]\').value'
            )

        n0 = (await page.call("state()"))["cables"]["hose"]["positions"]
        await page.cdp.evaluate(set_input.format(0.42))
        edited = await settle()
        n1 = (await page.call("state()"))["cables"]["hose"]["positions"]
        await page.cdp.evaluate(set_input.format(1.7))
        kept = await settle()
        refused = await page.text("message")
        await page.cdp.evaluate("document.getElementById('undo').click()")
        undone = await settle()
        n2 = (await page.call("state()"))["cables"]["hose"]["positions"]
        return n0, edited, n1, refused, kept, undone, n2

    with workbench_process(scene_copy) as (_, url):
        n0, edited, n1, refused, kept, undone, n2 = run_page(url, script)
    assert edited == "0.42" and kept == "0.42" and undone == "0.5"
    # the middle clip now holds s = 0.42: another shape; undone: the first one again
    assert np.abs(np.array(n1) - np.array(n0)).max() > 1e-3
    assert n2 == n0
    assert "covers s = [1.7, 1.7] m, outside the cable [0, 1.0] m" in refused


# ----------------------------------------------------------------------- harnesses, clip types

HARNESS = ROOT / "examples" / "harness" / "scene.toml"
BRACKET = np.array([0.8, 0.15, -0.05])  # the harness's engine-bracket clip (cable "engine")


def harness_path(n: int = 50) -> np.ndarray:
    """A drag path of the harness's engine bracket: 3 cm up and sideways along a quarter circle."""
    a = np.linspace(0.0, np.pi / 2, n)
    return BRACKET + 0.03 * np.column_stack([np.zeros(n), 1 - np.cos(a), np.sin(a)])


@pytest.fixture
def harness_copy(tmp_path):
    target = tmp_path / "harness.toml"
    shutil.copy(HARNESS, target)
    return target


def batch_harness(scene):
    """A cold batch static solve of a harness scene with its bodies at rest: (cable nodes by
    name, junction positions by name)."""
    from cablelife.simulate import simulate
    from cablelife.workbench.session import at_rest

    r = simulate(at_rest(scene), mode="static")
    return ({n: c.positions[0] for n, c in r.cables.items()},
            {n: j.position[0] for n, j in r.junctions.items()})  # fmt: skip


def test_harness_drag_moves_every_cable_and_the_junction(harness_copy, tmp_path):
    """Dragging one clip of a harness re-solves the tree: every cable and the junction move,
    the clip's node is at the clip, and the warm equilibrium equals a cold batch solve of the
    saved scene."""
    session = Session.open(harness_copy)
    x0 = {n: c.state.positions.copy() for n, c in session.cables.items()}
    j0 = np.array(session.state()["junctions"]["breakout"]["position"])
    node = clip_node(session, "engine", "engine-bracket")
    for p in harness_path(20):
        errors = session.move_clips([{"cable": "engine", "clip": "engine-bracket",
                                      "position": p.tolist()}])  # fmt: skip
        assert errors == {"engine": ""}
        np.testing.assert_allclose(session.cables["engine"].state.positions[node], p, atol=1e-12)
    out = session.save(tmp_path / "saved.toml")
    cables, junctions = batch_harness(load_scene(out))
    for name, live in session.cables.items():
        assert np.abs(live.state.positions - cables[name]).max() < 1e-9, name
        assert np.abs(live.state.positions - x0[name]).max() > 1e-4, (
            name
        )  # it answered (the trunk runs in a guide)
    j1 = np.array(session.state()["junctions"]["breakout"]["position"])
    assert np.abs(j1 - junctions["breakout"]).max() < 1e-9
    assert np.linalg.norm(j1 - j0) > 1e-4
    # the clips of the other cables stay put, the joined ends sit on the junction
    trunk = session.cables["trunk"].state.positions
    np.testing.assert_allclose(trunk[0], [0.0, 0.0, 0.0], atol=1e-12)
    np.testing.assert_allclose(trunk[-1], j1, atol=1e-12)
    # undo goes back to the scene as loaded
    for _ in range(20):
        assert session.undo()
    assert session.scene_text() == HARNESS.read_text()
    np.testing.assert_allclose(session.cables["body"].state.positions, x0["body"], atol=1e-9)


def test_harness_failed_solve_keeps_every_cable(harness_copy):
    session = Session.open(harness_copy)
    before = {n: c.state.positions.copy() for n, c in session.cables.items()}
    text = session.scene_text()
    errors = session.move_clips([{"cable": "engine", "clip": "engine-bracket",
                                  "position": [5000.0, 0.0, 0.0]}])  # fmt: skip
    assert "harness: no equilibrium at the new clip pose" in errors["engine"]
    for n, live in session.cables.items():
        assert np.array_equal(live.state.positions, before[n])
    assert session.scene_text() == text
    p = (BRACKET + [0.0, 0.005, 0.0]).tolist()
    assert session.move_clips([{"cable": "engine", "clip": "engine-bracket", "position": p}]) \
        == {"engine": ""}  # fmt: skip


def test_harness_edits_rebuild_the_tree(harness_copy):
    session = Session.open(harness_copy)

    def clip(name):
        return next(c for c in session.cable_spec("gearbox").clips if c.name == name)

    session.edit("gearbox", "gearbox-clip", "type", "hinge")
    c = clip("gearbox-clip")
    assert (c.type, c.axis, c.length) == ("hinge", (0.0, 1.0, 0.0), 0.0)
    session.edit("body", "", "length", 0.37)
    cables, _ = batch_harness(edited_scene(session))
    for name, live in session.cables.items():
        assert np.abs(live.state.positions - cables[name]).max() < 1e-9, name
    session.edit("gearbox", "gearbox-mid", "type", "sliding")  # sliding on a harness cable
    assert clip("gearbox-mid").type == "sliding"
    cables, _ = batch_harness(edited_scene(session))
    for name, live in session.cables.items():
        assert np.abs(live.state.positions - cables[name]).max() < 1e-9, name


def test_hinge_and_sliding_clip_types(scene_copy):
    """A clip turned into a hinge gets an axis (shown in global coordinates) that can be
    edited; into a sliding guide a length, and the panel's slid length is the solver's."""
    from cablelife.simulate import simulate
    from cablelife.workbench.session import at_rest

    session = Session.open(scene_copy)
    session.edit("hose", "middle", "type", "hinge")
    st = session.state()["cables"]["hose"]
    frame = np.array(st["clipFrames"][1]).T  # columns d1, d2, d3
    np.testing.assert_allclose(st["clipAxes"][1], frame[:, 1], atol=1e-12)
    assert st["clipAxes"][0] is None and st["figures"]["clips"][1]["axis"] == [0.0, 1.0, 0.0]
    session.edit("hose", "middle", "axis", [1.0, 0.0, 1.0])
    st = session.state()["cables"]["hose"]
    np.testing.assert_allclose(st["clipAxes"][1], (frame[:, 0] + frame[:, 2]) / np.sqrt(2),
                               atol=1e-12)  # fmt: skip
    ref = batch_equilibrium(edited_scene(session), "hose")
    assert np.abs(session.cables["hose"].state.positions - ref).max() < 1e-9
    with pytest.raises(WorkbenchError, match=r"axis = \[1, 'a'\]; give three numbers"):
        session.edit("hose", "middle", "axis", [1, "a"])
    with pytest.raises(WorkbenchError, match="axis given for a fixed clip"):
        session.edit("hose", "engine-bracket", "axis", [1, 0, 0])
    session.edit("hose", "middle", "type", "sliding")
    clip = session.cable_spec("hose").clips[1]
    assert clip.axis is None and clip.length == pytest.approx(4 * 1.0 / 50)  # four edges
    for k in range(1, 11):  # the end clip pulled back 2 cm: the cable slides through
        p = [0.75, 0.25 - 0.002 * k, 0.0]
        assert session.move_clips([{"cable": "hose", "clip": CLIP, "position": p}]) \
            == {"hose": ""}  # fmt: skip
    slid = session.state()["cables"]["hose"]["figures"]["clips"][1]["slid"]
    r = simulate(at_rest(edited_scene(session)), mode="static").cables["hose"]
    assert slid == pytest.approx(float(r.clips["middle"].slid_length[0]), abs=1e-9)
    assert abs(slid) > 1e-4
    assert np.abs(session.cables["hose"].state.positions - r.positions[0]).max() < 1e-9
    session.edit("hose", "middle", "type", "swivel")
    assert session.state()["cables"]["hose"]["figures"]["clips"][1]["slid"] is None


def test_page_follows_a_dragged_harness_clip(harness_copy, tmp_path):
    """The harness example in the page: 50 moveClip calls on its engine bracket; after each
    the clip's node is at the clip and the junction is drawn where the solver put it; the last
    equilibrium of every cable equals a batch static solve of the saved scene."""
    _browser()
    import time

    from cablelife.workbench.drive import run_page, workbench_process

    points = harness_path(50)
    shots = Path(os.environ.get("CABLELIFE_SCREENSHOTS", tmp_path))
    session = Session.open(harness_copy)  # the node of the clip (s = 0.45, the cable's end)
    node = clip_node(session, "engine", "engine-bracket")
    session.close()

    async def script(page):
        first = await page.call("state()")
        seen = []
        t0 = time.perf_counter()
        for p in points:
            await page.call(f"moveClip('engine', 'engine-bracket', {p.tolist()})")
            seen.append(await page.call("state()"))
        wall = time.perf_counter() - t0
        junctions = await page.cdp.evaluate("document.body.dataset.junctions")
        await page.call("select('engine', 'engine-bracket')")
        shot = await page.screenshot(shots / "workbench-harness.png")
        saved = await page.call(f"save({str(tmp_path / 'saved.toml')!r})")
        return first, seen, wall, junctions, shot, saved

    with workbench_process(harness_copy) as (_, url):
        first, seen, wall, junctions, shot, saved = run_page(url, script)
    print(f"\nworkbench harness: 50 moveClip calls in {wall:.2f} s = {50 / wall:.1f} updates/s")
    assert junctions == "1"
    for p, st in zip(points, seen, strict=True):
        np.testing.assert_allclose(st["cables"]["engine"]["positions"][node], p, atol=1e-12)
        j = st["junctions"]["breakout"]
        np.testing.assert_allclose(j["drawn"], j["position"], atol=1e-6)  # float32 on screen
        np.testing.assert_allclose(st["cables"]["trunk"]["positions"][-1], j["position"],
                                   atol=1e-12)  # fmt: skip
    assert saved["ok"]
    cables, junctions_ref = batch_harness(load_scene(tmp_path / "saved.toml"))
    last = seen[-1]
    for name, x in cables.items():
        assert np.abs(np.array(last["cables"][name]["positions"]) - x).max() < 1e-9, name
        moved = np.array(last["cables"][name]["positions"]) - first["cables"][name]["positions"]
        assert np.abs(moved).max() > 1e-4, name  # every cable of the tree answered
    assert np.abs(np.array(last["junctions"]["breakout"]["position"])
                  - junctions_ref["breakout"]).max() < 1e-9  # fmt: skip
    assert shot.stat().st_size > 20_000


def test_page_hinge_axis_and_slid_length(scene_copy, tmp_path):
    """Clip types in the page: a hinge's axis drawn along its global axis and shown in the
    panel, a sliding clip's slid length in the panel."""
    _browser()
    from cablelife.workbench.drive import run_page, workbench_process

    shots = Path(os.environ.get("CABLELIFE_SCREENSHOTS", tmp_path))
    select = (
        "(() => {{ const e = document.querySelector('select[data-item=\"middle\"]'); "
        "e.value = '{0}'; e.dispatchEvent(new Event('change', {{bubbles: true}})); }})()"
    )
    options = "Array.from(document.querySelector('select[data-item=\"middle\"]').options)" \
        ".map(o => o.value)"  # fmt: skip

    async def script(page):
        types = await page.cdp.evaluate(options)
        await page.cdp.evaluate(select.format("hinge"))
        await page.call("settled()")
        axis = await page.call("hingeAxis('hose', 'middle')")
        extra = await page.call("clipExtra('hose', 'middle')")
        await page.call("select('hose', 'middle')")
        shot = await page.screenshot(shots / "workbench-hinge.png")
        await page.cdp.evaluate(select.format("sliding"))
        await page.call("settled()")
        gone = await page.call("hingeAxis('hose', 'middle')")
        for k in range(1, 11):
            await page.call(f"moveClip('hose', '{CLIP}', [0.75, {0.25 - 0.002 * k}, 0.0])")
        slid = await page.call("clipExtra('hose', 'middle')")
        return types, axis, extra, shot, gone, slid

    with workbench_process(scene_copy) as (_, url):
        types, axis, extra, shot, gone, slid = run_page(url, script)
    assert types == ["fixed", "swivel", "ball", "hinge", "sliding"]
    # hinge about d2 of the clip frame (direction [1, 0.3, 0], normal [0, 0, 1])
    d3 = np.array([1.0, 0.3, 0.0]) / np.hypot(1.0, 0.3)
    np.testing.assert_allclose(axis, np.cross(d3, [0.0, 0.0, 1.0]), atol=1e-6)
    assert extra == [{"axis": [0, 1, 0]}]
    assert gone is None
    session = Session.open(scene_copy)  # the same edits and moves without the page
    session.edit("hose", "middle", "type", "sliding")
    for k in range(1, 11):
        session.move_clips([{"cable": "hose", "clip": CLIP,
                             "position": [0.75, 0.25 - 0.002 * k, 0.0]}])  # fmt: skip
    value = session.state()["cables"]["hose"]["figures"]["clips"][1]["slid"]
    assert len(slid) == 1 and slid[0]["slid"].endswith(" mm") and abs(value) > 1e-4
    assert float(slid[0]["slid"].split()[0]) == pytest.approx(value * 1e3, rel=5e-3)  # 4 digits
    assert shot.stat().st_size > 20_000


# ----------------------------------------------------------------------- dragging bodies

SHIFT = np.array([0.0, 0.02, 0.02])  # m: the powertrain's drag, translation
TURN = (0.03, 0.02)  # rad: and rotation ry, rz about the global axes


def body_pose_at(k: int, n: int = 10):
    """The powertrain's origin and orientation quaternion at drag step k of n."""
    from cablelife.rotations import euler_matrix, matrix_quaternions

    f = k / n
    r = euler_matrix([0.0, TURN[0] * f, TURN[1] * f])
    return (np.array([0.8, 0.0, -0.1]) + f * SHIFT).tolist(), matrix_quaternions(r[None])[0]


def test_dragging_a_body_moves_its_clips_and_saves_its_placement(harness_copy, tmp_path):
    """The harness's powertrain dragged (moved and turned) in 10 steps: its two clips follow
    rigidly, every cable answers, the saved scene has the body's new origin and orientation
    and the clips' new global poses; the equilibrium equals the last step of a batch
    quasistatic `simulate` that moves the body along the same poses (one static equilibrium
    after the other: a cold static solve of such a pose finds another equilibrium of this
    harness, 9–12 cm away)."""
    from cablelife.rotations import euler_matrix
    from cablelife.simulate import simulate

    session = Session.open(harness_copy)
    bracket0 = session.cables["engine"].clip_positions[0].copy()
    for k in range(1, 11):
        origin, q = body_pose_at(k)
        errors = session.move_body("powertrain", origin, q.tolist(), mark=k == 1)
        assert errors == {"engine": "", "gearbox": ""}
    rot = euler_matrix([0.0, *TURN])
    o0 = np.array([0.8, 0.0, -0.1])
    expected = o0 + SHIFT + rot @ (bracket0 - o0)
    np.testing.assert_allclose(session.cables["engine"].clip_positions[0], expected, atol=1e-12)
    node = clip_node(session, "engine", "engine-bracket")
    np.testing.assert_allclose(session.cables["engine"].state.positions[node], expected,
                               atol=1e-12)  # fmt: skip
    st = session.state()["bodies"]["powertrain"]
    np.testing.assert_allclose(np.array(st["map"])[:, :3], rot, atol=1e-12)
    out = session.save(tmp_path / "moved.toml")
    saved = load_scene(out)
    body = saved.body("powertrain")
    np.testing.assert_allclose(body.origin, o0 + SHIFT, atol=1e-12)
    np.testing.assert_allclose(body.orientation, [0.0, *TURN], atol=1e-12)
    clip = saved.cables[1].clips[0]
    np.testing.assert_allclose(clip.position, expected, atol=1e-12)
    np.testing.assert_allclose(clip.direction, rot @ [1.0, 0.0, 0.0], atol=1e-12)
    # the batch reference: the original scene, the body moved along the same 10 poses
    ramp = lambda v: {"type": "table", "t": [0.0, 1.0], "value": [0.0, v]}  # noqa: E731
    data = load_scene(HARNESS).model_dump(mode="json", exclude_none=True)
    data["bodies"][0]["motion"] = [
        {"channel": c, "signal": ramp(v)}
        for c, v in (("y", SHIFT[1]), ("z", SHIFT[2]), ("ry", TURN[0]), ("rz", TURN[1]))
    ]
    data["simulation"].update(mode="quasistatic", duration=1.0, time_step=0.1)
    ref = simulate(scene_from_dict(data, base_dir=HARNESS.parent), mode="quasistatic")
    for name, live in session.cables.items():
        assert np.abs(live.state.positions - ref.cables[name].positions[-1]).max() < 1e-9, name
    # one undo step for the drag
    assert session.undo() and not session.undo()
    assert session.scene_text() == HARNESS.read_text()


def test_body_drag_translation_equals_a_cold_batch_solve(harness_copy, tmp_path):
    session = Session.open(harness_copy)
    for k in range(1, 11):
        origin = (np.array([0.8, 0.0, -0.1]) + k / 10 * SHIFT).tolist()
        assert session.move_body("powertrain", origin) == {"engine": "", "gearbox": ""}
    cables, junctions = batch_harness(load_scene(session.save(tmp_path / "moved.toml")))
    for name, live in session.cables.items():
        assert np.abs(live.state.positions - cables[name]).max() < 1e-9, name


NEAR_ENGINE = ROOT / "examples" / "surroundings" / "hose-near-engine.toml"


@pytest.fixture
def near_engine_copy(tmp_path):
    """The surroundings example (CAD meshes in global coordinates) in a scratch folder."""
    pytest.importorskip("trimesh")
    if not (NEAR_ENGINE.parent / "engine.stl").exists():
        pytest.skip("example meshes not generated")
    for f in ("hose-near-engine.toml", "engine.stl", "bracket.stl"):
        shutil.copy(NEAR_ENGINE.parent / f, tmp_path / f)
    return tmp_path / "hose-near-engine.toml"


def engine_pose_at(k: int, n: int = 10):
    """The engine's drag: origin and quaternion [w, x, y, z] at step k of n (up 2 cm, turned
    0.05 rad about z)."""
    from scipy.spatial.transform import Rotation

    origin = (np.array([0.6, 0.2, 0.0]) + k / n * np.array([0.0, -0.01, 0.02])).tolist()
    q = Rotation.from_euler("z", 0.05 * k / n).as_quat(scalar_first=True)
    return origin, q


def test_dragging_a_cad_mesh_body_saves_its_placement(near_engine_copy, tmp_path):
    """The engine block is a CAD mesh in global coordinates: dragged (moved and turned), its
    mesh moves by the new ``placement``; the saved scene loads back, keeps its comments, and
    its batch static solve and clearance equal the workbench's (1e-9 m)."""
    from cablelife.simulate import simulate
    from cablelife.surroundings.build import load_surroundings
    from cablelife.workbench.session import at_rest

    session = Session.open(near_engine_copy)
    for k in range(1, 11):
        origin, q = engine_pose_at(k)
        assert session.move_body("engine", origin, q.tolist()) == {"hose": ""}
    shown = np.array(session.state()["cables"]["hose"]["values"]["clearance"]) / 1e3
    out = session.save(tmp_path / "moved.toml")
    text = out.read_text()
    assert text.startswith("# The hose of hose-three-clips.toml routed near its surroundings")
    assert "placement = {" in text
    saved = load_scene(out)
    body = saved.body("engine")
    np.testing.assert_allclose(body.placement.orientation, [0.0, 0.0, 0.05], atol=1e-12)
    # placement x ↦ p + R x equals the drag x ↦ o1 + R (x − o0)
    o0, o1 = np.array([0.6, 0.2, 0.0]), np.array(engine_pose_at(10)[0])
    rz = np.array([[np.cos(0.05), -np.sin(0.05), 0], [np.sin(0.05), np.cos(0.05), 0], [0, 0, 1]])
    np.testing.assert_allclose(body.placement.position, o1 - rz @ o0, atol=1e-12)
    # the saved scene's engine mesh is the opened one moved as drawn by the page
    before, after = load_surroundings(load_scene(NEAR_ENGINE)), load_surroundings(saved)
    k = before.bodies.index("engine")
    (v0, f0), (v1, f1) = before.display_meshes()[k], after.display_meshes()[k]
    ab = session.body_map("engine")
    np.testing.assert_array_equal(f0, f1)
    np.testing.assert_allclose(v1, v0 @ ab[:, :3].T + ab[:, 3], atol=1e-9)
    assert np.abs(v1 - v0).max() > 0.01
    ref = simulate(at_rest(saved), mode="static").cables["hose"]
    assert np.abs(session.cables["hose"].state.positions - ref.positions[0]).max() < 1e-9
    np.testing.assert_allclose(shown, ref.clearance[0], atol=1e-9)
    assert all(session.undo() for _ in range(10)) and not session.undo()  # one step a move
    assert session.scene_text() == NEAR_ENGINE.read_text()  # no placement any more
    with pytest.raises(WorkbenchError, match="body 'motor' is not in the scene; allowed: "):
        session.move_body("motor", [0.0, 0.0, 0.0])


def test_page_drags_a_cad_mesh_body_with_the_mouse(near_engine_copy, tmp_path):
    """The engine block (an STL in global coordinates) dragged by its handle with the mouse:
    the mesh and the clip follow, the cable answers; the saved scene (with the engine's new
    placement) solves to what the page shows, and its mesh is where the page draws it."""
    _browser()
    from cablelife.surroundings.build import load_surroundings
    from cablelife.workbench.drive import run_page, workbench_process
    from cablelife.workbench.session import at_rest

    shots = Path(os.environ.get("CABLELIFE_SCREENSHOTS", tmp_path))
    saved_path = tmp_path / "dragged.toml"

    async def script(page):
        x0 = await page.call("state()")
        await page.call("setQuantity('clearance')")
        await page.call("selectBody('engine')")
        x, y = await page.call("bodyOnScreen('engine')")
        mouse = page.cdp.call
        await mouse("Input.dispatchMouseEvent", type="mouseMoved", x=x, y=y)
        await mouse("Input.dispatchMouseEvent", type="mousePressed", x=x, y=y, button="left",
                    clickCount=1)  # fmt: skip
        for k in range(1, 16):
            await mouse("Input.dispatchMouseEvent", type="mouseMoved", x=x + 2 * k, y=y - 3 * k,
                        button="left", buttons=1)  # fmt: skip
            await page.call("settled()")
        await mouse("Input.dispatchMouseEvent", type="mouseReleased", x=x + 30, y=y - 45,
                    button="left", clickCount=1)  # fmt: skip
        await page.call("settled()")
        dragged = await page.call("state()")
        pose = await page.call("bodyPose('engine')")
        shot = await page.screenshot(shots / "workbench-body-mesh.png")
        saved = await page.call(f"save({str(saved_path)!r})")
        return x0, dragged, pose, shot, saved

    with workbench_process(near_engine_copy) as (_, url):
        x0, dragged, pose, shot, saved = run_page(url, script)
    assert saved["ok"]
    a0, a1 = np.array(x0["cables"]["hose"]["positions"]), dragged["cables"]["hose"]["positions"]
    assert np.abs(a0 - np.array(a1)).max() > 1e-3  # the body moved, the cable answered
    scene = load_scene(saved_path)
    body = scene.body("engine")
    assert body.placement is not None and body.origin == tuple(
        pytest.approx(v, abs=1e-12) for v in pose["position"]
    )
    ref = simulate_static(at_rest(scene))
    assert np.abs(np.array(a1) - ref.positions[0]).max() < 1e-9
    # the saved mesh is the opened one moved by the map the page draws it with
    before, after = load_surroundings(load_scene(NEAR_ENGINE)), load_surroundings(scene)
    k = before.bodies.index("engine")
    v0, v1 = before.display_meshes()[k][0], after.display_meshes()[k][0]
    ab = np.array(pose["map"])
    np.testing.assert_allclose(v1, v0 @ ab[:, :3].T + ab[:, 3], atol=1e-6)  # float32 on the page
    assert np.abs(v1 - v0).max() > 1e-3
    assert shot.stat().st_size > 20_000


def simulate_static(scene):
    from cablelife.simulate import simulate

    return simulate(scene, mode="static").cables["hose"]


def test_page_drags_a_body(harness_copy, tmp_path):
    """The harness's powertrain in the page: moved and turned through the test hook (its
    clips, handle and cables follow as the server solves them), then dragged with the mouse
    on its handle (one undo step)."""
    _browser()
    from cablelife.workbench.drive import run_page, workbench_process

    shots = Path(os.environ.get("CABLELIFE_SCREENSHOTS", tmp_path))

    async def script(page):
        x0 = await page.call("state()")
        for k in range(1, 11):
            origin, q = body_pose_at(k)
            await page.call(f"moveBody('powertrain', {origin}, {q.tolist()})")
        moved = await page.call("state()")
        handle = await page.call("bodyPose('powertrain')")
        clip = await page.call("clipPose('engine', 'engine-bracket')")
        await page.call("selectBody('powertrain')")
        shot = await page.screenshot(shots / "workbench-body.png")
        x, y = await page.call("bodyOnScreen('powertrain')")
        mouse = page.cdp.call
        await mouse("Input.dispatchMouseEvent", type="mouseMoved", x=x, y=y)
        await mouse("Input.dispatchMouseEvent", type="mousePressed", x=x, y=y, button="left",
                    clickCount=1)  # fmt: skip
        for k in range(1, 11):
            await mouse("Input.dispatchMouseEvent", type="mouseMoved", x=x + 2 * k, y=y - 2 * k,
                        button="left", buttons=1)  # fmt: skip
            await page.call("settled()")
        await mouse("Input.dispatchMouseEvent", type="mouseReleased", x=x + 20, y=y - 20,
                    button="left", clickCount=1)  # fmt: skip
        await page.call("settled()")
        dragged = await page.call("state()")
        origin = (await page.call("bodyPose('powertrain')"))["position"]
        await page.call("undo()")
        undone = await page.call("state()")
        return x0, moved, handle, clip, shot, dragged, origin, undone

    with workbench_process(harness_copy) as (_, url):
        x0, moved, handle, clip, shot, dragged, origin, undone = run_page(url, script)
    session = Session.open(harness_copy)  # the same moves without the page
    for k in range(1, 11):
        o, q = body_pose_at(k)
        session.move_body("powertrain", o, q.tolist())
    for name, live in session.cables.items():
        np.testing.assert_allclose(moved["cables"][name]["positions"], live.state.positions,
                                   atol=1e-12)  # fmt: skip
    np.testing.assert_allclose(handle["position"], body_pose_at(10)[0], atol=1e-6)
    q = body_pose_at(10)[1]
    assert min(np.abs(np.array(handle["quaternion"]) - q).max(),
               np.abs(np.array(handle["quaternion"]) + q).max()) < 1e-6  # fmt: skip
    np.testing.assert_allclose(clip["position"], session.cables["engine"].clip_positions[0],
                               atol=1e-6)  # fmt: skip
    # the mouse drag moved the body on: the cables answered; undo: back to the hook's pose
    assert np.linalg.norm(np.array(origin) - body_pose_at(10)[0]) > 1e-3
    for name in ("engine", "gearbox"):
        a, b = np.array(dragged["cables"][name]["positions"]), moved["cables"][name]["positions"]
        assert np.abs(a - b).max() > 1e-3
    for name in session.cables:  # undo solves back along the same branch (not a cold solve)
        a, b = np.array(undone["cables"][name]["positions"]), moved["cables"][name]["positions"]
        assert np.abs(a - b).max() < 1e-9, name
    assert shot.stat().st_size > 20_000


def test_turning_a_clip_with_the_mouse(scene_copy, tmp_path):
    """The rotate handle (E) of the engine bracket dragged with the mouse: the clip turns, the
    cable answers, and the saved scene (the turned direction and normal) solves to what the
    page shows."""
    _browser()
    from cablelife.workbench.drive import run_page, workbench_process

    async def script(page):
        await page.call(f"select('hose', '{CLIP}')")
        await page.call("setMode('rotate')")
        q0 = (await page.call(f"clipPose('hose', '{CLIP}')"))["quaternion"]
        x, y = await page.call(f"clipOnScreen('hose', '{CLIP}')")
        mouse = page.cdp.call
        ring = None
        for r in range(6, 200, 2):  # find a ring of the rotate handle left of the clip
            await mouse("Input.dispatchMouseEvent", type="mouseMoved", x=x - r, y=y)
            axis = await page.call("gizmoAxis()")
            if axis in ("X", "Y", "Z"):
                ring = (x - r, y, axis)
                break
        assert ring is not None, "no ring of the rotate handle found"
        rx, ry, axis = ring
        await mouse("Input.dispatchMouseEvent", type="mousePressed", x=rx, y=ry, button="left",
                    clickCount=1)  # fmt: skip
        for k in range(1, 11):
            await mouse("Input.dispatchMouseEvent", type="mouseMoved", x=rx, y=ry + 3 * k,
                        button="left", buttons=1)  # fmt: skip
            await page.call("settled()")
        await mouse("Input.dispatchMouseEvent", type="mouseReleased", x=rx, y=ry + 30,
                    button="left", clickCount=1)  # fmt: skip
        await page.call("settled()")
        q1 = (await page.call(f"clipPose('hose', '{CLIP}')"))["quaternion"]
        shown = (await page.call("state()"))["cables"]["hose"]["positions"]
        saved = await page.call(f"save({str(tmp_path / 'turned.toml')!r})")
        return q0, q1, axis, shown, saved

    with workbench_process(scene_copy) as (_, url):
        q0, q1, axis, shown, saved = run_page(url, script)
    angle = 2 * np.arccos(min(1.0, abs(float(np.dot(q0, q1)))))
    assert angle > 0.05, (axis, angle)  # the clip turned
    assert saved["ok"]
    scene = load_scene(tmp_path / "turned.toml")
    from cablelife.simulate import clip_poses

    _, quat = clip_poses(scene, scene.cables[0], np.array([0.0]), with_motion=False)
    q = quat[0, 2]
    assert min(np.abs(q - q1).max(), np.abs(q + q1).max()) < 1e-6  # saved as drawn
    assert np.abs(np.array(shown) - batch_equilibrium(scene, "hose")).max() < 1e-9


def test_dragged_body_carries_its_geometry_for_clearance(tmp_path):
    """A body with geometry in its own frame can be dragged: the clearance after the drag is
    the batch clearance of the saved scene (the geometry moved with the body)."""
    pytest.importorskip("trimesh")
    from cablelife.simulate import simulate
    from cablelife.workbench.session import at_rest

    text = EXAMPLE.read_text().replace(
        "origin = [0.6, 0.2, 0.0]",
        'origin = [0.6, 0.2, 0.0]\ngeometry = [{ shape = "sphere", center = [0.0, -0.1, 0.05], '
        'radius = 0.03, frame = "body" }]',
    )
    path = tmp_path / "sphere.toml"
    path.write_text(text)
    session = Session.open(path)
    before = np.array(session.state()["cables"]["hose"]["values"]["clearance"])
    for k in range(1, 6):
        assert session.move_body("engine", [0.6, 0.2 - 0.004 * k, 0.002 * k]) == {"hose": ""}
    after = np.array(session.state()["cables"]["hose"]["values"]["clearance"]) / 1e3
    scene = load_scene(session.save(tmp_path / "moved.toml"))
    assert scene.body("engine").origin == (0.6, 0.18, 0.01)
    ref = simulate(at_rest(scene), mode="static").cables["hose"]
    np.testing.assert_allclose(after, ref.clearance[0], atol=1e-9)
    assert np.abs(after - before / 1e3).max() > 1e-3  # the sphere moved (and the cable)
    assert np.abs(session.cables["hose"].state.positions - ref.positions[0]).max() < 1e-9


def test_time_slider_is_the_quasistatic_run(scene_copy, tmp_path):
    """The bodies' motion at the steps of the quasistatic grid, each solved as a static
    equilibrium warm from the last one shown: the same as a quasistatic run at those times
    within the Newton tolerance (1e-9 of the cable length), stepping through or jumping."""
    from cablelife.simulate import simulate

    session = Session.open(scene_copy)
    rest = session.cables["hose"].state.positions.copy()
    info = session.motion_info()
    assert info["steps"] == 101 and info["times"][-1] == pytest.approx(2.0)
    ref = simulate(load_scene(scene_copy), mode="quasistatic").cables["hose"].positions
    assert np.abs(ref[25] - ref[0]).max() > 1e-3  # the engine does move the cable
    for k in range(0, 101, 2):
        assert session.show_time(k) == {"hose": ""}
        assert np.abs(session.cables["hose"].state.positions - ref[k]).max() < 1e-9, k
    for k in (70, 5, 100, 33):  # jumps, also backwards
        assert session.show_time(k) == {"hose": ""}
        assert np.abs(session.cables["hose"].state.positions - ref[k]).max() < 1e-9, k
    st = session.state()
    assert st["time"] == {"step": 33, "t": pytest.approx(0.66)}
    m = np.array(st["bodies"]["engine"]["map"])  # the engine body drawn at its pose at t
    clip = np.array(st["cables"]["hose"]["clipPositions"][2])
    np.testing.assert_allclose(m[:, :3] @ [0.75, 0.25, 0.0] + m[:, 3], clip, atol=1e-12)
    with pytest.raises(WorkbenchError, match=r"motion is shown \(t = 0.66 s\): go back to rest"):
        session.move_clips([{"cable": "hose", "clip": CLIP, "position": [0.7, 0.2, 0.0]}])
    with pytest.raises(WorkbenchError, match="time step 101: allowed: an integer 0 … 100"):
        session.show_time(101)
    assert session.back_to_rest() == {"hose": ""}
    assert session.state()["time"] is None
    assert np.abs(session.cables["hose"].state.positions - rest).max() < 1e-9
    assert session.move_clips([{"cable": "hose", "clip": CLIP, "position": [0.7, 0.2, 0.0]}])
    # a grid too fine for a slider, and a scene without a duration: no slider, and why
    path = tmp_path / "fine.toml"
    path.write_text(scene_copy.read_text().replace("time_step = 0.02 ", "time_step = 1e-5 "))
    why = Session.open(path).motion_info()
    assert why["steps"] == 0 and "has 200001 steps" in why["why"]
    path = tmp_path / "static.toml"
    path.write_text(scene_copy.read_text().replace("duration = 2.0", ""))
    why = Session.open(path).motion_info()
    assert why["steps"] == 0 and "no simulation.duration" in why["why"]


def test_time_slider_on_a_harness(harness_copy):
    """The harness example's powertrain motion scrubbed: every cable and the junction equal
    the quasistatic run at the same steps (1e-9 m)."""
    from cablelife.simulate import simulate

    session = Session.open(harness_copy)
    res = simulate(load_scene(harness_copy), mode="quasistatic")
    steps = session.motion_info()["steps"]
    assert steps == res.cables["trunk"].positions.shape[0]
    for k in list(range(steps)) + [3, steps - 1, 0]:
        assert not any(session.show_time(k).values())
        for name, live in session.cables.items():
            assert np.abs(live.state.positions - res.cables[name].positions[k]).max() < 1e-9, k
    session.back_to_rest()
    assert session.state()["time"] is None


def test_page_scrubs_the_body_motion(scene_copy, tmp_path):
    """The time slider: the page shows the static equilibrium at steps of the quasistatic grid
    (the same as the session's, which equals the quasistatic run), labelled as such; moves are
    refused until *back to rest*, which returns to the rest equilibrium."""
    _browser()
    from cablelife.workbench.drive import run_page, workbench_process

    shots = Path(os.environ.get("CABLELIFE_SCREENSHOTS", tmp_path))
    steps = list(range(0, 101, 10)) + [37]

    async def script(page):
        x0 = await page.call("state()")
        info = await page.call("motionInfo()")
        shown = []
        for k in steps:
            t = await page.call(f"showTime({k})")
            shown.append((t, (await page.call("state()"))["cables"]["hose"]["positions"]))
        # the slider itself, as a person drags it
        await page.cdp.evaluate(
            "(function(){var s=document.getElementById('motion-step');s.value=25;"
            "s.dispatchEvent(new Event('input'));})()"
        )
        await page.call("settled()")
        slid = await page.call("state()")
        label = await page.text("motion-time")
        note = await page.cdp.evaluate("document.querySelector('#motion .note').textContent")
        note += " | " + await page.text("time-label")
        refused = await page.call(f"moveClip('hose', '{CLIP}', [0.7, 0.2, 0.0])")
        shot = await page.screenshot(shots / "workbench-motion.png")
        await page.call("backToRest()")
        rest = await page.call("state()")
        return x0, info, shown, slid, label, note, refused, shot, rest

    with workbench_process(scene_copy) as (_, url):
        x0, info, shown, slid, label, note, refused, shot, rest = run_page(url, script)
    assert info["steps"] == 101
    session = Session.open(scene_copy)
    for k, (t, positions) in zip(steps, shown, strict=True):
        assert t["time"]["step"] == k and t["time"]["t"] == pytest.approx(0.02 * k)
        assert f"t = {0.02 * k:.3f} s (step {k} of 100)" == t["label"]
        session.show_time(k)
        np.testing.assert_allclose(positions, session.cables["hose"].state.positions, atol=1e-12)
    session.show_time(25)
    np.testing.assert_allclose(slid["cables"]["hose"]["positions"],
                               session.cables["hose"].state.positions, atol=1e-12)  # fmt: skip
    assert label == "t = 0.500 s (step 25 of 100)"
    assert "Static equilibrium at each time" in note and "not dynamics" in note
    assert note.endswith("| t = 0.500 s: static equilibrium (quasistatic), not dynamics")
    assert "go back to rest to move or edit" in refused["error"]
    assert np.abs(np.array(rest["cables"]["hose"]["positions"])
                  - np.array(x0["cables"]["hose"]["positions"])).max() < 1e-9  # fmt: skip
    assert shot.stat().st_size > 20_000


def test_adding_and_removing_clips(scene_copy, tmp_path):
    """A clip added at s where the cable is (undoable, saved with the file's comments, the
    saved scene's batch solve equal to the workbench's); clips removed while the cable stays
    held; a removal that leaves the statics ill-posed is refused with the solver's reason."""
    session = Session.open(scene_copy)
    before = session.cables["hose"].state.positions.copy()
    name = session.add_clip("hose", 0.25, "fixed")
    assert name == "clip-1"
    spec = session.cable_spec("hose")
    assert [c.name for c in spec.clips] == ["body-clip", "clip-1", "middle", CLIP]
    arc = np.linspace(0.0, 1.0, 51)
    where = [np.interp(0.25, arc, before[:, i]) for i in range(3)]
    np.testing.assert_allclose(spec.clips[1].position, where, atol=1e-12)
    out = session.save(tmp_path / "added.toml")
    text = out.read_text()
    assert "# The engine rocks: 5 mm vertical sine" in text
    assert text.index('name = "clip-1"') < text.index('name = "middle"')
    ref = batch_equilibrium(load_scene(out), "hose")
    assert np.abs(session.cables["hose"].state.positions - ref).max() < 1e-9
    assert session.undo() and session.scene_text() == scene_copy.read_text()
    # a sliding clip brings its guide length, a hinge its axis
    session.add_clip("hose", 0.7, "sliding")
    assert session.cable_spec("hose").clips[-2].length == pytest.approx(0.08)
    session.undo()
    session.remove_clip("hose", "middle")
    assert [c.name for c in session.cable_spec("hose").clips] == ["body-clip", CLIP]
    ref = batch_equilibrium(load_scene(session.save(tmp_path / "removed.toml")), "hose")
    assert np.abs(session.cables["hose"].state.positions - ref).max() < 1e-9
    assert 'name = "middle"' not in (tmp_path / "removed.toml").read_text()
    session.undo()
    session.remove_clip("hose", "body-clip")
    kept = session.scene_text()
    with pytest.raises(WorkbenchError, match=r"'engine-bracket' cannot be removed: .*singular"):
        session.remove_clip("hose", CLIP)  # a single swivel point clip: the cable spins free
    assert session.scene_text() == kept and len(session.cable_spec("hose").clips) == 2
    for args, expected in [
        (("hose", 1.5, "fixed"), r"new clip s = 1.5 m is outside the cable \[0, 1\] m"),
        (("hose", 0.3, "glued"), "new clip type = 'glued'; allowed: fixed, swivel"),
        (("hose", 0.3, "fixed", "motor"), "new clip body = 'motor'; allowed: 'world', 'engine'"),
        (("hose", 0.5, "fixed"), "overlap"),
        (("pipe", 0.5, "fixed"), "cable 'pipe' is not in the scene"),
    ]:
        with pytest.raises((WorkbenchError, SceneError), match=expected):
            session.add_clip(*args)
        assert session.scene_text() == kept
    with pytest.raises(WorkbenchError, match="cable 'hose' has no clip 'nope'"):
        session.remove_clip("hose", "nope")


def test_page_adds_and_removes_clips(scene_copy, tmp_path):
    """The panel's *add clip* row and a clip's × button, clicked as a person would: the handle
    appears / goes, the cable is re-solved as the session does, undo restores; a removal that
    leaves the cable free is refused with the reason on the page."""
    _browser()
    from cablelife.workbench.drive import run_page, workbench_process

    shots = Path(os.environ.get("CABLELIFE_SCREENSHOTS", tmp_path))

    def click(selector):
        return f"document.querySelector({selector!r}).click()"

    async def script(page):
        ev = page.cdp.evaluate
        await ev("document.querySelector('.add-clip .add-s').value = '0.3'")
        await ev("(function(){var t=document.querySelector('.add-clip .add-type');"
                 "t.value='swivel';})()")  # fmt: skip
        await ev(click(".add-clip button.add"))
        await page.call("settled()")
        added = await page.call("clipNames()")
        state = await page.call("state()")
        await page.call("select('hose', 'clip-1')")
        shot = await page.screenshot(shots / "workbench-clips.png")
        await ev(click('button.rm[data-item="clip-1"]'))
        await page.call("settled()")
        removed = await page.call("clipNames()")
        await ev(click('button.rm[data-item="body-clip"]'))
        await page.call("settled()")
        refused = await page.call("removeClip('hose', 'engine-bracket')")
        message = await page.text("message")
        after = await page.call("clipNames()")
        await page.call("undo()")
        await page.call("undo()")
        undone = await page.call("clipNames()")
        return added, state, shot, removed, refused, message, after, undone

    with workbench_process(scene_copy) as (_, url):
        added, state, shot, removed, refused, message, after, undone = run_page(url, script)
    assert sorted(added["hose"]) == sorted(["body-clip", "clip-1", "middle", CLIP])
    session = Session.open(scene_copy)
    session.add_clip("hose", 0.3, "swivel")
    np.testing.assert_allclose(state["cables"]["hose"]["positions"],
                               session.cables["hose"].state.positions, atol=1e-12)  # fmt: skip
    assert sorted(removed["hose"]) == sorted(["body-clip", "middle", CLIP])
    assert "clip 'engine-bracket' cannot be removed" in refused["error"]
    assert "cannot be removed" in message and "singular" in message
    assert sorted(after["hose"]) == sorted(["middle", CLIP])
    assert sorted(undone["hose"]) == sorted(["body-clip", "clip-1", "middle", CLIP])
    assert shot.stat().st_size > 20_000


def test_dragged_body_moves_its_contact_obstacles(tmp_path):
    """With contact, the obstacles of a dragged body move with it: a table (a CAD mesh in
    global coordinates, no clips) under a sagging hose lifted by 5.4 cm pushes the hose up; the
    saved scene has the table where it was dragged (its placement), and the equilibrium is the
    quasistatic run's that lifts the table through the same poses (frictionless)."""
    trimesh = pytest.importorskip("trimesh")

    box = trimesh.creation.box(extents=[0.6, 0.4, 0.05])
    box.apply_translation([0.4, 0.1, -0.325])
    box.export(tmp_path / "table.stl")
    path = tmp_path / "table.toml"
    path.write_text(
        """# a hose hanging above a table
[simulation]
mode = "static"

[contact]
enabled = true
friction = 0.0

[[bodies]]
name = "table"
origin = [0.4, 0.1, -0.3]
geometry = [{ mesh = "table.stl", name = "top" }]

[[cables]]
name = "hose"
length = 1.0
segments = 40
section = { shape = "circle", radius = 0.005 }
material = { youngs_modulus = 5.0e7, poisson_ratio = 0.45, density = 1500.0 }

[[cables.clips]]
name = "a"
s = 0.0
position = [0.0, 0.0, 0.0]
direction = [1.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]

[[cables.clips]]
name = "b"
s = 1.0
position = [0.8, 0.2, 0.0]
direction = [1.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
"""
    )
    session = Session.open(path)
    before = session.cables["hose"].state.positions.copy()
    for k in range(1, 11):
        assert session.move_body("table", [0.4, 0.1, -0.3 + 0.0054 * k]) == {"hose": ""}
    after = session.cables["hose"].state.positions
    assert after[:, 2].min() - before[:, 2].min() > 2e-3  # the table holds the hose up
    from cablelife.contact_settings import obstacles
    from cablelife.simulate import simulate

    scene = load_scene(session.save(tmp_path / "lifted.toml"))
    np.testing.assert_allclose(scene.body("table").placement.position, [0, 0, 0.054], atol=1e-12)
    (_, f1, m1), (_, f0, m0) = obstacles(scene), obstacles(load_scene(path))
    np.testing.assert_allclose(f1[0][0], f0[0][0] + [0, 0, 0.054], atol=1e-12)  # the saved table
    np.testing.assert_allclose(m1[0][0], m0[0][0], atol=1e-12)
    # a cold batch solve cannot start with the route through the lifted table: the reference
    # is the quasistatic run lifting it through the same ten poses
    data = load_scene(path).model_dump(mode="json", exclude_none=True)
    data["bodies"][0]["motion"] = [
        {"channel": "z", "signal": {"type": "table", "t": [0.0, 1.0], "value": [0.0, 0.054]}}
    ]
    data["simulation"].update(mode="quasistatic", duration=1.0, time_step=0.1)
    ref = simulate(scene_from_dict(data, base_dir=tmp_path)).cables["hose"].positions
    assert np.abs(after - ref[-1]).max() < 1e-9
    assert all(session.undo() for _ in range(10))
    assert np.abs(session.cables["hose"].state.positions - before).max() < 1e-9


def test_time_slider_moves_the_geometry_for_clearance(near_engine_copy):
    """With the motion shown, the clearance is to the bodies' geometry at that time: equal to
    the quasistatic run's clearance at the same steps."""
    from cablelife.simulate import simulate

    session = Session.open(near_engine_copy)
    ref = simulate(load_scene(near_engine_copy), mode="quasistatic").cables["hose"]
    for k in (0, 12, 25, 60, 100):
        assert session.show_time(k) == {"hose": ""}
        live = session.cables["hose"]
        assert np.abs(live.state.positions - ref.positions[k]).max() < 1e-9
        clearance = np.array(session.state()["cables"]["hose"]["values"]["clearance"]) / 1e3
        np.testing.assert_allclose(clearance, ref.clearance[k], atol=1e-9)
    assert np.abs(ref.clearance - ref.clearance[0]).max() > 1e-3  # the engine does move


def test_harness_on_a_table_follows_the_dragged_table(tmp_path):
    """Contact on a harness in the workbench: the Y lies on a table (contact solved with the
    obstacles at rest), the table dragged up 5 mm in five moves lifts it, and the harness
    equals the quasistatic run that lifts the table through the same poses; undo brings it
    back."""
    import tomli_w
    from cablelife.simulate import simulate
    from test_harness_contact import TABLE_Z, R, table, y_scene

    d = table(y_scene(mass=0.02))
    path = tmp_path / "y.toml"
    path.write_bytes(tomli_w.dumps(d).encode())
    session = Session.open(path)
    j0 = session.harness.junction_positions[0].copy()
    assert j0[2] - R - TABLE_Z == pytest.approx(0.0, abs=0.01 * R)  # on the table
    for k in range(1, 6):
        moved = session.move_body("table", [0.0, 0.0, 0.001 * k])
        assert all(m == "" for m in moved.values()), moved
    j1 = session.harness.junction_positions[0]
    assert j1[2] - j0[2] == pytest.approx(0.005, abs=0.01 * R)  # lifted with the table
    d["simulation"].update(mode="quasistatic", duration=1.0, time_step=0.2)
    lift = {"type": "table", "t": [0.0, 1.0], "value": [0.0, 0.005]}
    d["bodies"][0]["motion"] = [{"channel": "z", "signal": lift}]
    ref = simulate(scene_from_dict(d))
    for name, live in session.cables.items():
        np.testing.assert_allclose(
            live.state.positions, ref.cables[name].positions[-1], rtol=0, atol=1e-8
        )
    assert all(session.undo() for _ in range(5))
    np.testing.assert_allclose(session.harness.junction_positions[0], j0, rtol=0, atol=1e-8)
