"""The HTML report: self-contained, every figure renders in headless Chromium, no errors."""

from __future__ import annotations

import copy
import json
import re
from pathlib import Path

import numpy as np
import pytest

ARTIFACTS = Path(__file__).resolve().parents[1] / "test-artifacts"


def variant_scene(length: float = 1.0, duration: float = 1.0) -> dict:
    """The two-clip hose with clip b on an engine rocking 50 mm at 1 Hz (quasistatic)."""
    from conftest import BASE

    d = copy.deepcopy(BASE)
    d["simulation"].update(mode="quasistatic", duration=duration, time_step=0.05)
    sine = {"type": "sine", "amplitude": 0.05, "frequency": 1.0}
    d["bodies"] = [
        {"name": "engine", "origin": [0.8, 0.2, 0.0], "motion": [{"channel": "z", "signal": sine}]}
    ]
    d["cables"][0]["clips"][1]["body"] = "engine"
    d["cables"][0]["length"] = d["cables"][0]["clips"][1]["s"] = length
    return d


def in_report(text: str, needle: str) -> bool:
    """``needle`` is in the report's markup or in a figure's JSON, whichever way the JSON
    encoder plotly uses writes non-ASCII characters (json: ``\\u2192``, orjson: raw UTF-8)."""
    return needle in text or json.dumps(needle)[1:-1] in text


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    """Two variants (cable lengths 1.0 and 1.1 m) and their damage files of the LDA, the
    damage files given in the opposite order (they are matched by their source)."""
    from cablelife.lda import analyse
    from cablelife.scene import scene_from_dict
    from cablelife.simulate import simulate

    folder = tmp_path_factory.mktemp("report")
    paths = [folder / "short.h5", folder / "long.h5"]
    for path, length in zip(paths, (1.0, 1.1), strict=True):
        simulate(scene_from_dict(variant_scene(length))).save(path)
    damage = []
    for path in reversed(paths):
        damage.append(analyse(path, sampling_check=False).save(path.with_suffix(".damage.h5")))
    return [*paths, *damage]


@pytest.fixture(scope="module")
def dynamic_files(files, tmp_path_factory):
    """The short variant also run dynamically (0.5 s), with its damage file: the report then
    has runs of two modes."""
    from cablelife.lda import analyse
    from cablelife.scene import scene_from_dict
    from cablelife.simulate import simulate

    d = variant_scene(1.0, duration=0.5)
    d["simulation"].update(mode="dynamic", time_step=0.002)
    d["bodies"][0]["motion"][0]["signal"]["fade_in"] = 0.2
    path = files[0].parent / "short-dynamic.h5"
    simulate(scene_from_dict(d)).save(path)
    dmg = analyse(path, sampling_check=False).save(path.with_suffix(".damage.h5"))
    return [path, dmg]


@pytest.fixture(scope="module")
def report(files, tmp_path_factory):
    import typer
    from cablelife.report.cli import report_command
    from typer.testing import CliRunner

    app = typer.Typer()
    app.command()(report_command)
    out = tmp_path_factory.mktemp("html") / "report.html"
    run = CliRunner().invoke(
        app, [*map(str, files), "-o", str(out), "--frames", "6", "--voxel", "5mm"]
    )
    assert run.exit_code == 0, run.output
    return out


