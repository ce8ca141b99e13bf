"""The LDA's damage map drawn on the tube (3D view and ParaView) keeps the LDA's angle
convention: the surface angle γ runs from d1 towards d2 of the cable's material frame, so a
damage maximum at γ = 90° shows on the d2 side of the centre line."""

from __future__ import annotations

import xml.etree.ElementTree as ET

import numpy as np
import pytest
from cablelife.export import write_paraview
from cablelife.lda import analyse
from cablelife.plots import damage_maps
from cablelife.report import damage_figure
from cablelife.results import CableResult, ClipReaction, Result
from scipy.spatial.transform import Rotation

R = 0.004  # m
AXIS = np.array([1.0, 2.0, 2.0]) / 3.0


def frame() -> np.ndarray:
    """Material frame (columns d1, d2, d3) of a straight cable along AXIS, twisted so that no
    director is a global axis."""
    d3 = AXIS
    d1 = np.cross(d3, [0.0, 0.0, 1.0])
    d1 /= np.linalg.norm(d1)
    d1 = Rotation.from_rotvec(0.7 * d3).apply(d1)
    return np.column_stack([d1, np.cross(d3, d1), d3])


def bent_cable(sign: float) -> Result:
    """Node 4 bends with M1 = sign·0.05 cos(2π 5 t) N m while the tension N = 20 cos(2π 5 t) N
    cycles in phase: σ = N/A + M1 sin γ a/I has its largest range at γ = 90° (sign +) or
    270° (sign −)."""
    t = np.arange(2001) * 1e-3
    c = np.cos(2 * np.pi * 5 * t)
    n = 10
    s = np.linspace(0.0, 1.0, n + 1)
    moments = np.zeros((t.size, n + 1, 3))
    moments[:, 4, 0] = sign * 0.05 * c
    forces = np.zeros((t.size, n, 3))
    forces[:, 3:5, 2] = 20.0 * c[:, None]
    q = Rotation.from_matrix(frame()).as_quat(scalar_first=True)
    cable = CableResult(
        name="hose",
        time=t,
        arc_length=s,
        positions=np.broadcast_to(s[:, None] * AXIS, (t.size, n + 1, 3)).copy(),
        quaternions=np.broadcast_to(q, (t.size, n, 4)).copy(),
        forces=forces,
        moments=moments,
        clips={
            k: ClipReaction(k, v, np.zeros((t.size, 3)), np.zeros((t.size, 3)))
            for k, v in (("a", 0.0), ("b", 1.0))
        },
        section={
            "shape": "circle",
            "outer_radius": R,
            "poisson_ratio": 0.3,
            **{"EI1": 0.01, "EI2": 0.01, "GJ": 0.008},
        },
    )
    return Result("dynamic", {"hose": cable})


def hottest_direction(vertices: np.ndarray, values: np.ndarray, cable: CableResult) -> np.ndarray:
    """Unit vector from the centre line to the vertex of largest value (rings per node)."""
    v = int(np.argmax(values))
    ring = v // (len(vertices) // cable.arc_length.size)
    out = vertices[v] - cable.positions[0, ring]
    assert np.linalg.norm(out) == pytest.approx(R, rel=1e-6)  # plotly keeps float32
    assert cable.arc_length[ring] == pytest.approx(0.4)
    return out / R


