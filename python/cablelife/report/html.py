"""The HTML report: one self-contained, offline page (plotly.js embedded once, compressed;
every plot interactive) with a comparison of the runs (ranking by pseudo-damage within one
analysis mode via :func:`cablelife.lda.compare`, the dynamic/quasistatic inertia factor per
variant, motion volumes overlaid), and per run its scene summary, solver statistics, maxima,
bend radius check, clip reactions, natural frequencies over the excitation spectrum, 3D views
and, with an LDA result, the damage pictures, hot spots and rainflow matrix. One function per
section (``_comparison``, ``_ranking``, ``_frequencies``, ``_damage_section`` …) writes to the
page (:mod:`cablelife.report.page`). See docs/visuals.md."""

from __future__ import annotations

import datetime as _dt
import html
import os
import re
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from cablelife.atomic import write_text_atomic
from cablelife.lda.pipeline import DamageAnalysis
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
    plot_rainflow_matrix,
)
from cablelife.plots.bend_radius import DEFAULT_FACTOR
from cablelife.plots.fatigue_data import DAMAGE_FLOOR
from cablelife.plots.runs import variant_of
from cablelife.report.interactive import maxima_over_time_figure
from cablelife.report.page import Page
from cablelife.report.scene3d import (
    FRAMES,
    cable_figure,
    merge_runs,
    volumes_figure,
    with_damage,
)
from cablelife.results import Result
from cablelife.summary import cable_summary

#: Natural frequencies computed per cable.
N_MODES = 10
#: Saved steps swept for a motion volume in the report at most (every k-th of longer runs).
VOLUME_STEPS = 500
#: A maximum below this fraction of the largest value of its kind (forces, moments) in the run
#: is a numerical zero and shown as 0.
ZERO = 1e-6
#: Analysis modes in the order the report ranks them.
MODE_ORDER = ("dynamic", "quasistatic", "static")


@dataclass
class ReportRun:
    """One run in the report: a label, its result and optionally its LDA result (a
    DamageAnalysis or the path of a damage file of ``cablelife lda``)."""

    label: str
    result: Result
    damage: DamageAnalysis | str | os.PathLike | None = None
    _maps: dict = field(default_factory=dict, init=False, repr=False)

    def __post_init__(self):
        if self.damage is None:
            return
        if isinstance(self.damage, str | os.PathLike):
            from cablelife.lda.io import load_damage

            self.damage = load_damage(self.damage)
        self._maps = damage_maps(self.damage, self.label)
        have = list(self.result.cables)
        for name, (dm, _) in self._maps.items():
            if name not in self.result.cables:
                raise ValueError(
                    f"run {self.label!r}: the damage data has cable {name!r}, the result has "
                    f"{have}: the damage file belongs to another result"
                )
            dm.check_fits(self.result.cables[name].arc_length, f"cable {name!r} of {self.label!r}")

    def damage_of(self, cable: str) -> tuple[DamageMap, RainflowMatrix | None] | None:
        """Damage map and rainflow matrix of ``cable`` (None without damage data)."""
        return self._maps.get(cable)


def _g(x: float, unit: str = "", scale: float | None = None) -> str:
    """A number for a table; 0 when below ZERO × ``scale`` (a numerical zero)."""
    if x is None or (isinstance(x, float) and not np.isfinite(x)):
        return "–" if x is None else ("∞" if x > 0 else "−∞")
    if scale is not None and abs(x) < ZERO * scale:
        x = 0.0
    return f"{x:.4g}{' ' + unit if unit else ''}"


def _scales(c) -> dict[str, float]:
    """The largest force and moment magnitude of a cable (the reference of numerical zeros)."""
    return {"N": float(np.abs(c.forces).max()), "N m": float(np.abs(c.moments).max())}


def _colours(runs) -> dict[str, str]:
    """One colour per variant (quasistatic and dynamic runs of a variant share it)."""
    from plotly.colors import qualitative

    out: dict[str, str] = {}
    for r in runs:
        v = variant_of(r.label, r.result.mode)
        out.setdefault(v, qualitative.Plotly[len(out) % 10])
    return {r.label: out[variant_of(r.label, r.result.mode)] for r in runs}