def test_report_is_self_contained(report, files):
    from cablelife.lda import compare
    from cablelife.report.page import unpack

    page = report.read_text()
    # Works offline: plotly.js embedded (compressed), no external script, style sheet or image.
    js = unpack(page, "plotlyjs")
    assert js.startswith("/**") and "plotly.js" in js[:2000] and len(js) > 3_000_000
    assert len(page) < 3_000_000  # compressed
    markup = re.sub(r"<script\b[^>]*>.*?</script>", "", page, flags=re.S)
    assert not re.findall(r'(?:src|href)="(?!data:|#)', markup)
    expected = int(re.search(r'data-expected-figures="(\d+)"', page)[1])
    figures = unpack(page)
    assert len(re.findall(r'<div id="figure-\d+"', page)) == expected == len(figures) > 0
    text = page + json.dumps(figures, ensure_ascii=False)
    for needle in (
        "Comparison of the variants",
        "ranking by maximum pseudo-damage (lower is better) with the hot spots",
        "motion volumes at 5 mm",
        "damage hot spots",
        "Run short (quasistatic)",
        "clip reactions",
        "clip b (engine)",  # clip labelled with its body in the 3D view (hover)
        "body engine → b",  # the body marked with the clips it carries
        "natural frequencies of the mounted cable; excited band",
        'aria-label="natural frequencies of hose over the excitation spectrum"',
        'aria-label="rainflow matrix of hose"',
        "fatigue analysis (LDA)",
        'aria-label="motion volumes of the runs"',  # paper Fig. 1: the volumes overlaid
    ):
        assert in_report(text, needle), needle
    # The ranking is the LDA's comparison of the two damage files, worst ratio included.
    cmp = compare(files[2:], labels=["long", "short"])
    worst = cmp.variants[-1]
    row = re.search(rf"<td>2</td><td>{worst.label}</td><td>([^<]+)</td><td>([^<]+)</td>", text)
    assert row and float(row[1]) == pytest.approx(worst.max_damage, rel=1e-3)
    assert float(row[2]) == pytest.approx(worst.ratio, rel=1e-3) and worst.ratio > 1


def test_damage_files_attach_to_the_results_they_were_made_from(files, tmp_path):
    import shutil as sh

    import h5py
    from cablelife.lda import load_damage
    from cablelife.report.cli import report_runs

    runs = report_runs(files)  # damage files given as long, short
    assert [r.label for r in runs] == ["short", "long"]
    for r in runs:
        assert r.damage.source.endswith(f"{r.label}.h5")
        assert r.damage_of("hose")[0].label == r.label
    # A damage file whose source is not at hand attaches in order.
    moved = sh.copy(files[3], tmp_path / "x.damage.h5")
    with h5py.File(moved, "a") as f:
        f.attrs["source"] = "elsewhere/run.h5"
    runs = report_runs([files[0], moved])
    assert runs[0].damage.source == "elsewhere/run.h5"
    assert load_damage(moved).max_damage == runs[0].damage.max_damage
    with pytest.raises(ValueError, match="3 damage files for 2 results"):
        report_runs([*files, moved])


def test_ranking_falls_back_to_bending_with_the_reason(files):
    from cablelife.lda import WohlerCurve, analyse
    from cablelife.report import ReportRun, build_report
    from cablelife.results import load_result

    a, b = (load_result(p) for p in files[:2])
    page = build_report([ReportRun("A", a), ReportRun("B", b, files[2])], voxel=None, frames=2)
    assert "no damage ranking: no damage file for A" in page
    assert "ranking by maximum bending moment" in page
    other = analyse(b, curve=WohlerCurve(k=4.0, alpha=1e30), sampling_check=False)
    page = build_report([ReportRun("A", a, files[3]), ReportRun("B", b, other)], voxel=None)
    assert "no damage ranking: variant &#x27;B&#x27; was analysed with other settings" in page


def test_report_bad_input(files, tmp_path):
    import typer
    from cablelife.report.cli import report_command
    from typer.testing import CliRunner

    app = typer.Typer()
    app.command()(report_command)
    run = CliRunner().invoke(app, [str(files[2]), "-o", str(tmp_path / "r.html")])
    assert run.exit_code == 2 and "at least one result file" in run.output
    run = CliRunner().invoke(app, [str(tmp_path / "missing.h5")])
    assert run.exit_code == 2 and "does not exist" in run.output


