"""LDA pipeline on synthetic results with known section loads: damage map, hot spots,
damage files, comparison of variants, sampling warning and the CLI functions."""

import math
import warnings

import numpy as np
import pytest
import typer
from cablelife.lda import (
    CircularSection,
    SamplingWarning,
    WohlerCurve,
    analyse,
    compare,
    load_damage,
)
from cablelife.lda.cli import compare_command, lda_command
from cablelife.lda.stations import node_forces, section_loads, station_indices
from cablelife.results import CableResult, ClipReaction, Result, save_result
from typer.testing import CliRunner

A = 0.004  # m, outer radius
INERTIA = math.pi * A**4 / 4
POLAR = 2 * INERTIA
DT = 1e-3
F = 5.0  # Hz
PERIODS = 10
SIGMA_A = 2e6  # Pa, bending stress amplitude at node 3
TAU_A = 1.5e6  # Pa, torsion shear amplitude at node 6


def make_result(
    scale=1.0, f=F, n_edges=10, clips=(("A", 0.0), ("C", 0.35), ("B", 1.0)), periods=PERIODS
):
    """Straight 1 m cable, loads cos(2π f t) over whole periods: bending M1 at node 3, torsion
    M3 at node 6, a weaker bending M2 at node 8."""
    t = np.arange(int(round(periods / f / DT)) + 1) * DT
    c = np.cos(2 * np.pi * f * t)
    n_t = t.size
    moments = np.zeros((n_t, n_edges + 1, 3))
    forces = np.zeros((n_t, n_edges, 3))
    moments[:, 3, 0] = scale * SIGMA_A * INERTIA / A * c
    moments[:, 6, 2] = scale * TAU_A * POLAR / A * c
    moments[:, 8, 1] = 0.5 * scale * SIGMA_A * INERTIA / A * c
    quats = np.zeros((n_t, n_edges, 4))
    quats[..., 0] = 1.0
    s = np.linspace(0.0, 1.0, n_edges + 1)
    pos = np.zeros((n_t, n_edges + 1, 3))
    pos[..., 2] = s
    cable = CableResult(
        name="harness",
        time=t,
        arc_length=s,
        positions=pos,
        quaternions=quats,
        forces=forces,
        moments=moments,
        clips={n: ClipReaction(n, sc, np.zeros((n_t, 3)), np.zeros((n_t, 3))) for n, sc in clips},
        section={
            "shape": "circle",
            "outer_radius": A,
            "inner_radius": 0.0,
            "poisson_ratio": 0.3,
            "from_measured": False,
        },
    )
    return Result(mode="dynamic", cables={"harness": cable})


def pseudo(range_pa, cycles=PERIODS, k=5.0):
    return cycles * (range_pa / 1e6) ** k / 1e6


def test_damage_map_matches_the_analytical_constant_amplitude_damage():
    """cos loading over 10 whole periods = 10 cycles of range 2σ_a: D = 10 (2σ_a/1 MPa)^5/1e6
    at the bending maximum γ = 90° (plane φ = 0°), zero on the neutral axis γ = 0°; torsion
    on the 5° plane set peaks at φ = 45° with σ_n = τ."""
    res = analyse(make_result(), plane_step_deg=5.0)
    cd = res.cables["harness"]
    assert cd.damage.shape == (11, 16)
    assert cd.damage[3, 4] == pytest.approx(pseudo(2 * SIGMA_A), rel=1e-12)  # γ = 90°
    assert cd.damage[3, 12] == pytest.approx(pseudo(2 * SIGMA_A), rel=1e-12)  # γ = 270°
    assert cd.critical_plane[3, 4] == 0.0
    assert cd.damage[3, 0] < 1e-20 * cd.damage[3, 4]
    assert cd.damage[6].max() == pytest.approx(pseudo(2 * TAU_A), rel=1e-12)
    assert np.allclose(np.rad2deg(cd.critical_plane[6]), 45.0)
    assert res.max_damage == pytest.approx(pseudo(2 * SIGMA_A), rel=1e-12)
    assert np.all(cd.damage[[0, 1, 2, 4, 5, 7, 9, 10]] == 0.0)


def test_default_plane_step_underestimates_torsion_by_cos_10_deg_pow_k():
    res = analyse(make_result())
    d6 = res.cables["harness"].damage[6].max()
    assert d6 == pytest.approx(pseudo(2 * TAU_A * math.cos(math.radians(10))), rel=1e-12)


def test_hot_spots_with_nearest_clip():
    spots = analyse(make_result()).hot_spots(3)
    assert [h.section_index for h in spots] == [3, 6, 8]
    h = spots[0]
    assert h.arc_length == pytest.approx(0.3)
    assert h.angle == pytest.approx(90.0) and h.plane == 0.0
    assert h.nearest_clip == "C" and h.clip_distance == pytest.approx(0.05)
    assert "clip 'C'" in h.describe()