MAXIMA = [
    ("max_tension", "max tension F3", "N"),
    ("min_tension", "min tension F3 (compression < 0)", "N"),
    ("max_shear", "max shear force |F1, F2|", "N"),
    ("max_bending", "max bending moment |M1, M2|", "N m"),
    ("max_torsion", "max torsion |M3|", "N m"),
    ("min_bend_radius", "min bend radius", "m"),
]


def _runs_of(runs: list[ReportRun]) -> list[Run]:
    colours = _colours(runs)
    out = []
    for r in runs:
        for name, c in r.result.cables.items():
            label = r.label if len(r.result.cables) == 1 else f"{r.label}: {name}"
            out.append(Run(label, c, r.result.mode, colours[r.label]))
    return out


def _ranking(page: Page, runs: list[ReportRun], summaries) -> None:
    """Ranking by maximum (pseudo-)damage within each analysis mode (dynamic first), with
    ratios and hot spots, when every run has an LDA result with the same settings, else by
    maximum bending moment (the reason noted); then the inertia factor per variant."""
    from cablelife.lda.compare import compare

    missing = [r.label for r in runs if r.damage is None]
    reason = "no run has a damage file"
    if not missing:
        try:
            by_mode = {
                m: [r for r in runs if r.result.mode == m]
                for m in MODE_ORDER
                if any(r.result.mode == m for r in runs)
            }
            ranked = {
                m: compare([r.damage for r in rs], labels=[r.label for r in rs])
                for m, rs in by_mode.items()
            }
        except ValueError as e:
            reason = str(e)
        else:
            for mode, cmp in ranked.items():
                kind = (
                    "pseudo-damage"
                    if all(v.analysis.curve.pseudo for v in cmp.variants)
                    else "damage"
                )
                rows = []
                for i, v in enumerate(cmp.variants, 1):
                    floor = DAMAGE_FLOOR * v.max_damage
                    spots = [h for h in v.hot_spots if h.damage >= floor]
                    for j, h in enumerate(spots or [None]):
                        head = [i, v.label, _g(v.max_damage), _g(v.ratio)] if j == 0 else [""] * 4
                        rows.append(head + _spot_cells(h))
                page.table(
                    ["rank", "variant", f"max {kind}", "ratio to best", *SPOT_HEADER],
                    rows,
                    f"{mode} runs: ranking by maximum {kind} (lower is better) with the hot spots",
                    cls=f"ranking ranking-{mode}",
                )
            _inertia(page, runs)
            return
    elif len(missing) < len(runs):
        reason = f"no damage file for {', '.join(missing)}"
    page.note(f"no damage ranking: {reason}", "warning" if not missing else "note")
    ranked = sorted(summaries, key=lambda x: x[1]["max_bending"])
    page.table(
        ["rank", "variant", "max bending moment"],
        [[i + 1, lab, _g(s["max_bending"], "N m")] for i, (lab, s) in enumerate(ranked)],
        "ranking by maximum bending moment",
    )


def _clearances(page: Page, runs: list[ReportRun]) -> None:
    """Beside the ranking: per run (dynamic first) the least clearance of each cable to the
    surroundings (which part, s, t) and the largest length closer than min_clearance, from
    :func:`cablelife.surroundings.summary.clearance_summary`; nothing without geometry."""
    from cablelife.surroundings.summary import clearance_summary

    rows = []
    limits = set()
    for mode in MODE_ORDER:
        for r in runs:
            if r.result.mode != mode:
                continue
            for name, c in r.result.cables.items():
                if c.surroundings is None:
                    continue
                s = clearance_summary(c)
                limits.add(s["min_clearance"])
                label = r.label if len(r.result.cables) == 1 else f"{r.label}: {name}"
                near = [v for v in s["bodies"].values() if v is not None]
                v = min(near, key=lambda x: x["min"]) if near else None
                cells = (
                    ["–"] * 4
                    if v is None
                    else [
                        f"{v['min'] * 1e3:.1f}",
                        v["part"],
                        f"{v['s']:.3f}",
                        f"{v['t']:.3f}",
                    ]
                )
                close = s["length_below_min"]
                when = f"{s['length_below_min_t']:.3f}" if close > 0 else "–"
                rows.append([label, *cells, f"{close:.3f}", when])
    if not rows:
        return
    limit = f"{next(iter(limits)) * 1e3:g} mm" if len(limits) == 1 else "min_clearance"
    page.table(
        [
            "run",
            "least clearance [mm]",
            "nearest part",
            "at s [m]",
            "at t [s]",
            f"length closer than {limit} [m]",
            "at t [s]",
        ],
        rows,
        "clearance to the surroundings: the least over time and cable (of the cable surface; "
        f"negative: inside) and the largest cable length closer than {limit}",
        cls="clearance-comparison",
    )


