"""Parts of the report that decide what a person sees: decimation keeps every peak, constant
series get a sensible axis, the excited band comes from the signal definitions, runs belong to
variants, a span between clips on one body is at rest, numerical zeros show as 0."""

from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]


def test_minmax_keeps_every_peak_within_the_point_budget():
    from cablelife.report.decimate import minmax

    t = np.linspace(0.0, 5.0, 5001)
    y = np.sin(2 * np.pi * 37 * t) + np.random.default_rng(1).normal(0, 0.1, t.size)
    y[1234] = 9.0  # a single spike
    x2, y2 = minmax(t, y, 1000)
    assert x2.size <= 1000 and np.all(np.diff(x2) > 0)
    assert y2.max() == y.max() == 9.0 and y2.min() == y.min()
    # every bucket's extremes are kept: the envelope over 10-sample windows is the same
    for a in range(0, 5000, 500):
        sel = (t >= t[a]) & (t < t[a] + 0.5)
        keep = (x2 >= t[a]) & (x2 < t[a] + 0.5)
        assert y2[keep].max() == y[sel].max()
    short = np.arange(10.0)
    assert minmax(short, short)[0] is short


def test_constant_series_get_a_readable_range():
    from cablelife.report.decimate import nice_range

    y = 0.123456789 + np.array([0.0, 1e-16, -2e-16, 0.0])  # round-off "noise"
    lo, hi = nice_range(y)
    assert lo < 0.1234 and hi > 0.1235 and hi - lo == pytest.approx(0.2 * 0.123456789)
    assert nice_range(np.zeros(5)) == [-1.0, 1.0]
    assert nice_range(np.array([0.0, 1.0])) is None


def test_excited_band_of_the_demo_is_the_band_of_its_psd_signals():
    from cablelife.report.scene_data import excited_band
    from cablelife.scene import load_scene

    scene = load_scene(ROOT / "examples" / "clip-variants" / "scene.toml")
    assert excited_band(scene, "harness") == (10.0, 100.0)


def test_runs_belong_to_variants_by_label():
    from cablelife.report.html import _g, variant_of

    assert variant_of("A-dynamic", "dynamic") == "A"
    assert variant_of("B_quasistatic", "quasistatic") == "B"
    assert variant_of("long (dynamic)", "dynamic") == "long"
    assert variant_of("dynamic", "dynamic") == "dynamic"
    # a numerical zero (2.4e-7 N next to forces of 6 N) shows as 0
    assert _g(2.4e-7, "N", 6.5) == "0 N" and _g(0.11, "N", 6.5) == "0.11 N"


def test_a_span_between_clips_at_rest_does_not_move():
    from cablelife.plots.spans import cable_spans
    from cablelife.scene import scene_from_dict
    from cablelife.simulate import simulate
    from conftest import BASE

    d = {**BASE, "simulation": {"mode": "quasistatic", "duration": 0.5, "time_step": 0.05}}
    d["cables"] = [dict(BASE["cables"][0])]
    clips = [dict(c) for c in BASE["cables"][0]["clips"]]
    clips.insert(1, {**clips[0], "name": "m", "s": 0.4, "position": [0.38, 0.0, 0.0]})
    clips[2] = {**clips[2], "body": "engine"}
    d["cables"][0]["clips"] = clips
    sine = {"type": "sine", "amplitude": 0.02, "frequency": 1.0}
    d["bodies"] = [{"name": "engine", "origin": [0.8, 0.2, 0.0],
                    "motion": [{"channel": "z", "signal": sine}]}]  # fmt: skip
    spans = {sp.name: sp.moves for sp in cable_spans(simulate(scene_from_dict(d)).cable)}
    assert spans == {"a → m": False, "m → b": True}


@pytest.mark.parametrize(("n", "nperseg"), [(5001, 625), (4000, 512), (777, 777), (300, 101)])
def test_welch_is_scipys(n, nperseg):
    """The report's Welch PSD (numpy; scipy.signal costs 1.6 s to import) equals scipy's for
    even and odd segments, a record of one segment and one with a remainder."""
    from cablelife.report.scene_data import welch
    from scipy.signal import welch as scipy_welch

    x = np.random.default_rng(3).normal(size=(n, 2, 3)) + np.linspace(0, 1, n)[:, None, None]
    f, p = welch(x, 250.0, nperseg)
    g, q = scipy_welch(x, fs=250.0, nperseg=nperseg, axis=0)
    np.testing.assert_allclose(f, g, rtol=1e-12)
    np.testing.assert_allclose(p, q, rtol=1e-10, atol=1e-14 * q.max())


