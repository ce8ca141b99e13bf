"""Plots: the data drawn is the data asked for, PNGs are written, bad input is named."""

from __future__ import annotations

import copy

import numpy as np
import pytest
from cablelife.plots import (
    DamageMap,
    RainflowMatrix,
    Run,
    check_bend_radius,
    damage_maps,
    plot_bend_radius,
    plot_clip_reactions,
    plot_damage_along_cable,
    plot_envelopes,
    plot_frequencies_over_spectrum,
    plot_maxima_over_time,
    plot_rainflow_matrix,
    save_png,
)
from cablelife.plots.runs import extreme_along
from cablelife.plots.spectrum import excited_band

PNG = b"\x89PNG\r\n\x1a\n"


@pytest.fixture(scope="module")
def runs():
    """A quasistatic run, and the same arrays labelled as a dynamic run with scaled loads."""
    from cablelife.scene import scene_from_dict
    from cablelife.simulate import simulate
    from conftest import BASE

    d = copy.deepcopy(BASE)
    d["simulation"].update(mode="quasistatic", duration=1.0, time_step=0.05)
    sine = {"type": "sine", "amplitude": 0.05, "frequency": 1.0}
    d["bodies"] = [{"name": "engine", "motion": [{"channel": "z", "signal": sine}]}]
    d["cables"][0]["clips"][1]["body"] = "engine"
    qs = simulate(scene_from_dict(d)).cable
    dyn = copy.deepcopy(qs)
    dyn.forces = dyn.forces * 1.5
    dyn.moments = dyn.moments * 1.5
    return [Run("variant A", qs, "quasistatic"), Run("variant A", dyn, "dynamic")]


def test_extreme_along_keeps_the_sign():
    v = np.array([[1.0, -3.0, 2.0], [0.5, 0.2, 0.1]])
    np.testing.assert_array_equal(extreme_along(v), [-3.0, 0.5])


def test_maxima_over_time_draws_fig2(runs, tmp_path):
    fig = plot_maxima_over_time(runs)
    axes = fig.axes
    assert len(axes) == 4
    qs, dyn = runs
    tension = axes[1].get_lines()
    assert [ln.get_linestyle() for ln in tension] == ["--", "-"]
    # one variant: one colour, the mode told by the line style
    assert tension[0].get_color() == tension[1].get_color()
    np.testing.assert_allclose(tension[0].get_ydata(), np.abs(qs.cable.forces[..., 2]).max(1))
    bending = axes[2].get_lines()[1].get_ydata()
    inner = np.hypot(*qs.cable.moments[:, 1:-1, :2].T).T  # nodes strictly between the clips
    np.testing.assert_allclose(bending, 1.5 * inner.max(1))
    assert axes[3].get_ylabel().startswith("|torsion M3|")
    path = save_png(fig, tmp_path / "fig2.png")
    assert path.read_bytes()[:8] == PNG


@pytest.fixture(scope="module")
def three_clips():
    """A cable whose first span lies between two clips on the world (it does not move) and
    whose second span ends on a moving body: runs of variants A and B."""
    from cablelife.scene import scene_from_dict
    from cablelife.simulate import simulate
    from conftest import BASE

    d = copy.deepcopy(BASE)
    d["simulation"].update(mode="quasistatic", duration=1.0, time_step=0.05)
    sine = {"type": "sine", "amplitude": 0.05, "frequency": 1.0}
    d["bodies"] = [{"name": "engine", "motion": [{"channel": "z", "signal": sine}]}]
    clips = d["cables"][0]["clips"]
    clips[1]["body"] = "engine"
    middle = {"name": "m", "s": 0.4, "position": [0.35, 0.05, 0.0], "direction": [1.0, 0.0, 0.0],
              "normal": [0.0, 0.0, 1.0]}  # fmt: skip
    clips.insert(1, middle)
    qs = simulate(scene_from_dict(d)).cable
    dyn = copy.deepcopy(qs)
    s = 0.5 * (qs.arc_length[1:] + qs.arc_length[:-1])
    dyn.forces[:, s < 0.4, :] = -1e3  # large constant loads in the span at rest
    b = copy.deepcopy(qs)
    b.moments = -2.0 * b.moments  # torsion of the other sign
    return [Run("A-quasistatic", qs, "quasistatic"), Run("A-dynamic", dyn, "dynamic"),
            Run("B-dynamic", b, "dynamic")]  # fmt: skip


