"""Interactive 3D views (plotly): the cable as a tube colour-coded by a section quantity with a
time slider, clips and bodies (origin, axes, links to their clips) marked, the motion volume as
a translucent mesh, and the damage map on the tube surface with its hot spots labelled."""

from __future__ import annotations

import tomllib

import numpy as np

from cablelife.plots.fatigue_data import DAMAGE_FLOOR, DamageMap
from cablelife.plots.runs import QUANTITIES, quantity
from cablelife.report.scene_data import BodyPose
from cablelife.report.tube import node_frames, tube_mesh
from cablelife.results import CableResult
from cablelife.scene import SceneError

#: Default number of animation frames (the saved steps are subsampled evenly).
FRAMES = 24


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


def scene_bodies(scene_toml: str, cable: CableResult, mode: str | None = None) -> list[BodyPose]:
    """The bodies of a result's scene at the cable's saved steps (``mode``: the run's mode,
    default the scene's); at rest when the motions cannot be evaluated (e.g. a measured file
    that is not at hand), none when the scene is unknown."""
    from cablelife.report.scene_data import body_poses, result_scene
    from cablelife.signals import SignalError
    from cablelife.simulate import euler_matrix

    try:
        scene = result_scene(scene_toml)
    except (SceneError, ValueError):
        return []
    mode = mode or scene.simulation.mode
    try:
        return body_poses(scene, cable.name, cable.time, mode)
    except (SceneError, SignalError, OSError, ValueError):
        n = cable.n_steps
        bodies = clip_bodies(scene_toml, cable.name)
        return [
            BodyPose(
                b.name,
                np.tile(np.asarray(b.origin, float), (n, 1)),
                np.tile(euler_matrix(b.orientation), (n, 1, 1)),
                [c for c, name in bodies.items() if name == b.name],
                False,
            )
            for b in scene.bodies
        ]


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
    axes["zaxis"]["tickvals"] = _ticks_off_corner(*axes["zaxis"]["range"])
    fig.update_layout(  # the legend left of the scene, not over it
        title=title,
        scene={**axes, "aspectmode": "cube", "domain": {"x": [0.3, 1.0], "y": [0.0, 1.0]}},
        margin={"l": 0, "r": 0, "t": 40, "b": 0},
        legend={"x": 0.0, "y": 1.0, "xanchor": "left", "font": {"size": 10}},
        height=560,
    )


def _ticks_off_corner(lo: float, hi: float) -> list[float]:
    """Round ticks in [lo, hi] (3–6 of them) but none within 8 % of the range above ``lo``: the
    lowest tick of the vertical axis sits at the corner where the y axis' ticks are and its
    label would be drawn over theirs (a duplicated "−0.5" there)."""
    span = hi - lo
    step = 10.0 ** np.floor(np.log10(span / 5))
    step *= next(m for m in (1.0, 2.0, 2.5, 5.0, 10.0) if span / (step * m) <= 6)
    ticks = np.arange(np.ceil(lo / step), np.floor(hi / step) + 1) * step
    return [float(round(v, 12)) for v in ticks if v - lo >= 0.08 * span]


def _clip_nodes(cable: CableResult) -> dict[str, int]:
    return {n: int(np.argmin(np.abs(cable.arc_length - c.s))) for n, c in cable.clips.items()}


def _scatter3d(points, **kw) -> dict:
    """A plotly Scatter3d (as a dict: plotly validates it in a figure, and the frames of the
    3D view need none, see :func:`cable_figure`) through ``points``: an (n, 3) array or
    (x, y, z) lists."""
    if isinstance(points, np.ndarray):
        points = (points[:, 0], points[:, 1], points[:, 2])
    x, y, z = points
    return {"type": "scatter3d", "x": x, "y": y, "z": z, **kw}


