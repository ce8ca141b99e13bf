"""The 3D view of a harness (docs/harness.md): the cables of one harness run in one scene,
coloured on one scale, the junctions marked, the time slider moving them all; behind a button
the damage map on every branch (one log scale)."""

from __future__ import annotations

import numpy as np

from cablelife.report.scene3d import (
    FRAMES,
    _scatter3d,
    cable_figure,
    damage_figure,
    extend_range,
    frame_steps,
    with_view,
)
from cablelife.results import Result

JUNCTION_MARKER = {"size": 9, "color": "#d62728", "symbol": "square"}


def _junction_trace(res: Result, k: int) -> dict:
    names = list(res.junctions)
    p = np.array([res.junctions[n].position[k] for n in names]).reshape(-1, 3)
    return _scatter3d(
        p,
        mode="markers+text",
        text=names,
        textposition="top center",
        hovertext=[f"junction {n}" for n in names],
        hoverinfo="text",
        name="junctions",
        marker=JUNCTION_MARKER,
    )


def _steps(res: Result, frames: int) -> np.ndarray:
    return frame_steps(next(iter(res.cables.values())).n_steps, frames)


def harness_figure(res: Result, color_by: str = "bending", frames: int = FRAMES, damage=None):
    """One plotly figure (a dict) of every cable of the harness result ``res``: the tubes
    coloured by ``color_by`` on one colour scale over time, their clips, the bodies (once) and
    the junctions (red squares, named); ``damage`` (cable name → DamageMap, optional) adds
    the view "damage on every branch" (:func:`cablelife.report.scene3d.with_view`)."""
    views = {
        name: cable_figure(c, color_by, frames=frames, scene_toml=res.scene_toml, mode=res.mode)
        for name, c in res.cables.items()
    }
    lo = min(v["data"][0]["cmin"] for v in views.values())
    hi = max(v["data"][0]["cmax"] for v in views.values())
    data: list[dict] = []
    moving: list[int] = []
    frame_data: list[list[dict]] = []
    first = None
    for i, (name, v) in enumerate(views.items()):
        keep = len(v["data"]) if i == 0 else 2  # the bodies once; each cable's tube and clips
        tube = v["data"][0]
        tube.update(cmin=lo, cmax=hi, showscale=i == 0)
        tube["hovertemplate"] = f"{name}: " + tube["hovertemplate"]
        clips = v["data"][1]
        clips.update(legendgroup="clips", showlegend=i == 0)
        clips["hovertext"] = [f"{name}: {h}" for h in clips["hovertext"]]
        moving_here = [t for t in v["frames"][0]["traces"] if t < keep] if v.get("frames") else []
        offset = len(data)
        data += v["data"][:keep]
        moving += [offset + t for t in moving_here]
        for f, fr in enumerate(v.get("frames", [])):
            if len(frame_data) <= f:
                frame_data.append([])
            for t in moving_here:
                trace = fr["data"][t]
                if trace.get("type") == "scatter3d" and t == 1:  # the clips: named per cable
                    trace["hovertext"] = [f"{name}: {h}" for h in trace["hovertext"]]
                frame_data[f].append(trace)
        if first is None:
            first = v
    steps = _steps(res, frames)
    data.append(_junction_trace(res, int(steps[0])))
    if len(steps) > 1:
        moving.append(len(data) - 1)
        for f, k in enumerate(steps):
            frame_data[f].append(_junction_trace(res, int(k)))
    out = {**first, "data": data}
    if first.get("frames"):
        out["frames"] = [
            {**fr, "data": frame_data[f], "traces": moving} for f, fr in enumerate(first["frames"])
        ]
    # The scene's cube holds every cable.
    for v in views.values():
        sc = v["layout"]["scene"]
        corners = np.array([[sc[f"{a}axis"]["range"][j] for a in "xyz"] for j in (0, 1)])
        extend_range(out, corners)
    out["layout"] = {**out["layout"]}
    label = data[0].get("colorbar", {}).get("title", {}).get("text", color_by)
    out["layout"]["title"] = {
        "text": f"harness ({len(views)} cables, {len(res.junctions)} junctions): {label}"
    }
    if damage:
        out = with_damage_of_branches(out, res, damage)
    return out


def with_damage_of_branches(fig: dict, res: Result, damage: dict) -> dict:
    """``fig`` (a :func:`harness_figure`) with the damage map of every branch in ``damage``
    (cable name → DamageMap) on one log scale, hot spots labelled, behind the button "damage
    on every branch"."""
    figs = {
        name: damage_figure(res.cables[name], d, scene_toml=res.scene_toml, mode=res.mode)
        for name, d in damage.items()
        if name in res.cables
    }
    if not figs:
        return fig
    meshes = {n: f.to_dict()["data"] for n, f in figs.items()}
    lo = min(t[0]["cmin"] for t in meshes.values())
    hi = max(t[0]["cmax"] for t in meshes.values())
    extra = []
    for i, (name, traces) in enumerate(meshes.items()):
        for t in traces:
            if t.get("name") == "damage":
                t.update(cmin=lo, cmax=hi, showscale=i == 0, name=f"damage: {name}")
                t["hovertemplate"] = f"{name}: " + t["hovertemplate"]
                extra.append(t)
            elif str(t.get("name", "")).startswith("hot spot"):
                t["name"] = f"{name} {t['name']}"
                t["hovertext"] = [f"{name} {h}" for h in t["hovertext"]]
                extra.append(t)
    if lo != hi:  # one colour bar for all branches: whole decades
        bar = extra[0]["colorbar"]
        ticks = np.arange(np.ceil(lo + 0.5), hi + 1e-9)
        bar["tickvals"] = [lo, *ticks]
        bar["ticktext"] = ["≤ floor", *[f"{v:g}" for v in ticks]]
    keep = [i for i, t in enumerate(fig["data"]) if t.get("type") != "mesh3d"]
    return with_view(fig, extra, "damage on every branch", keep=keep)