def _views_of(n_frames: int, seed: float, times=None):
    """A small 3D view of a moving cable (cable_figure with a second view behind a button)."""
    import copy

    from cablelife.report.scene3d import cable_figure, with_view
    from cablelife.scene import scene_from_dict
    from cablelife.simulate import simulate
    from conftest import BASE

    d = copy.deepcopy(BASE)
    d["simulation"].update(mode="quasistatic", duration=times or 0.2, time_step=0.05)
    sine = {"type": "sine", "amplitude": seed, "frequency": 1.0}
    d["bodies"] = [{"name": "engine", "motion": [{"channel": "z", "signal": sine}]}]
    d["cables"][0]["clips"][1]["body"] = "engine"
    res = simulate(scene_from_dict(d))
    view = cable_figure(res.cable, frames=n_frames, scene_toml=res.scene_toml, mode=res.mode)
    extra = {"type": "scatter3d", "x": [0.0], "y": [0.0], "z": [0.0], "name": "extra"}
    return with_view(view, [extra], "extra view")


def test_one_3d_view_for_the_runs_of_a_variant():
    """merge_runs: both runs' views in one scene, a drop-down "<run>: <view>" whose every entry
    shows exactly that run's traces of that view, the slider's frames moving both runs'
    traces; runs saved at other times are not merged."""
    from cablelife.report.scene3d import merge_runs

    a, b = _views_of(3, 0.01), _views_of(3, 0.02)
    na, nb = len(a["data"]), len(b["data"])
    b_frame_traces = b["frames"][1]["traces"]
    m = merge_runs(copy_of(a), copy_of(b), "A-dynamic", "A-quasistatic")
    assert len(m["data"]) == na + nb
    (menu,) = [u for u in m["layout"]["updatemenus"] if u.get("name") == "views"]
    assert menu["type"] == "dropdown"
    labels = [bt["label"] for bt in menu["buttons"]]
    assert labels[0].startswith("A-dynamic: ") and labels[-1] == "A-quasistatic: extra view"
    for bt in menu["buttons"]:
        vis = bt["args"][0]["visible"]
        assert len(vis) == na + nb
        mine = vis[:na] if bt["label"].startswith("A-dynamic") else vis[na:]
        other = vis[na:] if bt["label"].startswith("A-dynamic") else vis[:na]
        assert any(mine) and not any(other)
    assert all(t.get("visible") is False for t in m["data"][na:])  # A-dynamic shown first
    f = m["frames"][1]
    assert f["traces"][-len(b_frame_traces) :] == [na + i for i in b_frame_traces]
    assert len(f["data"]) == len(f["traces"])
    assert merge_runs(_views_of(3, 0.01), _views_of(3, 0.02, times=0.3), "a", "b") is None


def copy_of(view: dict) -> dict:
    import copy

    return copy.deepcopy(view)


def test_one_3d_view_for_every_run():
    """merge_views of three runs: one scene, a drop-down entry per run and view showing only
    that run's traces, the frames moving every run's traces (indices shifted per run), the
    first run shown, the title naming every run; runs saved at other times are not merged."""
    from cablelife.report.scene3d import merge_views

    views = [_views_of(3, 0.01), _views_of(3, 0.02), _views_of(3, 0.03)]
    sizes = [len(v["data"]) for v in views]
    starts = [0, sizes[0], sizes[0] + sizes[1]]
    frame_traces = [v["frames"][1]["traces"] for v in views]
    labels = ["A-dynamic", "B-dynamic", "A-quasistatic"]
    m = merge_views(list(zip(labels, map(copy_of, views), strict=True)))
    assert len(m["data"]) == sum(sizes)
    (menu,) = [u for u in m["layout"]["updatemenus"] if u.get("name") == "views"]
    assert len(menu["buttons"]) == 3 * 2  # the quantity and "extra view" of each run
    for bt in menu["buttons"]:
        vis = bt["args"][0]["visible"]
        assert len(vis) == sum(sizes)
        k = labels.index(bt["label"].split(": ")[0])
        mine = vis[starts[k] : starts[k] + sizes[k]]
        assert any(mine) and sum(vis) == sum(mine)
    assert m["data"][0].get("visible") is not False
    assert all(t.get("visible") is False for t in m["data"][sizes[0] :])
    f = m["frames"][1]
    assert f["traces"] == [i + s for ft, s in zip(frame_traces, starts, strict=True) for i in ft]
    assert len(f["data"]) == len(f["traces"])
    assert all(x in m["layout"]["title"]["text"] for x in labels)
    other = [("a", _views_of(3, 0.01)), ("b", _views_of(3, 0.02, times=0.3))]
    assert merge_views(other) is None
