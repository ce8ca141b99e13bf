"""The HTML report: one self-contained, offline page (plotly.js embedded once, PNGs inline)
with a comparison of the runs, and per run its scene summary, solver statistics, maxima, bend
radius check, clip reactions, 3D views and, when damage maps are given, the damage pictures
and hot spots. The page records in ``<body data-*>`` how many figures and images rendered and
any script errors (used by the test in headless Chromium)."""

from __future__ import annotations

import base64
import datetime as _dt
import html
import os
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from cablelife.atomic import write_text_atomic
from cablelife.plots import (
    DamageMap,
    RainflowMatrix,
    Run,
    check_bend_radius,
    plot_bend_radius,
    plot_clip_reactions,
    plot_damage_along_cable,
    plot_envelopes,
    plot_rainflow_matrix,
    png_bytes,
)
from cablelife.plots.bend_radius import DEFAULT_FACTOR
from cablelife.report.interactive import maxima_over_time_figure
from cablelife.report.scene3d import FRAMES, cable_figure, damage_figure
from cablelife.results import Result
from cablelife.summary import cable_summary


@dataclass
class ReportRun:
    """One run in the report: its result, a label, and damage data per cable (optional)."""

    label: str
    result: Result
    damage: dict[str, tuple[DamageMap, RainflowMatrix | None]] = field(default_factory=dict)

    def damage_of(self, cable: str):
        if cable in self.damage:
            return self.damage[cable]
        if len(self.damage) == 1 and len(self.result.cables) == 1:
            return next(iter(self.damage.values()))
        return None


class _Page:
    def __init__(self):
        self.parts: list[str] = []
        self.figures = 0
        self.images = 0

    def add(self, text: str) -> None:
        self.parts.append(text)

    def h(self, level: int, text: str, anchor: str | None = None) -> None:
        a = f' id="{html.escape(anchor)}"' if anchor else ""
        self.add(f"<h{level}{a}>{html.escape(text)}</h{level}>")

    def png(self, fig, alt: str) -> None:
        data = base64.b64encode(png_bytes(fig)).decode("ascii")
        self.images += 1
        self.add(f'<img class="plot" alt="{html.escape(alt)}" src="data:image/png;base64,{data}">')

    def plotly(self, fig) -> None:
        import plotly.io as pio

        self.figures += 1
        div = pio.to_html(
            fig,
            full_html=False,
            include_plotlyjs=False,
            div_id=f"figure-{self.figures}",
            auto_play=False,
            config={"displaylogo": False},
        )
        self.add(f'<div class="figure">{div}</div>')

    def table(self, header: list[str], rows: list[list], caption: str = "") -> None:
        cap = f"<caption>{html.escape(caption)}</caption>" if caption else ""
        head = "".join(f"<th>{html.escape(str(h))}</th>" for h in header)
        body = "".join(
            "<tr>" + "".join(f"<td>{html.escape(str(c))}</td>" for c in r) + "</tr>" for r in rows
        )
        self.add(f"<table>{cap}<thead><tr>{head}</tr></thead><tbody>{body}</tbody></table>")

    def note(self, text: str, cls: str = "note") -> None:
        self.add(f'<p class="{cls}">{html.escape(text)}</p>')


def _g(x: float, unit: str = "") -> str:
    if x is None or (isinstance(x, float) and not np.isfinite(x)):
        return "–" if x is None else ("∞" if x > 0 else "−∞")
    return f"{x:.4g}{' ' + unit if unit else ''}"


MAXIMA = [
    ("max_tension", "max tension F3", "N"),
    ("min_tension", "min tension F3 (compression < 0)", "N"),
    ("max_shear", "max shear force |F1, F2|", "N"),
    ("max_bending", "max bending moment |M1, M2|", "N m"),
    ("max_torsion", "max torsion |M3|", "N m"),
    ("min_bend_radius", "min bend radius", "m"),
]


def _runs_of(runs: list[ReportRun]) -> list[Run]:
    out = []
    for r in runs:
        for name, c in r.result.cables.items():
            label = r.label if len(r.result.cables) == 1 else f"{r.label}: {name}"
            out.append(Run(label, c, r.result.mode))
    return out