def test_section_subset_and_node_forces():
    r = make_result()
    idx, s, loads = section_loads(r.cable, step=4)
    assert idx.tolist() == [0, 4, 8, 10] and loads.shape == (4, r.cable.n_steps, 6)
    assert station_indices(11, indices=[8, 3]).tolist() == [3, 8]
    with pytest.raises(ValueError, match="section_step = 0"):
        station_indices(11, step=0)
    with pytest.raises(ValueError, match="node indices must lie in"):
        station_indices(11, indices=[11])
    f = np.arange(2 * 3 * 3, dtype=float).reshape(2, 3, 3)
    fn = node_forces(f)
    np.testing.assert_allclose(fn[:, 0], f[:, 0])
    np.testing.assert_allclose(fn[:, 1], 0.5 * (f[:, 0] + f[:, 1]))
    np.testing.assert_allclose(fn[:, 3], f[:, 2])
    sub = analyse(r, section_step=3)
    assert sub.cables["harness"].section_index.tolist() == [0, 3, 6, 9, 10]


def test_transverse_force_damage_uses_the_poisson_dependent_shear_factor():
    r = make_result(scale=0.0)
    c = np.cos(2 * np.pi * F * r.cable.time)
    r.cable.forces[:, :, 0] = 40.0 * c[:, None]  # F1 on every edge: node force 40 N
    res = analyse(r, plane_step_deg=5.0)
    kappa = CircularSection(A, 0.0, 0.3).shear_factor
    tau = kappa * 40.0 / (math.pi * A**2)
    assert res.max_damage == pytest.approx(pseudo(2 * tau), rel=1e-12)


def test_damage_file_roundtrip(tmp_path):
    res = analyse(make_result(), curve=WohlerCurve(k=4.0, alpha=1e30, knee_range=1e5))
    path = res.save(tmp_path / "v.damage.h5")
    back = load_damage(path)
    a, b = res.cables["harness"], back.cables["harness"]
    np.testing.assert_array_equal(a.damage_planes, b.damage_planes)
    np.testing.assert_array_equal(a.arc_length, b.arc_length)
    assert back.curve == res.curve and back.settings == res.settings
    assert b.clips == a.clips and b.section == a.section
    assert [h.damage for h in back.hot_spots()] == [h.damage for h in res.hot_spots()]
    assert not list(tmp_path.glob("*.tmp"))


def test_compare_ranks_variants_with_ratios(tmp_path):
    save_result(make_result(1.0), tmp_path / "a.h5")
    save_result(make_result(1.2), tmp_path / "b.h5")
    analyse(tmp_path / "b.h5").save(tmp_path / "b.damage.h5")
    cmp = compare([tmp_path / "b.damage.h5", tmp_path / "a.h5"])  # a is analysed on the fly
    assert [v.label for v in cmp.variants] == ["a", "b"]  # the run, not the file stem
    assert cmp.best.label == "a"
    assert cmp.variants[1].ratio == pytest.approx(1.2**5, rel=1e-12)
    text = cmp.table()
    assert "b " in text and "2.49" in text and "clip 'C'" in text
    with pytest.raises(ValueError, match="wohler_k 5.0 vs 4.0"):
        compare([tmp_path / "b.damage.h5", analyse(make_result(), curve=WohlerCurve(4.0, 1e30))])
    with pytest.raises(ValueError, match="2 labels for 1 variants"):
        compare([tmp_path / "a.h5"], labels=["x", "y"])


def test_sampling_warning_for_coarse_output_steps():
    with pytest.warns(SamplingWarning, match="samples per period"):
        res = analyse(make_result(f=120.0, periods=240))  # 8.3 samples per period at 1 ms
    assert res.cables["harness"].sampling.f_max == pytest.approx(120.0, rel=0.02)
    with warnings.catch_warnings():
        warnings.simplefilter("error", SamplingWarning)
        ok = analyse(make_result())  # 200 samples per period
    assert ok.cables["harness"].sampling.samples_per_period > 100


def test_cli_functions(tmp_path):
    app = typer.Typer()
    app.command("lda")(lda_command)
    app.command("compare")(compare_command)
    save_result(make_result(1.0), tmp_path / "a.h5")
    save_result(make_result(1.1), tmp_path / "b.h5")
    runner = CliRunner()
    out = runner.invoke(app, ["lda", str(tmp_path / "a.h5")])
    assert out.exit_code == 0, out.output
    assert (tmp_path / "a.damage.h5").exists() and "hot spots" in out.output
    out = runner.invoke(app, ["lda", str(tmp_path / "b.h5"), "-o", str(tmp_path / "bd.h5")])
    assert out.exit_code == 0, out.output
    out = runner.invoke(app, ["compare", str(tmp_path / "bd.h5"), str(tmp_path / "a.damage.h5")])
    assert out.exit_code == 0, out.output
    assert "best: a\n" in out.output
    out = runner.invoke(app, ["lda", str(tmp_path / "a.h5"), "--wohler-k", "-1"])
    assert out.exit_code == 2 and "k = -1" in out.output