@pytest.fixture(scope="module")
def mixed_report(files, dynamic_files, tmp_path_factory):
    """A report of runs in two modes (short and long quasistatic, short dynamic)."""
    from cablelife.report.cli import report_runs
    from cablelife.report.html import write_report

    out = tmp_path_factory.mktemp("mixed") / "report.html"
    runs = report_runs([*files, *dynamic_files])
    return write_report(out, runs, frames=6, voxel=0.005)


# Per damage picture (3D): the range of log10 damage drawn on the moving cable against the
# colour range; per ranking table: its caption and the runs it ranks.
PAGE_FACTS = {
    "damage": """JSON.stringify([...document.querySelectorAll('.js-plotly-plot')].filter(
        d => d.data && d.data.some(t => t.type === 'mesh3d' && t.name === 'damage')).map(d => {
        const i = d.data.findIndex(t => t.name === 'damage');
        const b = [...d.querySelectorAll('.updatemenu-button')].find(
            e => e.textContent === 'damage on the surface');
        b.dispatchEvent(new MouseEvent('click', {bubbles: true}));  // the button a person clicks
        const t = d._fullData[i], v = Array.from(t.intensity);
        if (!t.visible || d._fullData[0].visible) return {visible: false};
        return {min: Math.min(...v), max: Math.max(...v), cmin: t.cmin, cmax: t.cmax,
                distinct: new Set(v.map(x => Math.round(x * 4))).size}}))""",
    "rankings": """JSON.stringify([...document.querySelectorAll('table.ranking')].map(t => ({
        caption: t.caption.textContent,
        runs: [...t.querySelectorAll('tbody tr')].map(r => r.cells[1].textContent)
              .filter(x => x)})))""",
}


def test_report_as_a_person_sees_it_in_headless_chromium(mixed_report):
    """Every figure renders without script errors, no two text boxes overlap, no text is cut
    off at a figure's edge (the animated views' slider labels were), each ranking
    table ranks runs of one mode, the damage colours span the moving cable; screenshots of
    the whole page are kept as test artifacts (look at them)."""
    from cablelife.report.browser import check_page, find_browser

    if find_browser() is None:
        pytest.skip("chromium not found (Debian package 'chromium'; .ci/run should install it)")
    shots = ARTIFACTS / "report"
    for old in shots.glob("report-*.png"):
        old.unlink()
    seen = check_page(mixed_report, width=1100, height=900, screenshots=shots, evaluate=PAGE_FACTS)
    assert seen.errors == []
    assert seen.rendered == seen.expected > 0
    assert seen.overlaps == [], seen.overlaps
    assert seen.clipped == [], seen.clipped  # no label cut off at a figure's edge
    rankings = json.loads(seen.values["rankings"])
    assert [r["caption"].split(" runs:")[0] for r in rankings] == ["dynamic", "quasistatic"]
    assert rankings[0]["runs"] == ["short-dynamic"]
    assert sorted(rankings[1]["runs"]) == ["long", "short"]
    damage = json.loads(seen.values["damage"])
    assert len(damage) == 3
    for d in damage:
        # the floor is 1e-6 of the maximum: six decades of colour, and the cable (all of it
        # moves here) uses more than one of them
        assert d["cmax"] - d["cmin"] == pytest.approx(6.0)
        assert d["max"] == pytest.approx(d["cmax"], abs=1e-3)
        assert d["max"] - d["min"] > 1.0 and d["distinct"] > 4
    assert len(seen.screenshots) > 3 and all(p.stat().st_size > 10_000 for p in seen.screenshots)
    page = mixed_report.read_text()
    assert "inertia factor: dynamic over quasistatic maximum damage of each variant" in page


def test_compare_refuses_runs_of_different_modes(files, dynamic_files):
    from cablelife.lda import compare

    with pytest.raises(ValueError, match="different modes.*short-dynamic: dynamic"):
        compare([files[3], dynamic_files[1]])
    forced = compare([files[3], dynamic_files[1]], check_modes=False)
    assert sorted(v.label for v in forced.variants) == ["short", "short-dynamic"]


