"""Interactive 3D views (plotly): the cable as a tube colour-coded by a section quantity with a
time slider, clips marked, the motion volume as a translucent mesh, and the damage map on the
tube surface with its hot spots labelled."""

from __future__ import annotations

import tomllib

import numpy as np

from cablelife.plots.fatigue_data import DamageMap
from cablelife.plots.runs import QUANTITIES, quantity
from cablelife.report.tube import tube_mesh
from cablelife.results import CableResult

#: Default number of animation frames (the saved steps are subsampled evenly).
FRAMES = 40


def clip_bodies(scene_toml: str, cable: str) -> dict[str, str]:
    """Clip name → body name from a result's scene (empty when unknown)."""
    try:
        scene = tomllib.loads(scene_toml) if scene_toml else {}
    except tomllib.TOMLDecodeError:
        return {}
    for c in scene.get("cables", []):
        if c.get("name") == cable:
            return {k.get("name", ""): k.get("body", "world") for k in c.get("clips", [])}
    return {}


def frame_steps(n_steps: int, frames: int) -> np.ndarray:
    """At most ``frames`` saved-step indices, evenly spread, first and last included."""
    if frames < 1:
        raise ValueError(f"frames = {frames}: must be >= 1")
    return np.unique(np.linspace(0, n_steps - 1, min(frames, n_steps)).round().astype(int))


def node_values(cable: CableResult, name: str) -> np.ndarray:
    """A quantity at the nodes (T, N+1): edge quantities averaged onto the nodes."""
    _, v = quantity(cable, name)
    if v.shape[1] == cable.arc_length.size:
        return v
    pad = np.concatenate([v[:, :1], v, v[:, -1:]], axis=1)
    return 0.5 * (pad[:, :-1] + pad[:, 1:])


def _layout(fig, title: str, box: np.ndarray) -> None:
    centre, half = box.mean(axis=0), (box[1] - box[0]).max() / 2 * 1.05
    axes = {
        f"{a}axis": {"range": [centre[i] - half, centre[i] + half], "title": f"{a} [m]"}
        for i, a in enumerate("xyz")
    }
    fig.update_layout(
        title=title,
        scene={**axes, "aspectmode": "cube"},
        margin={"l": 0, "r": 0, "t": 40, "b": 0},
        legend={"x": 0.0, "y": 1.0, "xanchor": "left"},
        height=560,
    )


def _clip_trace(cable: CableResult, k: int, bodies: dict[str, str]):
    import plotly.graph_objects as go

    names = list(cable.clips)
    idx = [int(np.argmin(np.abs(cable.arc_length - cable.clips[n].s))) for n in names]
    p = cable.positions[k, idx] if idx else np.zeros((0, 3))
    text = [f"{n} ({bodies.get(n, 'world')})" for n in names]
    return go.Scatter3d(
        x=p[:, 0],
        y=p[:, 1],
        z=p[:, 2],
        mode="markers+text",
        text=text,
        name="clips",
        marker={"size": 6, "color": "black", "symbol": "diamond"},
        textposition="top center",
    )


def cable_figure(
    cable: CableResult,
    color_by: str = "bending",
    *,
    frames: int = FRAMES,
    volume=None,
    scene_toml: str = "",
    n_angles: int = 16,
    title: str | None = None,
):
    """A plotly figure: the tube coloured by ``color_by`` (one of the plot quantities) at up
    to ``frames`` saved steps with a slider and play button, clips marked with their bodies,
    and ``volume`` (a MotionVolume or TriangleMesh) as a translucent mesh."""
    import plotly.graph_objects as go

    if color_by not in QUANTITIES:
        raise ValueError(f"color_by = {color_by!r}: allowed are {', '.join(QUANTITIES)}")
    label, unit, _, _ = QUANTITIES[color_by]
    radius = float(cable.section.get("outer_radius", 0.005))
    values = node_values(cable, color_by)
    steps = frame_steps(cable.n_steps, frames)
    lo, hi = float(values[steps].min()), float(values[steps].max())
    bodies = clip_bodies(scene_toml, cable.name)

    def tube(k):
        m = tube_mesh(cable.positions[k], cable.quaternions[k], radius, n_angles)
        v = np.repeat(values[k], n_angles)
        return m, v

    m0, v0 = tube(steps[0])
    tube_trace = go.Mesh3d(
        x=m0.vertices[:, 0],
        y=m0.vertices[:, 1],
        z=m0.vertices[:, 2],
        i=m0.faces[:, 0],
        j=m0.faces[:, 1],
        k=m0.faces[:, 2],
        intensity=v0,
        cmin=lo,
        cmax=hi,
        colorscale="Turbo",
        name=cable.name,
        colorbar={"title": f"{label} [{unit}]"},
        flatshading=False,
        hovertemplate=f"{label}: %{{intensity:.4g}} {unit}<extra></extra>",
    )
    traces = [tube_trace, _clip_trace(cable, steps[0], bodies)]
    box = cable.positions.reshape(-1, 3)
    box = np.stack([box.min(axis=0) - radius, box.max(axis=0) + radius])
    if volume is not None:
        mesh = getattr(volume, "mesh", volume)
        if len(mesh.faces):
            vv, ff = mesh.vertices, mesh.faces
            traces.append(
                go.Mesh3d(
                    x=vv[:, 0],
                    y=vv[:, 1],
                    z=vv[:, 2],
                    i=ff[:, 0],
                    j=ff[:, 1],
                    k=ff[:, 2],
                    color="lightsteelblue",
                    opacity=0.25,
                    name="motion volume",
                    hoverinfo="name",
                    showlegend=True,
                )
            )
            box = np.stack([np.minimum(box[0], vv.min(0)), np.maximum(box[1], vv.max(0))])
    fig = go.Figure(data=traces)
    fig.frames = [
        go.Frame(
            name=f"{cable.time[k]:.4g}",
            data=[
                go.Mesh3d(x=m.vertices[:, 0], y=m.vertices[:, 1], z=m.vertices[:, 2], intensity=v),
                _clip_trace(cable, k, bodies),
            ],
            traces=[0, 1],
        )
        for k in steps
        for m, v in [tube(k)]
    ]
    _layout(fig, title or f"{cable.name}: {label}", box)
    if len(steps) > 1:
        fig.update_layout(
            sliders=[
                {
                    "currentvalue": {"prefix": "t = ", "suffix": " s"},
                    "steps": [
                        {
                            "label": f.name,
                            "method": "animate",
                            "args": [
                                [f.name],
                                {"mode": "immediate", "frame": {"duration": 0, "redraw": True}},
                            ],
                        }
                        for f in fig.frames
                    ],
                }
            ],
            updatemenus=[
                {
                    "type": "buttons",
                    "showactive": False,
                    "x": 0.0,
                    "y": 0.0,
                    "buttons": [
                        {
                            "label": "play",
                            "method": "animate",
                            "args": [
                                None,
                                {"frame": {"duration": 80, "redraw": True}, "fromcurrent": True},
                            ],
                        },
                        {
                            "label": "pause",
                            "method": "animate",
                            "args": [[None], {"mode": "immediate", "frame": {"duration": 0}}],
                        },
                    ],
                }
            ],
        )
    return fig