def _inertia(page: Page, runs: list[ReportRun]) -> None:
    """Dynamic over quasistatic maximum damage per variant that has both runs: how much the
    inertia (resonance) adds; not a ranking."""
    by_variant: dict[str, dict[str, float]] = {}
    for r in runs:
        if r.damage is not None:
            v = variant_of(r.label, r.result.mode)
            by_variant.setdefault(v, {})[r.result.mode] = r.damage.max_damage
    rows = [
        [v, _g(d["dynamic"]), _g(d["quasistatic"]), _g(d["dynamic"] / d["quasistatic"])]
        for v, d in by_variant.items()
        if d.get("quasistatic", 0) > 0 and "dynamic" in d
    ]
    if rows:
        page.table(
            ["variant", "max damage, dynamic", "max damage, quasistatic", "inertia factor"],
            rows,
            "inertia factor: dynamic over quasistatic maximum damage of each variant",
            cls="inertia",
        )


SPOT_HEADER = ["hot spot s [m]", "angle γ [°]", "plane φ [°]", "damage", "nearest clip"]


def _spot_cells(h) -> list[str]:
    """Table cells of a hot spot (an LDA HotSpot, angles in degrees, or a plots HotSpot)."""
    if h is None:
        return ["–"] * len(SPOT_HEADER)
    lda = hasattr(h, "section_index")
    angle = h.angle if lda else np.degrees(h.angle)
    plane = h.plane if lda else (None if h.plane is None else np.degrees(h.plane))
    clip = "–"
    if h.nearest_clip is not None:
        clip = h.nearest_clip
        if h.clip_distance is not None:
            clip += f" ({h.clip_distance * 1e3:.0f} mm away)"
    return [
        f"{h.arc_length:.3f}",
        f"{angle:.0f}",
        "–" if plane is None else f"{plane:.0f}",
        _g(h.damage),
        clip,
    ]


def _summary(cache: dict, c) -> dict:
    """The cable summary of ``c``, computed once per report (``cache``: ("summary", id) →
    the summary or its future, started in the background by :func:`build_report`)."""
    key = ("summary", id(c))
    got = cache.get(key)
    if got is None:
        got = cache[key] = cable_summary(c, strains=False)
    elif hasattr(got, "result"):
        got = cache[key] = got.result()
    return got