def _max_damage(r: ReportRun) -> float | None:
    values = [
        float(d[0].damage.max()) for n in r.result.cables if (d := r.damage_of(n)) is not None
    ]
    return max(values) if values else None


def _comparison(page: _Page, runs: list[ReportRun], volumes: dict, voxel: float, factor: float):
    page.h(2, "Comparison of the variants", "comparison")
    plot_runs = _runs_of(runs)
    summaries = [(run.label, cable_summary(run.cable)) for run in plot_runs]
    page.table(
        ["quantity", *[s[0] for s in summaries]],
        [[lab, *[_g(s[key], unit) for _, s in summaries]] for key, lab, unit in MAXIMA],
        "maxima over time and arc length",
    )
    damages = [(r.label, _max_damage(r)) for r in runs]
    if all(d is not None for _, d in damages):
        ranked = sorted(damages, key=lambda x: x[1])
        best = ranked[0][1]
        page.table(
            ["rank", "variant", "max pseudo-damage", "ratio to best"],
            [
                [i + 1, lab, _g(d), _g(d / best if best > 0 else np.inf)]
                for i, (lab, d) in enumerate(ranked)
            ],
            "ranking by maximum pseudo-damage (lower is better)",
        )
    else:
        ranked = sorted(summaries, key=lambda x: x[1]["max_bending"])
        page.table(
            ["rank", "variant", "max bending moment"],
            [[i + 1, lab, _g(s["max_bending"], "N m")] for i, (lab, s) in enumerate(ranked)],
            "ranking by maximum bending moment (not every run has a damage file)",
        )
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
    page.plotly(maxima_over_time_figure(plot_runs))
    page.png(plot_envelopes(plot_runs), "envelopes along the cable")
    page.png(plot_bend_radius(plot_runs, factor), "smallest bend radius along the cable")
    maps = [
        DamageMap(d[0].arc_length, d[0].angle, d[0].damage, r.label)
        for r in runs
        for n in r.result.cables
        if (d := r.damage_of(n)) is not None
    ]
    if maps:
        page.png(plot_damage_along_cable(maps), "damage along the cable")


def _run_section(page, k, run: ReportRun, volumes, color_by, frames, factor):
    res = run.result
    page.h(2, f"Run {run.label} ({res.mode})", f"run-{k}")
    if not res.complete:
        page.note(f"incomplete run: {res.message}", "warning")
    for name, c in res.cables.items():
        s = cable_summary(c)
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
        rows = [[lab, _g(s[key], unit)] for key, lab, unit in MAXIMA]
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
        page.plotly(cable_figure(c, color_by, frames=frames, volume=vol, scene_toml=res.scene_toml))
        one = [Run(run.label, c, res.mode)]
        page.plotly(maxima_over_time_figure(one))
        page.png(plot_envelopes(one), f"envelopes of {name}")
        page.png(plot_bend_radius(one, factor), f"bend radius of {name}")
        if c.clips:
            page.png(plot_clip_reactions(one), f"clip reactions of {name}")
        dmg = run.damage_of(name)
        if dmg is not None:
            dm, rf = dmg
            spots = dm.hot_spots(5)
            page.table(
                ["hot spot", "s [m]", "angle γ [°]", "damage", "nearest clip"],
                [
                    [
                        i + 1,
                        f"{h.arc_length:.3f}",
                        f"{np.degrees(h.angle):.0f}",
                        _g(h.damage),
                        _nearest_clip(c, h.arc_length),
                    ]
                    for i, h in enumerate(spots)
                ],
                "damage hot spots",
            )
            page.plotly(damage_figure(c, dm))
            clips = {n: r.s for n, r in c.clips.items()}
            page.png(plot_damage_along_cable([dm], clips), f"damage along {name}")
            if rf is not None:
                page.png(plot_rainflow_matrix(rf), f"rainflow matrix of {name}")


def _nearest_clip(c, s: float) -> str:
    if not c.clips:
        return "–"
    n, r = min(c.clips.items(), key=lambda kv: abs(kv[1].s - s))
    return f"{n} ({abs(r.s - s) * 1e3:.0f} mm away)"