def damage_figure(
    cable: CableResult,
    damage: DamageMap,
    *,
    step: int = 0,
    hot_spots: int = 3,
    n_angles: int = 32,
    title: str | None = None,
):
    """Paper Fig. 8: the damage map on the tube surface at saved step ``step`` (log colours),
    interpolated from the map's stations and surface angles onto the tube's rings; hot spots
    marked and labelled with arc length, angle and value."""
    import plotly.graph_objects as go

    radius = float(cable.section.get("outer_radius", 0.005))
    m = tube_mesh(cable.positions[step], cable.quaternions[step], radius, n_angles)
    per_node = _damage_on_rings(damage, cable.arc_length, m.angles)
    positive = damage.damage[damage.damage > 0]
    floor = positive.min() if positive.size else 1.0
    log = np.log10(np.maximum(per_node.ravel(), floor))
    traces = [
        go.Mesh3d(
            x=m.vertices[:, 0],
            y=m.vertices[:, 1],
            z=m.vertices[:, 2],
            i=m.faces[:, 0],
            j=m.faces[:, 1],
            k=m.faces[:, 2],
            intensity=log,
            colorscale="Hot",
            reversescale=True,
            name="damage",
            colorbar={"title": "log10 damage"},
            hovertemplate="log10 damage: %{intensity:.2f}<extra></extra>",
        )
    ]
    spots = damage.hot_spots(hot_spots)
    if spots:
        pts, text = [], []
        for rank, h in enumerate(spots, 1):
            d1, d2 = _frame_at(cable, step, h.arc_length)
            x = _position_at(cable, step, h.arc_length)
            pts.append(x + 1.6 * radius * (np.cos(h.angle) * d1 + np.sin(h.angle) * d2))
            text.append(
                f"#{rank} s={h.arc_length:.3f} m γ={np.degrees(h.angle):.0f}° D={h.damage:.3g}"
            )
        p = np.array(pts)
        traces.append(
            go.Scatter3d(
                x=p[:, 0],
                y=p[:, 1],
                z=p[:, 2],
                mode="markers+text",
                text=text,
                name="hot spots",
                marker={"size": 5, "color": "blue"},
                textposition="top center",
            )
        )
    fig = go.Figure(data=traces)
    box = np.stack([m.vertices.min(0), m.vertices.max(0)])
    _layout(fig, title or f"{cable.name}: pseudo-damage on the surface", box)
    return fig


def _damage_on_rings(damage: DamageMap, arc_length: np.ndarray, angles: np.ndarray) -> np.ndarray:
    """Damage (N+1, G') at the tube's nodes and ring angles: linear in s, periodic in γ."""
    along = np.array([np.interp(arc_length, damage.arc_length, col) for col in damage.damage.T]).T
    a = np.concatenate([damage.angle, [damage.angle[0] + 2 * np.pi]])
    out = np.empty((len(arc_length), len(angles)))
    for n in range(len(arc_length)):
        row = np.concatenate([along[n], along[n, :1]])
        out[n] = np.interp(np.mod(angles - a[0], 2 * np.pi) + a[0], a, row)
    return out


def _position_at(cable: CableResult, step: int, s: float) -> np.ndarray:
    return np.array([np.interp(s, cable.arc_length, cable.positions[step, :, i]) for i in range(3)])


def _frame_at(cable: CableResult, step: int, s: float):
    from cablelife.report.tube import node_frames

    d1, d2 = node_frames(cable.positions[step], cable.quaternions[step])
    n = int(np.argmin(np.abs(cable.arc_length - s)))
    return d1[n], d2[n]
