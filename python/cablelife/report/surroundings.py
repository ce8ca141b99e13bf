"""Report section of the surroundings: the clearance summary, the clearance along the cable
(envelope over time: least value per arc length, with the time and body of it), and a 3D view
at the step of the least clearance — the tube coloured by clearance, the bodies' geometry
(decimated display meshes) where they are at that step."""

from __future__ import annotations

import numpy as np

from cablelife.report.margins import BOTTOM, EXTRA_HEIGHT, LEFT, TOP, legend_room
from cablelife.report.scene3d import mesh_trace
from cablelife.results import CableResult, Result
from cablelife.surroundings.summary import clearance_summary


def clearance_envelope_figure(cable: CableResult):
    """Least clearance over time per arc length, its time and nearest body in the hover."""
    import plotly.graph_objects as go

    cl = cable.surroundings
    k = np.argmin(cl.value, axis=0)
    nodes = np.arange(cl.value.shape[1])
    least = cl.value[k, nodes]
    names = np.array(cl.bodies, dtype=object)[cl.body[k, nodes]]
    fig = go.Figure()
    fig.add_scatter(
        x=cable.arc_length,
        y=least * 1e3,
        mode="lines+markers",
        name="least over time",
        customdata=np.column_stack([cable.time[k], names]),
        hovertemplate="s = %{x:.3f} m: %{y:.2f} mm at t = %{customdata[0]:.4g} s "
        "to %{customdata[1]}<extra></extra>",
    )
    fig.add_scatter(
        x=cable.arc_length,
        y=cl.value.max(axis=0) * 1e3,
        mode="lines",
        name="largest over time",
        line={"dash": "dot"},
    )
    # the limits as lines named in the legend (annotations at their ends overprint each other
    # when the clearance axis spans much more than min_clearance)
    ends = [float(cable.arc_length[0]), float(cable.arc_length[-1])]
    if cl.min_clearance > 0:
        fig.add_scatter(
            x=ends,
            y=[cl.min_clearance * 1e3] * 2,
            mode="lines",
            name=f"min_clearance {cl.min_clearance * 1e3:g} mm",
            line={"color": "orange", "dash": "dash"},
            hoverinfo="name",
        )
    fig.add_scatter(
        x=ends, y=[0, 0], mode="lines", name="contact (0)", line={"color": "red"}, hoverinfo="name"
    )
    fig.update_layout(
        title=f"clearance of {cable.name} along the cable",
        xaxis_title="arc length s [m]",
        yaxis_title="clearance [mm]",
        height=380 + EXTRA_HEIGHT,
        margin={"l": LEFT, "r": legend_room(t.name for t in fig.data), "t": TOP, "b": BOTTOM},
    )
    return fig


def least_clearance_step(cable: CableResult) -> int:
    """The saved step of the least clearance of ``cable`` (with surroundings)."""
    v = cable.surroundings.value
    return int(np.unravel_index(np.argmin(v), v.shape)[0])


def clearance_traces(
    cable: CableResult, result: Result, step: int, n_angles: int = 16
) -> tuple[list[dict], np.ndarray]:
    """The tube at saved step ``step`` coloured by clearance and the bodies' geometry there
    (plotly traces as dicts), and the points they span (n, 3)."""
    from cablelife.report.tube import tube_mesh

    cl = cable.surroundings
    radius = float(cable.section.get("outer_radius", 0.005))
    m = tube_mesh(cable.positions[step], cable.quaternions[step], radius, n_angles)
    values = np.repeat(cl.value[step], n_angles) * 1e3
    traces = [
        mesh_trace(
            m.vertices,
            m.faces,
            intensity=values,
            meta={"tube": n_angles, "radius": radius},
            colorscale="RdYlGn",
            # the colours resolve the near zone: up to 4 × min_clearance or 5 cm
            cmin=min(float(cl.value.min()) * 1e3, 0.0),
            cmax=max(4 * cl.min_clearance, 0.05) * 1e3,
            colorbar={"title": {"text": "clearance [mm]", "side": "right"}},
            name=f"{cable.name}: clearance",
            hovertemplate="clearance %{intensity:.2f} mm<extra></extra>",
        ).to_plotly_json()
    ]
    points = [m.vertices]
    geom = result.surroundings
    if geom is not None:
        t = float(cable.time[step])
        j = int(np.argmin(np.abs(geom.time - t)))
        for b, name in enumerate(geom.bodies):
            v = geom.at(b, j)
            f = geom.meshes[b][1]
            if not len(f):
                continue
            points.append(v)
            traces.append(
                mesh_trace(
                    v,
                    f,
                    color="lightsteelblue",
                    opacity=0.45,
                    name=name,
                    showlegend=True,
                    hovertemplate=f"{name}<extra></extra>",
                    flatshading=True,
                ).to_plotly_json()
            )
    return traces, np.concatenate(points)