@pytest.mark.parametrize("sign", [1.0, -1.0])
def test_damage_at_90_degrees_shows_on_the_d2_side(sign, tmp_path):
    res = bent_cable(sign)
    cable = res.cable
    analysis = analyse(res)
    spot = analysis.hot_spots(1)[0]
    assert spot.arc_length == pytest.approx(0.4)
    assert spot.angle == pytest.approx(90.0 if sign > 0 else 270.0)
    d2 = frame()[:, 1]

    # 3D view: the damage intensity on the tube (32 vertices per ring, through the file).
    dm, _ = damage_maps(analysis.save(tmp_path / "d.h5"))["hose"]
    fig = damage_figure(cable, dm)
    mesh = fig.data[0]
    vertices = np.column_stack([mesh.x, mesh.y, mesh.z])
    direction = hottest_direction(vertices, mesh.intensity, cable)
    np.testing.assert_allclose(direction, sign * d2, atol=1e-6)
    label = next(t for t in fig.data if t.name.startswith("hot spot #1"))
    marker = np.array([label.x[0], label.y[0], label.z[0]]) - cable.positions[0, 4]
    np.testing.assert_allclose(marker / np.linalg.norm(marker), sign * d2, atol=1e-6)
    assert "s = 0.400 m" in label.hovertext[0] and "near a (400 mm)" in label.hovertext[0]

    # ParaView: the tube part of step 0 carries the map per vertex and per triangle.
    pvd = write_paraview(cable, tmp_path / "pv.pvd", damage=analysis.cables["hose"], steps=[0])
    parts = ET.parse(pvd).getroot().find("Collection").findall("DataSet")
    assert [p.get("part") for p in parts] == ["0", "1"]
    piece = ET.parse(tmp_path / parts[1].get("file")).getroot().find("PolyData/Piece")
    arrays = {
        a.get("Name"): np.array(a.text.split(), dtype=float)
        for a in piece.iter("DataArray")
        if a.get("Name") in ("Points", "damage", "surface_angle")
    }
    pts = arrays["Points"].reshape(-1, 3)
    point_damage = [
        np.array(a.text.split(), dtype=float) for a in piece.find("PointData").iter("DataArray")
        if a.get("Name") == "damage"
    ][0]  # fmt: skip
    np.testing.assert_allclose(hottest_direction(pts, point_damage, cable), sign * d2, atol=1e-6)
    np.testing.assert_allclose(point_damage.max(), analysis.max_damage, rtol=1e-8)  # %.9g
    assert int(piece.get("NumberOfPolys")) == 2 * 10 * 16
    cell_damage = [
        np.array(a.text.split(), dtype=float) for a in piece.find("CellData").iter("DataArray")
        if a.get("Name") == "damage"
    ][0]  # fmt: skip
    assert cell_damage.size == 2 * 10 * 16 and cell_damage.max() < point_damage.max()


def test_paraview_command_with_a_damage_file(tmp_path):
    import typer
    from cablelife.export.cli import paraview_command
    from typer.testing import CliRunner

    res = bent_cable(1.0)
    path = res.save(tmp_path / "r.h5")
    analyse(res).save(tmp_path / "r.damage.h5")
    app = typer.Typer()
    app.command()(paraview_command)
    out = tmp_path / "pv" / "hose.pvd"
    args = [str(path), "-o", str(out), "--every", "1000", "--damage", str(tmp_path / "r.damage.h5")]
    run = CliRunner().invoke(app, args)
    assert run.exit_code == 0, run.output
    assert len(list((tmp_path / "pv" / "hose").glob("hose_tube_*.vtp"))) == 3
    other = bent_cable(1.0)
    other.cables["pipe"] = other.cables.pop("hose")
    other.cable.name = "pipe"
    analyse(other).save(tmp_path / "pipe.damage.h5")
    args[-1] = str(tmp_path / "pipe.damage.h5")
    bad = CliRunner().invoke(app, args)
    assert bad.exit_code == 2 and "has the cables pipe" in bad.output


def test_report_refuses_damage_of_another_result():
    from cablelife.report import ReportRun

    res = bent_cable(1.0)
    longer = analyse(res)
    longer.cables["hose"].arc_length = longer.cables["hose"].arc_length * 1.2
    with pytest.raises(ValueError, match="spans s = 0 … 1.2 m, but cable 'hose' of 'x' spans"):
        ReportRun("x", res, longer)
    renamed = analyse(res)
    renamed.cables["pipe"] = renamed.cables.pop("hose")
    with pytest.raises(ValueError, match="has cable 'pipe', the result has \\['hose'\\]"):
        ReportRun("x", res, renamed)