def test_zero_damage_and_single_step_results(tmp_path):
    """A static result (one step) has no cycles: zero damage, no hot spots, still saved and
    comparable (a zero best gives ratio 1 to other zeros)."""
    r = make_result()
    c = r.cable
    static = Result(
        mode="static",
        cables={
            "harness": CableResult(
                name="harness",
                time=c.time[:1],
                arc_length=c.arc_length,
                positions=c.positions[:1],
                quaternions=c.quaternions[:1],
                forces=c.forces[:1],
                moments=c.moments[:1],
                clips=c.clips,
                section=c.section,
            )
        },
    )
    res = analyse(static)
    assert res.max_damage == 0.0 and res.hot_spots() == [] and res.life == math.inf
    back = load_damage(res.save(tmp_path / "s.h5"))
    assert back.max_damage == 0.0
    cmp = compare([res, back], labels=["a", "b"])
    assert [v.ratio for v in cmp.variants] == [1.0, 1.0]


def test_rainflow_matrix_of_the_most_damaged_series(tmp_path):
    """The stored range–mean matrix counts the cycles of the critical series: for the cosine
    bending, 10 cycles of range 2σ_a at mean 0 at node 3, γ = 90°, φ = 0°; for a two-tone
    load, the same cycles (recounted here from the loads) whose Miner sum is the maximum."""
    import h5py
    from cablelife.lda import plane_weights, rainflow_cycles, section_series, surface_angles
    from cablelife.lda.pipeline import RAINFLOW_BINS

    a = analyse(make_result())
    rf = a.cables["harness"].rainflow
    assert (rf.section_index, rf.angle, rf.plane, rf.unit) == (3, 90.0, 0.0, "Pa")
    assert rf.arc_length == pytest.approx(0.3)
    assert rf.counts.shape == (RAINFLOW_BINS, RAINFLOW_BINS) and rf.total == 10.0
    i, j = np.unravel_index(rf.counts.argmax(), rf.counts.shape)
    assert rf.counts[i, j] == 10.0 and rf.range_edges[i + 1] == pytest.approx(2 * SIGMA_A)
    assert rf.mean_edges[j] <= 0.0 <= rf.mean_edges[j + 1]
    back = load_damage(a.save(tmp_path / "a.h5")).cables["harness"].rainflow
    np.testing.assert_array_equal(back.counts, rf.counts)
    np.testing.assert_array_equal(back.range_edges, rf.range_edges)
    assert (back.section_index, back.angle, back.plane) == (3, 90.0, 0.0)

    r = make_result(scale=0.0)
    t = r.cable.time
    wave = np.cos(2 * np.pi * F * t) + 0.4 * np.sin(2 * np.pi * 23 * t)
    r.cable.moments[:, 5, 1] = 1.0 + wave
    r.cable.forces[:, :, 2] = 50.0 * wave[:, None]  # in phase: N/A − M2 cos γ a/I peaks at 180°
    cd = analyse(r, residue="full").cables["harness"]
    rf = cd.rainflow
    assert rf.section_index == 5 and rf.angle == pytest.approx(180.0) and rf.plane == 0.0
    sec = CircularSection(A, 0.0, 0.3)
    w = plane_weights(sec, surface_angles(16), np.deg2rad(np.arange(0, 180, 10.0)))
    loads = np.concatenate([node_forces(r.cable.forces)[:, 5], r.cable.moments[:, 5]], axis=1)
    row = 8 * 18 + 0  # γ = 180°, φ = 0°
    cycles = rainflow_cycles(section_series(loads, w)[row], residue="full")
    assert cycles.total == rf.total > 20
    assert pseudo(cycles.range, cycles.count).sum() == pytest.approx(cd.max_damage, rel=1e-12)
    h, _, _ = np.histogram2d(
        cycles.range, cycles.mean, bins=(rf.range_edges, rf.mean_edges), weights=cycles.count
    )
    np.testing.assert_array_equal(h, rf.counts)
    static = analyse(make_result(scale=0.0))
    assert static.cables["harness"].rainflow is None
    with h5py.File(static.save(tmp_path / "z.h5")) as f:
        assert "rainflow" not in f["cables/harness"]