def _comparison(
    page: Page, runs: list[ReportRun], volumes: dict, voxel: float, factor: float, cache: dict
):
    page.h(2, "Comparison of the variants", "comparison")
    plot_runs = _runs_of(runs)
    summaries = [(run.label, _summary(cache, run.cable)) for run in plot_runs]
    scales = [_scales(run.cable) for run in plot_runs]
    page.table(
        ["quantity", *[s[0] for s in summaries]],
        [
            [
                lab,
                *[
                    _g(s[key], unit, sc.get(unit))
                    for (_, s), sc in zip(summaries, scales, strict=True)
                ],
            ]
            for key, lab, unit in MAXIMA
        ],
        f"maxima over time and arc length (0: below {ZERO:g} × the largest force or moment)",
    )
    _ranking(page, runs, summaries)
    _clearances(page, runs)
    if len(volumes) == 2:
        from cablelife.volume import compare_volumes

        (la, a), (lb, b) = volumes.items()
        c = compare_volumes(a, b, voxel)
        v = c.volumes
        page.table(
            ["quantity", "value"],
            [
                [f"volume A = {la}", _g(v["a"] * 1e3, "l")],
                [f"volume B = {lb}", _g(v["b"] * 1e3, "l")],
                ["A ∪ B", _g(v["union"] * 1e3, "l")],
                ["A ∖ B", _g(v["a_minus_b"] * 1e3, "l")],
                ["B ∖ A", _g(v["b_minus_a"] * 1e3, "l")],
                ["A sticks out of B by", _g(c.a_beyond_b.distance * 1e3, "mm")],
                ["B sticks out of A by", _g(c.b_beyond_a.distance * 1e3, "mm")],
            ],
            f"motion volumes at {voxel * 1e3:g} mm voxels",
        )
    if len(volumes) >= 2:
        cables = {r.label: r.result.cable for r in runs if len(r.result.cables) == 1}
        page.plotly(volumes_figure(volumes, cables), "motion volumes of the runs")
    page.plotly(maxima_over_time_figure(plot_runs), "maxima over time of the runs")
    page.plot(plot_envelopes(plot_runs), "envelopes along the cable")
    page.plot(plot_bend_radius(plot_runs, factor), "smallest bend radius along the cable")
    if any(run.cable.clips for run in plot_runs):
        page.plot(plot_clip_reactions(plot_runs), "clip reactions of the runs")
    colours = _colours(runs)
    for mode in MODE_ORDER:  # damage of one mode per picture: the modes differ by orders
        picked = [
            (d[0], colours[r.label], r.result.cables[n])
            for r in runs
            if r.result.mode == mode
            for n in r.result.cables
            if (d := r.damage_of(n)) is not None and d[0].damage.max() > 0
        ]
        if picked:
            clips = {n: rc.s for n, rc in picked[0][2].clips.items()}
            page.plot(
                plot_damage_along_cable(
                    [m for m, _, _ in picked], clips, [c for _, c, _ in picked]
                ),
                f"damage along the cable, {mode} runs",
            )


def _scene_key(res: Result, name: str) -> tuple[str, str]:
    """Runs of one scene in several modes share their modes and excitation."""
    return (re.sub(r'(?m)^mode = "\w+"$', "", res.scene_toml), name)


def frequency_data(res: Result, name: str):
    """(natural frequencies, excitation PSD or the reason it is missing, excited band) of a
    cable of a run, or the exception that stopped it."""
    from cablelife.modal import cable_modes
    from cablelife.report.scene_data import excitation_psd, excited_band, result_scene
    from cablelife.scene import SceneError
    from cablelife.signals import SignalError

    try:
        scene = result_scene(res.scene_toml)
        spec = next(c for c in scene.cables if c.name == name)
        fn = cable_modes(scene, spec, N_MODES).frequencies
    except (SceneError, SignalError, StopIteration, ValueError) as e:
        return e or ValueError("cable not in the scene")
    try:
        mode = "dynamic" if res.mode == "static" else res.mode
        exc = excitation_psd(scene, name, mode)
        band = excited_band(scene, name, exc)
    except (SceneError, SignalError, ValueError, OSError) as e:
        exc, band = e, None
    return fn, exc, band