def test_body_poses_follow_the_motion_and_carry_their_clips():
    """The engine's origin moves 50 mm up and down; clip b rides on it rigidly, so the
    distance from the body origin to the cable's clip node stays constant."""
    from cablelife.report import cable_figure
    from cablelife.report.scene_data import body_poses, result_scene
    from cablelife.scene import scene_from_dict
    from cablelife.simulate import simulate

    res = simulate(scene_from_dict(variant_scene(duration=1.0)))
    cable = res.cable
    (engine,) = body_poses(result_scene(res.scene_toml), "hose", cable.time, res.mode)
    assert engine.name == "engine" and engine.clips == ["b"] and engine.moving
    z = engine.origin[:, 2]
    np.testing.assert_allclose(z, 0.05 * np.sin(2 * np.pi * cable.time), atol=1e-12)
    np.testing.assert_allclose(engine.axes, np.broadcast_to(np.eye(3), engine.axes.shape))
    arm = np.linalg.norm(cable.positions[:, -1] - engine.origin, axis=1)
    np.testing.assert_allclose(arm, arm[0], rtol=1e-9)
    rest = body_poses(result_scene(res.scene_toml), "hose", cable.time, "static")[0]
    assert not rest.moving and np.all(rest.origin == [0.8, 0.2, 0.0])
    # The 3D view animates the body with the cable: its origin at each frame's time.
    fig = cable_figure(cable, frames=3, scene_toml=res.scene_toml, mode=res.mode)
    assert len(fig["frames"]) == 3
    for frame in fig["frames"]:
        k = int(np.argmin(np.abs(cable.time - float(frame["name"]))))
        body = next(t for t in frame["data"] if t.get("name") == "bodies")
        np.testing.assert_allclose([body[a][0] for a in "xyz"], engine.origin[k])
        link = next(t for t in frame["data"] if t.get("name") == "body → clip")
        np.testing.assert_allclose([link[a][1] for a in "xyz"], cable.positions[k, -1])
    go = pytest.importorskip("plotly.graph_objects")
    assert len(go.Figure(fig).frames) == 3  # a valid plotly figure, frames included


def test_excitation_psd_holds_the_clip_acceleration_variance():
    """Acceleration sines of 2 m/s² at 2 Hz (z) and 1 m/s² at 5 Hz (x) on the engine: the PSD
    at clip b peaks at 2 Hz and integrates to the variance 2²/2 + 1²/2 = 2.5 (m/s²)²."""
    from cablelife.report.scene_data import excitation_psd
    from cablelife.scene import SceneError, scene_from_dict

    d = variant_scene(duration=8.0)
    d["simulation"]["time_step"] = 0.005
    sine = {"type": "sine", "quantity": "acceleration"}
    d["bodies"][0]["motion"] = [
        {"channel": "z", "signal": {**sine, "amplitude": 2.0, "frequency": 2.0}},
        {"channel": "x", "signal": {**sine, "amplitude": 1.0, "frequency": 5.0}},
    ]
    scene = scene_from_dict(d)
    e = excitation_psd(scene, "hose", "quasistatic")
    assert e.labels == ["clip b (engine)"] and e.psd.shape == (1, e.frequency.size)
    df = e.frequency[1] - e.frequency[0]
    assert abs(e.frequency[e.psd[0].argmax()] - 2.0) <= df
    assert np.sum(e.psd[0]) * df == pytest.approx(2.5, rel=0.02)
    with pytest.raises(SceneError, match="static run has no excitation"):
        excitation_psd(scene, "hose", "static")
    d["bodies"][0]["motion"] = []
    with pytest.raises(SceneError, match="no clip of cable 'hose' sits on a moving body"):
        excitation_psd(scene_from_dict(d), "hose", "quasistatic")