def clearance_3d_figure(cable: CableResult, result: Result, step: int, n_angles: int = 16):
    """The tube at saved step ``step`` coloured by clearance, with the bodies' geometry."""
    import plotly.graph_objects as go

    traces, _ = clearance_traces(cable, result, step, n_angles)
    fig = go.Figure(traces)
    fig.update_layout(
        title=f"{cable.name} at t = {cable.time[step]:.4g} s (least clearance), surroundings",
        scene={"aspectmode": "data"},
        legend={"x": 0.0, "y": 0.0, "xanchor": "left", "yanchor": "bottom"},
        height=560,
        margin={"l": 0, "r": 0, "t": 40, "b": 0},
    )
    return fig


def with_clearance(view: dict, cable: CableResult, result: Result) -> dict:
    """The run's 3D view (:func:`cablelife.report.scene3d.cable_figure`) with the clearance
    as another view behind a button: the tube at the step of the least clearance coloured by
    clearance, and the bodies' geometry where they are then (the cube widened to hold them)."""
    from cablelife.report.scene3d import extend_range, with_view

    step = least_clearance_step(cable)
    traces, points = clearance_traces(cable, result, step)
    extend_range(view, points)
    label = f"clearance at t = {cable.time[step]:.3g} s (least), surroundings"
    view["layout"]["title"]["text"] += " / clearance"
    return with_view(view, traces, label, keep=[])


def surroundings_section(
    page, result: Result, name: str, view_at: str = "its 3D view above"
) -> None:
    """Adds the clearance of cable ``name`` to a report page (``report.html._Page``)."""
    cable = result.cables[name]
    if cable.surroundings is None:
        return
    s = clearance_summary(cable)
    page.h(4, f"clearance of {name} to the surroundings")
    rows = []
    for body, v in s["bodies"].items():
        if v is None:
            rows.append([body, "never nearest", "", "", ""])
        else:
            rows.append(
                [body, f"{v['min'] * 1e3:.2f}", f"{v['s']:.3f}", f"{v['t']:.4g}", v["part"]]
            )
    page.table(
        ["body", "least clearance [mm]", "at s [m]", "at t [s]", "nearest part"],
        rows,
        "clearance of the cable surface (negative: inside)",
    )
    page.table(
        ["cable length (max over time)", "length [m]", "at t [s]"],
        [
            [
                "in collision (clearance < 0)",
                f"{s['length_in_collision']:.4g}",
                f"{s['length_in_collision_t']:.4g}",
            ],
            [
                f"closer than min_clearance = {s['min_clearance'] * 1e3:g} mm",
                f"{s['length_below_min']:.4g}",
                f"{s['length_below_min_t']:.4g}",
            ],
        ],
    )
    page.plotly(clearance_envelope_figure(cable), f"clearance of {name} along the cable")
    t = cable.time[least_clearance_step(cable)]
    page.note(
        f"the clearance on the surface of {name} at t = {t:.4g} s (its least) with the bodies' "
        f"geometry: 'clearance at t = …' in {view_at}"
    )