def _frequencies(page: Page, res: Result, name: str, cache: dict, run_label: str = "") -> None:
    """Natural frequencies of the mounted cable (about its static equilibrium, bodies at rest)
    over the acceleration PSD at its clips on moving bodies; the excited band from the signal
    definitions (:func:`cablelife.report.scene_data.excited_band`). Computed once per scene
    (``cache``: scene key → the future of :func:`frequency_data`)."""
    key = _scene_key(res, name)
    if key not in cache:
        cache[key] = frequency_data(res, name)
    if hasattr(cache[key], "result"):
        cache[key] = cache[key].result()
    got = cache[key]
    shown = cache.setdefault("shown", {})
    if key in shown:
        page.note(
            f"natural frequencies and excitation spectrum: as in run {shown[key]} (the same "
            "scene in another mode)"
        )
        return
    shown[key] = run_label
    if isinstance(got, Exception):
        page.note(f"natural frequencies not available: {got}")
        return
    fn, exc, band = got
    if isinstance(exc, Exception) or res.mode == "static":
        why = "a static run" if res.mode == "static" else exc
        page.table(
            ["mode", *range(1, fn.size + 1)],
            [["f [Hz]", *[f"{x:.4g}" for x in fn]]],
            f"natural frequencies of the mounted cable (no excitation spectrum: {why})",
        )
        return
    lo, hi = band
    inside = [i + 1 for i, x in enumerate(fn) if lo <= x <= hi]
    page.table(
        ["mode", *range(1, fn.size + 1)],
        [
            ["f [Hz]", *[f"{x:.4g}" for x in fn]],
            ["excited", *["yes" if i + 1 in inside else "" for i in range(fn.size)]],
        ],
        f"natural frequencies of the mounted cable; excited band {lo:.3g} – {hi:.3g} Hz "
        "(from the signal definitions)",
    )
    if inside and res.mode == "quasistatic":
        page.note(
            f"modes {inside} lie inside the excited band: the quasistatic run ignores their "
            "resonance; run the scene in dynamic mode",
            "warning",
        )
    page.plot(
        plot_frequencies_over_spectrum(fn, exc.frequency, exc.psd, labels=exc.labels, band=band),
        f"natural frequencies of {name} over the excitation spectrum",
    )


def _impact_notes(res) -> list[str]:
    """The warnings of impacts the dynamic time step does not resolve (saved per step in
    ``solver["unresolved_gain"]`` and ``solver["impact_dissipation"]``; one for a harness,
    whose cables share them)."""
    from cablelife.validity import impact_messages

    named = [(f"cable '{n}'", c) for n, c in res.cables.items()]
    if res.junctions and named:
        named = [("harness", named[0][1])]
    return [
        m
        for name, c in named
        if c.solver.get("unresolved_gain") is not None
        for m in impact_messages(
            name, c.solver["unresolved_gain"], c.time, c.solver.get("impact_dissipation")
        )
    ]