def _clip_trace(cable: CableResult, k: int, bodies: dict[str, str]):

    nodes = _clip_nodes(cable)
    p = cable.positions[k, list(nodes.values())] if nodes else np.zeros((0, 3))
    text = [f"clip {n} ({bodies.get(n, 'world')})" for n in nodes]
    return _scatter3d(
        p,
        mode="markers",
        hovertext=text,
        hoverinfo="text",
        name="clips (hover for names)",
        marker={"size": 6, "color": "black", "symbol": "diamond"},
    )


AXIS_COLOURS = ("red", "green", "blue")


def _segments(pairs) -> list[np.ndarray]:
    """x, y, z lists of line segments separated by gaps (None)."""
    pts: list = []
    for a, b in pairs:
        pts += [a, b, [None] * 3]
    arr = np.array(pts, dtype=object).reshape(-1, 3)
    return [arr[:, i].tolist() for i in range(3)]


def _body_traces(cable: CableResult, k: int, bodies: list[BodyPose], length: float) -> list:
    """Body origins (labelled with their clips), their x/y/z axes (red, green, blue) and dotted
    links from each origin to the clips it carries, at saved step ``k``."""

    if not bodies:
        return []
    o = np.array([b.origin[k] for b in bodies])
    labels = [f"body {b.name}" + (f" → {', '.join(b.clips)}" if b.clips else "") for b in bodies]
    traces = [
        _scatter3d(
            o,
            mode="markers",
            hovertext=labels,
            hoverinfo="text",
            name="bodies",
            marker={"size": 5, "color": "purple", "symbol": "square"},
        )
    ]
    for i, colour in enumerate(AXIS_COLOURS):
        x, y, z = _segments((b.origin[k], b.origin[k] + length * b.axes[k][:, i]) for b in bodies)
        traces.append(
            _scatter3d(
                (x, y, z),
                mode="lines",
                line={"color": colour, "width": 5},
                name="body axes x, y, z (red, green, blue)",
                legendgroup="body axes",
                showlegend=i == 0,
                hoverinfo="skip",
            )
        )
    nodes = _clip_nodes(cable)
    links = [
        (b.origin[k], cable.positions[k, nodes[c]]) for b in bodies for c in b.clips if c in nodes
    ]
    x, y, z = _segments(links) if links else ([], [], [])
    traces.append(
        _scatter3d(
            (x, y, z),
            mode="lines",
            line={"color": "purple", "width": 2, "dash": "dot"},
            name="body → clip",
            hoverinfo="skip",
        )
    )
    return traces


def mesh_trace(vertices: np.ndarray, faces: np.ndarray, **style):
    """A plotly Mesh3d of a triangle mesh (vertices (V, 3), faces (F, 3)) with ``style``."""
    import plotly.graph_objects as go

    v, f = vertices, faces
    return go.Mesh3d(x=v[:, 0], y=v[:, 1], z=v[:, 2], i=f[:, 0], j=f[:, 1], k=f[:, 2], **style)


def volume_trace(mesh, name: str, color: str, opacity: float):
    """A translucent plotly mesh of a motion volume's triangle mesh."""
    return mesh_trace(
        mesh.vertices,
        mesh.faces,
        color=color,
        opacity=opacity,
        name=name,
        hoverinfo="name",
        showlegend=True,
    )