def test_interactive_plots_draw_what_the_matplotlib_plots_draw(files):
    """The report's plotly versions redraw the matplotlib artists: the same line data and
    styles, bands, rule lines, log axes, spans, heatmap values and labels."""
    from cablelife.plots import (
        Run,
        check_bend_radius,
        damage_maps,
        plot_bend_radius,
        plot_envelopes,
        plot_frequencies_over_spectrum,
        plot_maxima_over_time,
        plot_rainflow_matrix,
    )
    from cablelife.report.mpl_plotly import to_plotly
    from cablelife.results import load_result

    cable = load_result(files[0]).cable
    runs = [Run("qs", cable, "quasistatic")]
    mpl = plot_maxima_over_time(runs)
    fig = to_plotly(mpl)
    assert (
        len(fig.data) == 4
        and fig.layout.title.text == "largest magnitude over the spans that move, over time"
    )
    for ax, trace in zip(mpl.axes, fig.data, strict=True):
        line = ax.get_lines()[0]
        np.testing.assert_allclose(trace.x, line.get_xdata())
        np.testing.assert_allclose(trace.y, line.get_ydata())
        assert trace.line.dash == "dash" and trace.name == "qs (quasistatic)"
    assert [t.showlegend for t in fig.data] == [True, False, False, False]

    fig = to_plotly(plot_envelopes(runs))
    assert sum(t.fill == "toself" for t in fig.data) == 4  # one band per quantity

    chk = check_bend_radius(cable, 1e3)  # a rule everything breaks in stretches
    fig = to_plotly(plot_bend_radius(runs, 1e3))
    assert fig.layout.yaxis.type == "log"
    rule = [t for t in fig.data if t.mode == "lines" and t.line.dash == "dot" and t.y[0]]
    assert tuple(rule[0].y) == (chk.allowed, chk.allowed)
    spans = [t for t in fig.data if t.fill == "toself"]
    assert len(spans) == len(chk.violations) > 0
    assert [min(t.x) for t in spans] == pytest.approx([v[0] for v in chk.violations])

    fig = to_plotly(plot_frequencies_over_spectrum([3.0, 300.0], [1.0, 10.0, 100.0], [1, 2, 1]))
    lines = [t for t in fig.data if t.x[0] == t.x[1]]
    assert [(t.x[0], t.line.color) for t in lines] == [(3.0, "#ff0000"), (300.0, "#808080")]
    assert fig.layout.xaxis.type == "log" and "mode 1: 3 Hz" in [t.name for t in fig.data]

    _, rf = damage_maps(files[2])["hose"]
    heat = to_plotly(plot_rainflow_matrix(rf)).data[0]
    z = np.array(heat.z, dtype=float)
    np.testing.assert_allclose(10 ** z[rf.counts > 0], rf.counts[rf.counts > 0])
    assert np.isnan(z[rf.counts == 0]).all()
    assert heat.x[-1] == pytest.approx(rf.mean_edges[-1] / 1e6)  # MPa


def test_an_unresolved_impact_is_in_the_report_as_on_the_terminal(dynamic_files):
    """The report says what the run's ImpactWarning said (an impact the step guard accepted
    unresolved, saved per step in the solver data), in the run's section; nothing without."""
    import html

    from cablelife.report import ReportRun, build_report
    from cablelife.results import load_result
    from cablelife.validity import impact_messages

    res = load_result(dynamic_files[0])
    page = build_report([ReportRun("D", res)], voxel=None, frames=2)
    assert "an impact on the geometry" not in page
    c = res.cable
    c.solver["unresolved_gain"] = np.zeros(c.n_steps)
    c.solver["unresolved_gain"][7] = 0.0123
    c.solver["impact_dissipation"] = np.zeros(c.n_steps)
    c.solver["impact_dissipation"][2] = 0.0031
    page = build_report([ReportRun("D", res)], voxel=None, frames=2)
    messages = impact_messages(
        "cable 'hose'", c.solver["unresolved_gain"], c.time, c.solver["impact_dissipation"]
    )
    assert len(messages) == 2
    for message in messages:
        assert html.escape(message) in page