def _run_section(page, k, run: ReportRun, volumes, color_by, frames, factor, cache, alone):
    """A run's section; its load plots only when ``alone`` (else the comparison has them)."""
    res = run.result
    page.h(2, f"Run {run.label} ({res.mode})", f"run-{k}")
    if not res.complete:
        page.note(f"incomplete run: {res.message}", "warning")
    for message in _impact_notes(res):  # as the terminal said (ImpactWarning)
        page.note(message, "warning")
    if res.junctions:
        _harness_section(page, run, color_by, frames)
    for name, c in res.cables.items():
        s = _summary(cache, c)
        page.h(3, f"cable {name}")
        sec = c.section
        page.table(
            ["scene", "value"],
            [
                ["saved steps", s["steps"]],
                ["time span", f"{_g(float(c.time[0]))} – {_g(float(c.time[-1]), 's')}"],
                ["segments", s["segments"]],
                ["length", _g(float(c.arc_length[-1] - c.arc_length[0]), "m")],
                [
                    "section",
                    f"{sec.get('shape', '?')}, outer radius {_g(sec.get('outer_radius'), 'm')}",
                ],
                ["clips", ", ".join(f"{n} at s = {v['s']:.3f} m" for n, v in s["clips"].items())],
            ],
        )
        page.table(
            ["solver", "value"],
            [
                ["mode", res.mode],
                [
                    "Newton iterations per step",
                    f"mean {s['newton_iterations_mean']:.1f}, max {s['newton_iterations_max']}",
                ],
                ["wall time", _g(s["wall_time"], "s")],
                ["complete", f"{res.complete} {res.message}".strip()],
            ],
        )
        sc = _scales(c)
        rows = [[lab, _g(s[key], unit, sc.get(unit))] for key, lab, unit in MAXIMA]
        rows.append(
            [
                "min bend radius at",
                f"s = {s['min_bend_radius_s']:.3f} m, t = {s['min_bend_radius_t']:.4g} s",
            ]
        )
        page.table(["maximum", "value"], rows, "maxima over time and arc length")
        page.table(
            ["clip", "s [m]", "max |force| [N]", "max |moment| [N m]"],
            [
                [n, f"{v['s']:.3f}", _g(v["max_force"]), _g(v["max_moment"])]
                for n, v in s["clips"].items()
            ],
            "clip reactions",
        )
        chk = check_bend_radius(c, factor)
        if chk.ok:
            page.note(
                f"bend radius OK: ≥ {factor:g} × diameter = {chk.allowed * 1e3:.1f} mm everywhere"
            )
        else:
            page.table(
                ["from s [m]", "to s [m]", "smallest radius [mm]"],
                [[f"{a:.3f}", f"{b:.3f}", f"{r * 1e3:.1f}"] for a, b, r in chk.violations],
                f"bend radius below the rule {factor:g} × diameter = {chk.allowed * 1e3:.1f} mm",
            )
        vol = volumes.get(run.label) if len(res.cables) == 1 else None
        if vol is not None:
            box = vol.bounding_box * 1e3
            page.note(
                f"motion volume {vol.litres:.4g} l; bounding box "
                + " × ".join(f"[{a:.1f}, {b:.1f}]" for a, b in zip(box[0], box[1], strict=True))
                + " mm"
            )
        view = cache.get("views", {}).get((run.label, name))
        view_at = "its 3D view above"
        if isinstance(view, tuple):  # drawn with another run's view: (note, where)
            page.note(view[0])
            view_at = view[1]
        else:
            view = view or run_view(run, name, vol, color_by, frames)
            page.plotly(view, f"3D view of {name}")
        one = [Run(run.label, c, res.mode, _colours([run])[run.label])]
        if alone:
            page.plotly(maxima_over_time_figure(one), f"maxima over time of {name}")
            page.plot(plot_envelopes(one), f"envelopes of {name}")
            page.plot(plot_bend_radius(one, factor), f"bend radius of {name}")
        if c.clips and alone:
            page.plot(plot_clip_reactions(one), f"clip reactions of {name}")
        _frequencies(page, res, name, cache, run.label)
        if c.surroundings is not None:
            from cablelife.report.surroundings import surroundings_section

            surroundings_section(page, res, name, view_at)
        if run.damage_of(name) is not None:
            _damage_section(page, run, name, alone, view_at)


def _harness_section(page, run: ReportRun, color_by: str, frames: int) -> None:
    """A harness run: its junctions (largest branch loads, how far each moved) and one 3D view
    of all its cables with the junctions marked and the damage on every branch."""
    from cablelife.report.harness_view import harness_figure

    res = run.result
    page.h(3, f"harness: {len(res.cables)} cables, {len(res.junctions)} junctions")
    rows = []
    for name, j in res.junctions.items():
        moved = float(np.linalg.norm(j.position - j.position[:1], axis=1).max(initial=0.0))
        for k, (end, force) in enumerate(j.branch_force.items()):
            rows.append(
                [
                    name if k == 0 else "",
                    end,
                    _g(float(np.linalg.norm(force, axis=1).max(initial=0.0))),
                    _g(float(np.linalg.norm(j.branch_moment[end], axis=1).max(initial=0.0))),
                    f"{moved * 1e3:.3g}" if k == 0 else "",
                ]
            )
    page.table(
        ["junction", "branch", "max |force| [N]", "max |moment| [N m]", "moved [mm]"],
        rows,
        "junctions (max over time)",
    )
    damage = {}
    for name in res.cables:
        d = run.damage_of(name)
        if d is not None and d[0].damage.max() > 0:
            damage[name] = d[0]
    page.plotly(
        harness_figure(res, color_by, frames, damage), "3D view of the harness (all cables)"
    )