def test_maxima_over_time_plots_magnitudes_over_the_moving_spans(three_clips):
    """Fig. 2 (PNG) as the report draws it: magnitudes (torsion of either sign positive), over
    the spans that move (the span at rest with its large constant loads left out), one colour
    per variant (A's quasistatic and dynamic runs share one), dashed quasistatic."""
    fig = plot_maxima_over_time(three_clips)
    shear, tension, _, torsion = (ax.get_lines() for ax in fig.axes)
    qs, dyn, b = (r.cable for r in three_clips)
    s = 0.5 * (qs.arc_length[1:] + qs.arc_length[:-1])
    moving = s > 0.4
    np.testing.assert_allclose(tension[1].get_ydata(), np.abs(dyn.forces[:, moving, 2]).max(1))
    assert tension[1].get_ydata().max() < 1e3  # the span at rest is not drawn
    inner = (qs.arc_length > 0.4 + 1e-9) & (qs.arc_length < 1.0 - 1e-9)
    np.testing.assert_allclose(torsion[2].get_ydata(), 2 * np.abs(qs.moments[:, inner, 2]).max(1))
    assert all((ln.get_ydata() >= 0).all() for ax in fig.axes for ln in ax.get_lines())
    colours = [ln.get_color() for ln in shear]
    assert colours[0] == colours[1] != colours[2]
    assert [ln.get_linestyle() for ln in shear] == ["--", "-", "-"]
    assert fig.get_suptitle() == "largest magnitude over the spans that move, over time"


def test_envelopes_bound_every_step(runs):
    fig = plot_envelopes(runs)
    shear_hi = fig.axes[0].get_lines()[0].get_ydata()
    f = runs[0].cable.forces
    assert np.all(shear_hi >= np.hypot(f[..., 0], f[..., 1]) - 1e-12)
    assert len(fig.axes[0].get_lines()[0].get_xdata()) == f.shape[1]  # edge midpoints


def test_bend_radius_rule(runs):
    c = runs[0].cable
    chk = check_bend_radius(c, factor=10)
    assert chk.allowed == pytest.approx(10 * 2 * c.section["outer_radius"])
    np.testing.assert_allclose(chk.min_radius, c.bend_radius().min(axis=0))
    strict = check_bend_radius(c, factor=1e4)  # allowed 100 m: everything bent violates
    assert not strict.ok and strict.violations[0][2] == pytest.approx(chk.min_radius.min())
    fig = plot_bend_radius(runs, factor=10)
    assert fig.axes[0].get_yscale() == "log"
    with pytest.raises(ValueError, match="factor = -1"):
        check_bend_radius(c, factor=-1)


def test_clip_reactions(runs):
    fig = plot_clip_reactions(runs)
    assert len(fig.axes) == 2 * len(runs[0].cable.clips)
    force_a = fig.axes[0].get_lines()[0].get_ydata()
    np.testing.assert_allclose(force_a, np.linalg.norm(runs[0].cable.clips["a"].force, axis=1))


def test_frequencies_over_spectrum():
    f = np.geomspace(10, 2000, 50)
    fig = plot_frequencies_over_spectrum([3.0, 25.0, 140.0], f, 10 / (1 + (f / 300) ** 2))
    ax = fig.axes[0]
    colours = [ln.get_color() for ln in ax.get_lines()[1:]]
    assert colours == ["gray", "red", "red"]  # 3 Hz lies below the excited band
    assert ax.get_xlim()[0] < 3.0  # every natural frequency is on the axis
    # With a level the band ends where the PSD falls below 0.1 × its peak (f = 900 Hz here).
    assert excited_band(f, 10 / (1 + (f / 300) ** 2), 0.1)[1] == pytest.approx(900, rel=0.1)
    fig = plot_frequencies_over_spectrum(
        [25.0, 1500.0], f, 10 / (1 + (f / 300) ** 2), band_level=0.1, labels=["clip b"]
    )
    assert [ln.get_color() for ln in fig.axes[0].get_lines()[1:]] == ["red", "gray"]
    assert fig.axes[0].get_legend().get_texts()[0].get_text() == "clip b"
    with pytest.raises(ValueError, match="psd has shape"):
        plot_frequencies_over_spectrum([3.0], f, np.ones(3))
    with pytest.raises(ValueError, match="labels: 2 given for 1 PSD channels"):
        plot_frequencies_over_spectrum([3.0], f, np.ones(50), labels=["a", "b"])


