"""The example harness through the command line (run, lda, report), and the report's harness
view: every cable in one 3D scene with the junctions marked, the damage on every branch;
checked in headless Chromium as a person sees it (screenshots kept as test artifacts)."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]
ARTIFACTS = ROOT / "test-artifacts"
EXAMPLE = ROOT / "examples" / "harness" / "scene.toml"
CABLES = ["trunk", "engine", "gearbox", "body"]


def cli(*args: str) -> str:
    proc = subprocess.run(
        [sys.executable, "-m", "cablelife", *args], capture_output=True, text=True, cwd=ROOT
    )
    assert proc.returncode == 0, proc.stderr
    return proc.stdout


@pytest.fixture(scope="module")
def example(tmp_path_factory):
    """The example harness run (dynamic, 1 s at 1 ms, as in the scene: the demo style), its
    LDA and its report."""
    d = tmp_path_factory.mktemp("harness")
    out = cli("run", str(EXAMPLE), "-o", str(d / "h.h5"))
    assert "junctions (max over time)" in out
    lda = cli("lda", str(d / "h.h5"), "-o", str(d / "h.damage.h5"))
    assert "hot spots" in lda
    cli(
        "report",
        str(d / "h.h5"),
        str(d / "h.damage.h5"),
        "-o",
        str(d / "h.html"),
        "--voxel",
        "none",
    )
    return d


def test_example_has_every_clip_type_and_its_results(example):
    from cablelife.results import load_result

    res = load_result(example / "h.h5")
    assert res.complete and res.mode == "dynamic"
    # Dynamic harness outputs: junction velocity (the derivative of its saved position, to
    # the integrator's O(h²)) and the harness's energies.
    j = res.junctions["breakout"]
    assert j.velocity.shape == (res.cables["trunk"].n_steps, 3)
    fd = np.gradient(j.position, j.time, axis=0)
    assert np.abs(fd - j.velocity)[5:-5].max() < 0.05 * np.abs(j.velocity).max()
    e = res.harness_energies
    assert e["kinetic_energy"].max() > 0 and np.isfinite(e["dissipated_energy"]).all()
    assert sorted(res.cables) == sorted(CABLES)
    guide = res.cables["trunk"].clips["trunk-guide"]
    assert guide.slid_length is not None and np.abs(guide.slid_length).max() > 1e-5
    # The hinged connector turns freely about its axis (d1 of the clip frame): no moment
    # about it, while the bracket carries moments about the other axes. Checked on the
    # quasistatic run (equilibria to round-off; in the dynamic run the free angle's balance
    # holds to the Newton tolerance, a fraction of the step's error estimate).
    from cablelife.report.scene_data import result_scene
    from cablelife.simulate import clip_kinematics, simulate

    scene = result_scene(res.scene_toml)
    sim = scene.simulation.model_copy(update={"mode": "quasistatic", "time_step": 0.005})
    scene = scene.model_copy(update={"simulation": sim})
    engine = simulate(scene).cables["engine"]
    spec = next(c for c in scene.cables if c.name == "engine")
    kin = clip_kinematics(scene, spec, engine.time)
    w, x, y, z = kin["quaternions"][:, 0].T  # the clip frame; the axis is its d1
    axis = np.stack([1 - 2 * (y * y + z * z), 2 * (x * y + w * z), 2 * (x * z - w * y)], axis=1)
    m = engine.clips["engine-bracket"].moment
    about = np.einsum("ti,ti->t", m, axis)
    assert np.abs(about).max() < 1e-6 * np.linalg.norm(m, axis=1).max()
    assert res.cables["gearbox"].clips["gearbox-mid"].force.shape == (
        res.cables["gearbox"].n_steps,
        3,
    )


def test_harness_view_draws_every_cable_and_the_junctions(example):
    from cablelife.report.harness_view import harness_figure
    from cablelife.report.html import ReportRun
    from cablelife.results import load_result

    res = load_result(example / "h.h5")
    run = ReportRun("h", res, example / "h.damage.h5")
    damage = {n: run.damage_of(n)[0] for n in res.cables}
    fig = harness_figure(res, "bending", 6, damage)
    tubes = [t for t in fig["data"] if t["type"] == "mesh3d" and t["name"] in CABLES]
    assert sorted(t["name"] for t in tubes) == sorted(CABLES)
    assert len({(t["cmin"], t["cmax"]) for t in tubes}) == 1  # one colour scale
    assert sum(bool(t.get("showscale")) for t in tubes) == 1
    (junctions,) = [t for t in fig["data"] if t["name"] == "junctions"]
    j = res.junctions["breakout"]
    np.testing.assert_allclose([junctions[a][0] for a in "xyz"], j.position[0])
    # Every frame moves every tube and the junction: at the last frame the junction marker
    # is at the junction's position then.
    last = fig["frames"][-1]
    assert len(last["data"]) == len(last["traces"])
    moved = [fig["data"][i]["name"] for i in last["traces"]]
    assert sorted(n for n in moved if n in CABLES) == sorted(CABLES) and "junctions" in moved
    k = int(np.argmin(np.abs(j.time - float(last["name"]))))
    jt = last["data"][moved.index("junctions")]
    np.testing.assert_allclose([jt[a][0] for a in "xyz"], j.position[k])
    # The damage map covers every branch, on one log scale, behind its button.
    maps = [t for t in fig["data"] if str(t.get("name", "")).startswith("damage: ")]
    assert sorted(t["name"][8:] for t in maps) == sorted(CABLES)
    assert len({(t["cmin"], t["cmax"]) for t in maps}) == 1
    menu = next(m for m in fig["layout"]["updatemenus"] if m.get("name") == "views")
    button = next(b for b in menu["buttons"] if b["label"] == "damage on every branch")
    shown = [fig["data"][i]["name"] for i, v in enumerate(button["args"][0]["visible"]) if v]
    assert all(f"damage: {c}" in shown for c in CABLES) and "junctions" in shown
    assert not any(n in CABLES for n in shown)  # the coloured tubes give way to the maps


HARNESS_FACTS = {
    "harness": """JSON.stringify([...document.querySelectorAll('.js-plotly-plot')].filter(
        d => d.data && d.data.some(t => t.name === 'junctions')).map(d => {
        const b = [...d.querySelectorAll('.updatemenu-button')].find(
            e => e.textContent === 'damage on every branch');
        b.dispatchEvent(new MouseEvent('click', {bubbles: true}));  // the button a person clicks
        return d._fullData.filter(t => t.visible === true).map(t => t.name)}))""",
}


def test_harness_report_as_a_person_sees_it_in_headless_chromium(example):
    from cablelife.report.browser import check_page, find_browser

    if find_browser() is None:
        pytest.skip("chromium not found (Debian package 'chromium'; .ci/run should install it)")
    shots = ARTIFACTS / "report-harness"
    for old in shots.glob("report-*.png"):
        old.unlink()
    seen = check_page(
        example / "h.html", width=1100, height=900, screenshots=shots, evaluate=HARNESS_FACTS
    )
    assert seen.errors == []
    assert seen.rendered == seen.expected > 0
    (visible,) = json.loads(seen.values["harness"])
    assert all(f"damage: {c}" in visible for c in CABLES), visible
    assert "junctions" in visible
    assert len(seen.screenshots) > 2 and all(p.stat().st_size > 10_000 for p in seen.screenshots)