def run_view(run: ReportRun, name: str, volume, color_by: str, frames: int) -> dict:
    """The 3D view of a run's cable: the tube coloured by ``color_by`` over time, and behind
    buttons the damage on the surface and the clearance at its least (when there are)."""
    res, c = run.result, run.result.cables[name]
    view = cable_figure(
        c, color_by, frames=frames, volume=volume, scene_toml=res.scene_toml, mode=res.mode
    )
    dmg = run.damage_of(name)
    if dmg is not None and dmg[0].damage.max() > 0:  # the damage map: a button of the view
        view = with_damage(view, c, dmg[0], scene_toml=res.scene_toml, mode=res.mode)
    if c.surroundings is not None:  # the clearance at its least: a button of the view
        from cablelife.report.surroundings import with_clearance

        view = with_clearance(view, c, res)
    return view


def variant_views(runs: list[ReportRun], volumes: dict, color_by: str, frames: int) -> dict:
    """One 3D view per variant of its dynamic and quasistatic runs (single-cable runs with the
    same saved times: :func:`cablelife.report.scene3d.merge_runs`), as each WebGL scene costs
    about a second to draw without a GPU whatever it shows: (run label, cable) → the view (in
    the dynamic run's section) or, in the quasistatic run's, (the note that replaces it, where
    its views are)."""
    by_variant: dict[str, dict[str, ReportRun]] = {}
    for r in runs:
        if len(r.result.cables) == 1:
            by_variant.setdefault(variant_of(r.label, r.result.mode), {})[r.result.mode] = r
    out: dict = {}
    for pair in by_variant.values():
        d, q = pair.get("dynamic"), pair.get("quasistatic")
        if d is None or q is None:
            continue
        (name,) = d.result.cables
        if list(q.result.cables) != [name]:
            continue
        views = [run_view(r, name, volumes.get(r.label), color_by, frames) for r in (d, q)]
        merged = merge_runs(*views, d.label, q.label)
        if merged is not None:
            out[(d.label, name)] = merged
            out[(q.label, name)] = (
                f"the 3D view of {name} in this run: in run {d.label}'s section, with that run "
                f"(its drop-down: '{q.label}: …')",
                f"run {d.label}'s 3D view (its drop-down, '{q.label}: …')",
            )
    return out


def _damage_section(
    page: Page, run: ReportRun, name: str, alone: bool = True, view_at: str = "its 3D view above"
) -> None:
    """LDA settings, hot spots, the damage along the cable (on the surface: a button of the
    3D view) and the rainflow matrix of the most damaged series."""
    c = run.result.cables[name]
    dm, rf = run.damage_of(name)
    a = run.damage
    curve = a.curve
    kind = "pseudo-damage" if curve.pseudo else "damage"
    st = a.settings
    cd = a.cables[name]
    rows = [
        [f"max {kind}", _g(cd.max_damage)],
        [
            "Wöhler curve (ranges)",
            f"k = {curve.k:g}, α = {curve.alpha:.4g} Pa^k"
            + ("" if curve.knee_range is None else f", knee {curve.knee_range:.4g} Pa"),
        ],
        [
            "settings",
            f"{st['n_points']} surface points, planes every {st['plane_step_deg']:g}°, "
            f"section step {st['section_step']}, residue {st['residue']}",
        ],
    ]
    if cd.sampling is not None:
        rows.append(
            [
                "sampling",
                f"{cd.sampling.samples_per_period:.1f} samples per period of "
                f"{cd.sampling.f_max:.3g} Hz"
                + ("" if cd.sampling.ok else " (damage undercounted)"),
            ]
        )
    page.table(["fatigue analysis (LDA)", "value"], rows)
    if dm.damage.max() <= 0:
        page.note(f"{kind} is zero everywhere: no load cycles")
        return
    page.table(
        ["#", *SPOT_HEADER],
        [[i + 1, *_spot_cells(h)] for i, h in enumerate(dm.hot_spots(5))],
        f"damage hot spots (local maxima along the cable above {DAMAGE_FLOOR:g} × the maximum)",
    )
    page.note(
        f"the {kind} on the surface of {name}: 'damage on the surface' in {view_at} (log "
        "colours from the floor, hot spots labelled)"
    )
    clips = {n: r.s for n, r in c.clips.items()}
    if alone:  # else the comparison draws the runs of a mode together
        page.plot(plot_damage_along_cable([dm], clips), f"damage along {name}")
    if rf is not None:
        page.plot(plot_rainflow_matrix(rf), f"rainflow matrix of {name}")
    else:
        page.note("the damage file has no rainflow matrix (older file): rerun cablelife lda")