def cable_figure(
    cable: CableResult,
    color_by: str = "bending",
    *,
    frames: int = FRAMES,
    volume=None,
    scene_toml: str = "",
    mode: str | None = None,
    n_angles: int = 8,
    title: str | None = None,
):
    """A plotly figure as a dict (``go.Figure(fig)`` for the object): the tube coloured by
    ``color_by`` (one of the plot quantities) at up to ``frames`` saved steps with a slider
    and play button, clips marked with their bodies, the bodies of ``scene_toml`` (the
    result's scene; ``mode`` the run's mode) with their axes and clips, and ``volume`` (a
    MotionVolume or TriangleMesh) as a translucent mesh. The first frame's traces are checked
    by plotly; the animation frames (the same traces moved) are plain dicts, as checking them
    cost most of the report's generation time."""
    import plotly.graph_objects as go

    if color_by not in QUANTITIES:
        raise ValueError(f"color_by = {color_by!r}: allowed are {', '.join(QUANTITIES)}")
    label, unit, _, _ = QUANTITIES[color_by]
    radius = float(cable.section.get("outer_radius", 0.005))
    values = node_values(cable, color_by)
    steps = frame_steps(cable.n_steps, frames)
    lo, hi = float(values[steps].min()), float(values[steps].max())
    bodies = clip_bodies(scene_toml, cable.name)
    poses = scene_bodies(scene_toml, cable, mode)

    def tube(k):
        m = tube_mesh(cable.positions[k], cable.quaternions[k], radius, n_angles)
        v = np.repeat(values[k], n_angles)
        return m, v

    m0, v0 = tube(steps[0])
    tube_trace = mesh_trace(
        m0.vertices,
        m0.faces,
        intensity=v0,
        meta={"tube": n_angles, "radius": radius},
        cmin=lo,
        cmax=hi,
        colorscale="Turbo",
        name=cable.name,
        colorbar={"title": {"text": f"{label} [{unit}]", "side": "right"}},
        flatshading=False,
        hovertemplate=f"{label}: %{{intensity:.4g}} {unit}<extra></extra>",
    )
    box = cable.positions.reshape(-1, 3)
    box = np.stack([box.min(axis=0) - radius, box.max(axis=0) + radius])
    axis_length = 0.08 * float((box[1] - box[0]).max())
    traces = [
        tube_trace,
        _clip_trace(cable, steps[0], bodies),
        *_body_traces(cable, steps[0], poses, axis_length),
    ]
    moving = list(range(len(traces)))
    if poses:
        o = np.concatenate([b.origin for b in poses])
        box = np.stack([np.minimum(box[0], o.min(0)), np.maximum(box[1], o.max(0))])
    if volume is not None:
        mesh = getattr(volume, "mesh", volume)
        if len(mesh.faces):
            vv = mesh.vertices
            traces.append(volume_trace(mesh, "motion volume", "#1f9e89", 0.18))
            box = np.stack([np.minimum(box[0], vv.min(0)), np.maximum(box[1], vv.max(0))])
    fig = go.Figure(data=traces)
    names = [f"{cable.time[k]:.4g}" for k in steps]
    frame_list = [
        {
            "name": name,
            "data": [
                {
                    "type": "mesh3d",
                    "x": m.vertices[:, 0],
                    "y": m.vertices[:, 1],
                    "z": m.vertices[:, 2],
                    "intensity": v,
                    "meta": {"tube": n_angles, "radius": radius},
                },
                _clip_trace(cable, k, bodies),
                *_body_traces(cable, k, poses, axis_length),
            ],
            "traces": moving,
        }
        for k, name in zip(steps, names, strict=True)
        for m, v in [tube(k)]
    ]
    _layout(fig, title or f"{cable.name}: {label}", box)
    if len(steps) > 1:
        fig.update_layout(
            sliders=[
                {
                    "x": 0.16,
                    "len": 0.84,
                    "y": 0.0,
                    "pad": {"t": 10, "b": 20},  # room below its time labels (else cut off)
                    "currentvalue": {"prefix": "t = ", "suffix": " s", "xanchor": "right"},
                    "steps": [
                        {
                            "label": name,
                            "method": "animate",
                            "args": [
                                [name],
                                {"mode": "immediate", "frame": {"duration": 0, "redraw": True}},
                            ],
                        }
                        for name in names
                    ],
                }
            ],
            updatemenus=[
                {
                    "type": "buttons",
                    "direction": "left",
                    "showactive": False,
                    "x": 0.0,
                    "xanchor": "left",
                    "y": 0.0,
                    "yanchor": "top",
                    "pad": {"t": 28, "r": 10},
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
    out = fig.to_dict()
    out["frames"] = frame_list
    return out


def damage_figure(
    cable: CableResult,
    damage: DamageMap,
    *,
    step: int = 0,
    hot_spots: int = 3,
    n_angles: int = 32,
    scene_toml: str = "",
    mode: str | None = None,
    title: str | None = None,
):
    """Paper Fig. 8: the damage map on the tube surface at saved step ``step`` (log colours),
    interpolated from the map's stations and surface angles onto the tube's rings (a vertex at
    γ sits at x + r (cos γ d1 + sin γ d2), the LDA's convention); hot spots marked and labelled
    with arc length, angle, damage and nearest clip; clips and bodies marked."""
    import plotly.graph_objects as go

    radius = float(cable.section.get("outer_radius", 0.005))
    m = tube_mesh(cable.positions[step], cable.quaternions[step], radius, n_angles)
    per_node = damage.on_surface(cable.arc_length, m.angles)
    top = float(damage.damage.max())
    floor = damage.floor if top > 0 else 1.0
    log = np.log10(np.maximum(per_node.ravel(), floor))
    lo, hi = np.log10(floor), np.log10(top) if top > 0 else 1.0
    ticks = np.arange(np.ceil(lo + 0.5), hi + 1e-9)  # whole decades above the floor
    traces = [
        mesh_trace(
            m.vertices,
            m.faces,
            intensity=log,
            meta={"tube": n_angles, "radius": radius},
            cmin=lo,
            cmax=hi,
            colorscale="Hot",
            reversescale=True,
            name="damage",
            colorbar={
                "title": {"text": "log10 damage", "side": "right"},
                "tickvals": [lo, *ticks],
                "ticktext": ["≤ floor", *[f"{v:g}" for v in ticks]],
            },
            hovertemplate="log10 damage: %{intensity:.2f}<extra></extra>",
        ),
        _clip_trace(cable, step, clip_bodies(scene_toml, cable.name)),
    ]
    spots = damage.hot_spots(hot_spots)
    if spots:
        d1, d2 = node_frames(cable.positions[step], cable.quaternions[step])
        for rank, h in enumerate(spots, 1):
            n = int(np.argmin(np.abs(cable.arc_length - h.arc_length)))
            x = _position_at(cable, step, h.arc_length)
            p = x + 1.6 * radius * (np.cos(h.angle) * d1[n] + np.sin(h.angle) * d2[n])
            clip = "" if h.nearest_clip is None else f", near {h.nearest_clip}"
            if h.nearest_clip is not None and h.clip_distance is not None:
                clip += f" ({h.clip_distance * 1e3:.0f} mm)"
            text = (
                f"#{rank} s = {h.arc_length:.3f} m, γ = {np.degrees(h.angle):.0f}°, "
                f"D = {h.damage:.3g}{clip}"
            )
            traces.append(
                _scatter3d(
                    p[None],
                    mode="markers",
                    hovertext=[text],
                    hoverinfo="text",
                    name=f"hot spot {text}",
                    marker={"size": 6, "color": "blue", "symbol": "circle-open"},
                )
            )
    box = np.stack([m.vertices.min(0), m.vertices.max(0)])
    poses = scene_bodies(scene_toml, cable, mode)
    traces += _body_traces(cable, step, poses, 0.08 * float((box[1] - box[0]).max()))
    fig = go.Figure(data=traces)
    _layout(
        fig,
        title
        or f"{cable.name}: pseudo-damage on the surface (floor {DAMAGE_FLOOR:g} × the maximum)",
        box,
    )
    return fig


def _position_at(cable: CableResult, step: int, s: float) -> np.ndarray:
    return np.array([np.interp(s, cable.arc_length, cable.positions[step, :, i]) for i in range(3)])


def volumes_figure(volumes: dict, cables: dict | None = None, title: str | None = None):
    """Paper Fig. 1: the motion volumes of several runs (label → MotionVolume or TriangleMesh)
    overlaid as translucent meshes, each with its cable's centre line at the first saved step
    (``cables``: label → CableResult)."""
    import plotly.graph_objects as go
    from plotly.colors import qualitative

    if not volumes:
        raise ValueError("volumes: give at least one motion volume")
    traces, points = [], []
    for k, (label, volume) in enumerate(volumes.items()):
        colour = qualitative.Plotly[k % 10]
        mesh = getattr(volume, "mesh", volume)
        if len(mesh.faces):
            v = mesh.vertices
            traces.append(volume_trace(mesh, f"motion volume {label}", colour, 0.35))
            points.append(v)
        cable = (cables or {}).get(label)
        if cable is not None:
            x = cable.positions[0]
            points.append(x)
            traces.append(
                _scatter3d(
                    x,
                    mode="lines",
                    line={"color": "#222222", "width": 3, "dash": "solid"},
                    name=f"cable {label} (t = {cable.time[0]:.3g} s)",
                    legendgroup=label,
                )
            )
    fig = go.Figure(data=traces)
    p = np.concatenate(points) if points else np.zeros((1, 3))
    _layout(fig, title or "motion volumes", np.stack([p.min(0), p.max(0)]))
    return fig


def with_view(fig: dict, traces: list[dict], label: str, keep: list[int] | None = None) -> dict:
    """The 3D view ``fig`` (a :func:`cable_figure`) with another view behind a button: the
    buttons (one menu above the scene) switch between the view's first picture (the quantity
    the tube is coloured by, animated) and the views added here, each ``traces`` (hidden until
    its button is pressed) shown together with the traces of ``fig`` at ``keep`` (indices; by
    default every trace but the coloured tube). One WebGL scene in the page instead of one per
    view: each costs about a second to draw without a GPU, whatever it shows."""
    n, e = len(fig["data"]), len(traces)
    keep = set(range(1, n) if keep is None else keep)
    for t in traces:
        t["visible"] = False
    fig["data"] = [*fig["data"], *traces]
    menus = fig["layout"].setdefault("updatemenus", [])
    menu = next((m for m in menus if m.get("name") == "views"), None)
    if menu is None:
        first = fig["data"][0].get("colorbar", {}).get("title", {}).get("text", "quantity")
        menu = {
            "name": "views",
            "type": "buttons",
            "direction": "left",
            "showactive": True,
            "active": 0,
            "x": 0.3,
            "xanchor": "left",
            "y": 1.0,
            "yanchor": "top",
            "pad": {"t": 4, "l": 4},
            "buttons": [{"label": first, "method": "restyle", "args": [{"visible": [True] * n}]}],
        }
        menus.append(menu)
    for b in menu["buttons"]:  # the views so far do not show the new traces
        b["args"][0]["visible"] = [*b["args"][0]["visible"], *[False] * e]
    visible = [i in keep for i in range(n)] + [True] * e
    menu["buttons"].append({"label": label, "method": "restyle", "args": [{"visible": visible}]})
    return fig


def extend_range(fig: dict, points: np.ndarray) -> None:
    """Widens the cube of a 3D view (:func:`_layout`) to hold ``points`` (n, 3) as well."""
    scene = fig["layout"]["scene"]
    lo = np.array([scene[f"{a}axis"]["range"][0] for a in "xyz"])
    hi = np.array([scene[f"{a}axis"]["range"][1] for a in "xyz"])
    lo, hi = np.minimum(lo, points.min(0)), np.maximum(hi, points.max(0))
    centre, half = (lo + hi) / 2, (hi - lo).max() / 2 * 1.02
    for i, a in enumerate("xyz"):
        scene[f"{a}axis"]["range"] = [centre[i] - half, centre[i] + half]


def with_damage(
    fig: dict,
    cable: CableResult,
    damage: DamageMap,
    *,
    scene_toml: str = "",
    mode: str | None = None,
) -> dict:
    """The 3D view ``fig`` (a :func:`cable_figure`) with the damage map of
    :func:`damage_figure` (on the tube at the first saved step, hot spots labelled) as a
    view behind the button "damage on the surface" (:func:`with_view`). The view starts with
    the quantity."""
    extra = [
        t
        for t in damage_figure(cable, damage, scene_toml=scene_toml, mode=mode).to_dict()["data"]
        if t.get("name") == "damage" or str(t.get("name", "")).startswith("hot spot")
    ]
    title = fig["layout"]["title"]
    fig["layout"]["title"] = {"text": title["text"] if isinstance(title, dict) else title}
    fig["layout"]["title"]["text"] += " / damage"
    return with_view(fig, extra, "damage on the surface")


def _view_buttons(fig: dict) -> list[dict]:
    """The view buttons of a 3D view (:func:`with_view`), one "all traces" button without."""
    for m in fig["layout"].get("updatemenus", []):
        if m.get("name") == "views":
            return m["buttons"]
    first = fig["data"][0].get("colorbar", {}).get("title", {}).get("text", "quantity")
    return [{"label": first, "method": "restyle", "args": [{"visible": [True] * len(fig["data"])}]}]


def merge_runs(a: dict, b: dict, label_a: str, label_b: str) -> dict | None:
    """One 3D view of two runs of a cable (e.g. a variant's dynamic and quasistatic runs):
    :func:`merge_views` of the two."""
    return merge_views([(label_a, a), (label_b, b)])


def merge_views(views: list[tuple[str, dict]]) -> dict | None:
    """One 3D view of several runs of a cable (the variants' dynamic and quasistatic runs):
    the views of all (:func:`cable_figure` with its :func:`with_view` views) in one WebGL
    scene, chosen from a drop-down ("<run>: <view>"), the slider moving all; the first starts
    shown. None when their animation frames differ (other saved times): they stay apart."""
    if len(views) < 2:
        return None
    names = [[f["name"] for f in v.get("frames", [])] for _, v in views]
    if any(n != names[0] for n in names[1:]):
        return None
    sizes = [len(v["data"]) for _, v in views]
    total, starts = sum(sizes), np.cumsum([0, *sizes[:-1]]).tolist()
    buttons = []
    for (label, v), n0, n in zip(views, starts, sizes, strict=True):
        for bt in _view_buttons(v):
            vis = [*[False] * n0, *bt["args"][0]["visible"], *[False] * (total - n0 - n)]
            buttons.append({**bt, "label": f"{label}: {bt['label']}", "args": [{"visible": vis}]})
    for _, v in views[1:]:
        for t in v["data"]:
            t["visible"] = False
    a = views[0][1]
    out = {**a, "data": [t for _, v in views for t in v["data"]]}
    out["frames"] = [
        {
            **fs[0],
            "data": [t for f in fs for t in f["data"]],
            "traces": [i + n0 for f, n0 in zip(fs, starts, strict=True) for i in f["traces"]],
        }
        for fs in zip(*(v.get("frames", []) for _, v in views), strict=True)
    ]
    layout = out["layout"] = {**a["layout"]}
    menus = [m for m in layout.get("updatemenus", []) if m.get("name") != "views"]
    menus.append(
        {
            "name": "views",
            "type": "dropdown",
            "direction": "down",
            "showactive": True,
            "active": 0,
            "x": 0.3,
            "xanchor": "left",
            "y": 1.0,
            "yanchor": "top",
            "pad": {"t": 4, "l": 4},
            "buttons": buttons,
        }
    )
    layout["updatemenus"] = menus
    for _, v in views[1:]:
        sv = v["layout"]["scene"]
        corners = np.array([[sv[f"{x}axis"]["range"][i] for x in "xyz"] for i in (0, 1)])
        extend_range(out, corners)
    name = a["data"][0].get("name", "cable")
    labels = [lab for lab, _ in views]
    runs = " and ".join([", ".join(labels[:-1]), labels[-1]])
    layout["title"] = {"text": f"{name}: runs {runs} (choose run and view)"}
    return out