CSS = """
body{font-family:system-ui,sans-serif;margin:0 auto;max-width:1200px;padding:1em;color:#222}
h1{font-size:1.6em}h2{border-bottom:2px solid #ccd;padding-bottom:.2em;margin-top:2em}
table{border-collapse:collapse;margin:.8em 0;font-size:.9em}
caption{text-align:left;font-weight:600;padding:.3em 0}
th,td{border:1px solid #ccd;padding:.25em .6em;text-align:left}th{background:#eef}
img.plot{max-width:100%;display:block;margin:.8em 0}.figure{margin:1em 0}
.warning{color:#a00;font-weight:600}.note{color:#335}nav a{margin-right:1em}
"""

# Records script errors (before plotly runs) and, after load, which figures rendered.
CHECK_HEAD = """<script>
window.__errors=[];window.addEventListener('error',function(e){__errors.push(String(e.message))});
(function(){var ce=console.error;console.error=function(){
__errors.push(Array.prototype.join.call(arguments,' '));ce.apply(console,arguments)}})();
</script>"""
CHECK_TAIL = """<script>
window.addEventListener('load',function(){setTimeout(function(){
var figs=document.querySelectorAll('.js-plotly-plot'),ok=0;
figs.forEach(function(f){var L=f._fullLayout||{},gl=L._has&&L._has('gl3d');
if(f.querySelector('.main-svg')&&L.width>0&&(!gl||f.querySelector('canvas')))ok++});
var imgs=document.querySelectorAll('img.plot'),iok=0;
imgs.forEach(function(i){if(i.complete&&i.naturalWidth>0)iok++});
var b=document.body.dataset;b.renderedFigures=ok;b.renderedImages=iok;
b.errors=JSON.stringify(window.__errors);b.checked='yes';},1500)});
</script>"""


def build_report(
    runs: list[ReportRun],
    *,
    color_by: str = "bending",
    frames: int = FRAMES,
    voxel: float | None = 0.004,
    bend_factor: float = DEFAULT_FACTOR,
    title: str = "cablelife report",
) -> str:
    """The report page as an HTML string. ``voxel`` (m) for the motion volumes; None skips
    them."""
    from plotly.offline import get_plotlyjs

    from cablelife import __version__
    from cablelife.volume import motion_volume

    if not runs:
        raise ValueError("runs: give at least one result")
    labels = [r.label for r in runs]
    if len(set(labels)) != len(labels):
        raise ValueError(f"run labels must be unique, got {labels}")
    volumes = {}
    if voxel is not None:
        volumes = {r.label: motion_volume(r.result, voxel) for r in runs}
    page = _Page()
    stamp = _dt.datetime.now().strftime("%Y-%m-%d %H:%M")
    page.h(1, title)
    page.note(f"cablelife {__version__}, {stamp}; runs: {', '.join(labels)}")
    links = ([("comparison", "comparison")] if len(runs) > 1 else []) + [
        (f"run-{k}", r.label) for k, r in enumerate(runs)
    ]
    page.add("<nav>" + "".join(f'<a href="#{a}">{html.escape(t)}</a>' for a, t in links) + "</nav>")
    if len(runs) > 1:
        _comparison(page, runs, volumes, voxel or 0.004, bend_factor)
    for k, run in enumerate(runs):
        _run_section(page, k, run, volumes, color_by, frames, bend_factor)
    body = "\n".join(page.parts)
    return (
        '<!DOCTYPE html>\n<html lang="en"><head><meta charset="utf-8">'
        f"<title>{html.escape(title)}</title><style>{CSS}</style>{CHECK_HEAD}"
        f'<script type="text/javascript">{get_plotlyjs()}</script></head>'
        f'<body data-expected-figures="{page.figures}" data-expected-images="{page.images}">'
        f"\n{body}\n{CHECK_TAIL}</body></html>\n"
    )


def write_report(output: str | os.PathLike, runs: list[ReportRun], **kw) -> Path:
    """Builds the report and writes it atomically to ``output``."""
    return write_text_atomic(Path(output), build_report(runs, **kw))