CSS = """
body{font-family:system-ui,sans-serif;margin:0 auto;max-width:1200px;padding:1em;color:#222}
h1{font-size:1.6em}h2{border-bottom:2px solid #ccd;padding-bottom:.2em;margin-top:2em}
table{border-collapse:collapse;margin:.8em 0;font-size:.9em}
caption{text-align:left;font-weight:600;padding:.3em 0}
th,td{border:1px solid #ccd;padding:.25em .6em;text-align:left}th{background:#eef}
.figure{margin:1em 0}
.warning{color:#a00;font-weight:600}.note{color:#335}nav a{margin-right:1em}
.plot{min-height:320px}.plot:not([data-state]){background:#f4f4f8}
"""


def build_report(
    runs: list[ReportRun],
    *,
    color_by: str = "bending",
    frames: int = FRAMES,
    voxel: float | None = 0.004,
    bend_factor: float = DEFAULT_FACTOR,
    title: str = "cablelife report",
    on_step: Callable[[str], None] | None = None,
) -> str:
    """The report page as an HTML string. ``voxel`` (m) for the motion volumes; None skips
    them. ``on_step(what)`` follows the progress (one call per section)."""
    from cablelife import __version__
    from cablelife.volume import motion_volume

    if not runs:
        raise ValueError("runs: give at least one result")
    labels = [r.label for r in runs]
    if len(set(labels)) != len(labels):
        raise ValueError(f"run labels must be unique, got {labels}")
    step = on_step or (lambda what: None)
    # In the background (the modal solves, signal synthesis and volume kernels release the
    # GIL): the natural frequencies and excitation per scene, the motion volumes per run.
    pool = ThreadPoolExecutor(max_workers=max(1, min(4, os.cpu_count() or 1)))

    def volume(r):
        n = next(iter(r.result.cables.values())).n_steps
        every = slice(None, None, max(1, -(-n // VOLUME_STEPS)))
        return motion_volume(r.result, voxel, steps=every)

    pending = {r.label: pool.submit(volume, r) for r in runs} if voxel is not None else {}
    cache: dict = {}
    for r in runs:
        for name, c in r.result.cables.items():
            cache[("summary", id(c))] = pool.submit(cable_summary, c, strains=False)
            key = _scene_key(r.result, name)
            if key not in cache:
                cache[key] = pool.submit(frequency_data, r.result, name)
    volumes = {}
    for label, f in pending.items():
        step(f"motion volume of {label}")
        volumes[label] = f.result()
    page = Page()
    stamp = _dt.datetime.now().strftime("%Y-%m-%d %H:%M")
    page.h(1, title)
    page.note(f"cablelife {__version__}, {stamp}; runs: {', '.join(labels)}")
    links = ([("comparison", "comparison")] if len(runs) > 1 else []) + [
        (f"run-{k}", r.label) for k, r in enumerate(runs)
    ]
    page.add("<nav>" + "".join(f'<a href="#{a}">{html.escape(t)}</a>' for a, t in links) + "</nav>")
    if len(runs) > 1:
        step("comparison")
        _comparison(page, runs, volumes, voxel or 0.004, bend_factor, cache)
    if len(runs) > 1:
        step("3D views")
        cache["views"] = variant_views(runs, volumes, color_by, frames)
    for k, run in enumerate(runs):
        step(f"run {run.label}")
        _run_section(page, k, run, volumes, color_by, frames, bend_factor, cache, len(runs) == 1)
    pool.shutdown()
    step("page")
    return page.html(title, CSS)


def write_report(output: str | os.PathLike, runs: list[ReportRun], **kw) -> Path:
    """Builds the report and writes it atomically to ``output``."""
    return write_text_atomic(Path(output), build_report(runs, **kw))