def test_rainflow_and_damage(tmp_path):
    m = RainflowMatrix(np.arange(5.0), np.linspace(-2, 2, 4), np.arange(12.0).reshape(4, 3))
    save_png(plot_rainflow_matrix(m), tmp_path / "rf.png")
    with pytest.raises(ValueError, match=r"counts has shape \(2, 2\): must be \(4, 3\)"):
        RainflowMatrix(np.arange(5.0), np.linspace(-2, 2, 4), np.ones((2, 2)))
    s = np.linspace(0, 1, 51)
    g = np.linspace(0, 2 * np.pi, 16, endpoint=False)
    dmg = np.exp(-((s[:, None] - 0.2) ** 2) / 0.001) * (1 + np.cos(g - 1.0)) + 1e-6
    dmg[40] = 0.5 * dmg.max()
    dm = DamageMap(s, g, dmg, "A")
    spots = dm.hot_spots(2)
    assert spots[0].arc_length == pytest.approx(0.2) and spots[0].angle == pytest.approx(g[3])
    assert spots[1].arc_length == pytest.approx(0.8)
    save_png(plot_damage_along_cable([dm], clips={"a": 0.0, "b": 1.0}), tmp_path / "d.png")
    with pytest.raises(ValueError, match="damage has shape"):
        DamageMap(s, g, dmg[:, :3])


def test_damage_on_other_stations_and_angles():
    """Exact at the map's own points, linear in s, periodic-linear in γ across 2π."""
    g = np.deg2rad([0.0, 90.0, 180.0, 270.0])
    dm = DamageMap([0.0, 1.0], g, [[0.0, 1.0, 2.0, 3.0], [4.0, 5.0, 6.0, 7.0]])
    np.testing.assert_allclose(dm.on_surface([0.0, 1.0], g), dm.damage)
    np.testing.assert_allclose(dm.on_surface([0.5], np.deg2rad([45.0])), [[2.5]])
    np.testing.assert_allclose(dm.on_surface([0.0], np.deg2rad([315.0, -45.0])), [[1.5, 1.5]])
    with pytest.raises(ValueError, match="spans s = 0 … 1 m, but the cable spans 0 … 0.9 m"):
        dm.check_fits(np.linspace(0, 0.9, 4))


def test_damage_maps_read_the_lda_damage_file(tmp_path):
    """The plots take the LDA's own file through its reader: the map (max over planes), the
    hot spots (with plane and nearest clip) and the rainflow matrix of the critical series."""
    from cablelife.lda import analyse
    from test_lda_pipeline import make_result

    a = analyse(make_result())
    maps = damage_maps(a.save(tmp_path / "a.damage.h5"), "variant A")
    dm, rf = maps["harness"]
    cd = a.cables["harness"]
    np.testing.assert_array_equal(dm.damage, cd.damage)
    np.testing.assert_array_equal(dm.angle, cd.angles)
    assert dm.label == "variant A"
    for mine, theirs in zip(dm.hot_spots(5), cd.hot_spots(5), strict=True):
        assert mine.arc_length == theirs.arc_length and mine.damage == theirs.damage
        assert np.degrees(mine.angle) == pytest.approx(theirs.angle)
        assert mine.nearest_clip == theirs.nearest_clip
    assert "clip C" in dm.hot_spots(1)[0].describe()
    np.testing.assert_array_equal(rf.counts, cd.rainflow.counts)
    fig = plot_rainflow_matrix(rf)
    assert fig.axes[0].get_ylabel() == "range [MPa]"
    assert "γ = 90°" in fig.axes[0].get_title() and "10 cycles" in fig.axes[0].get_title()
    with pytest.raises(TypeError, match="give a DamageAnalysis or the path"):
        damage_maps(42)
    with pytest.raises(ValueError, match="not a cablelife damage file"):
        damage_maps(make_result().save(tmp_path / "result.h5"))
