"""ParaView export: the written XML parses back to the result's arrays."""

from __future__ import annotations

import copy
import xml.etree.ElementTree as ET

import numpy as np
import pytest
from cablelife.export import write_paraview
from cablelife.export.frames import rotation_matrices, to_global
from cablelife.plots.fatigue_data import DamageMap


@pytest.fixture(scope="module")
def cable():
    from cablelife.scene import scene_from_dict
    from cablelife.simulate import simulate
    from conftest import BASE

    d = copy.deepcopy(BASE)
    d["simulation"].update(mode="quasistatic", duration=0.5, time_step=0.1)
    sine = {"type": "sine", "amplitude": 0.05, "frequency": 1.0}
    d["bodies"] = [{"name": "engine", "motion": [{"channel": "y", "signal": sine}]}]
    d["cables"][0]["clips"][1]["body"] = "engine"
    return simulate(scene_from_dict(d)).cable


def arrays(node) -> dict[str, np.ndarray]:
    out = {}
    for a in node.findall("DataArray"):
        v = np.array(a.text.split(), dtype=float)
        comps = int(a.get("NumberOfComponents", "1"))
        out[a.get("Name")] = v.reshape(-1, comps) if comps > 1 else v
    return out


def test_rotation_matrices_are_the_material_frame(cable):
    r = rotation_matrices(cable.quaternions)
    np.testing.assert_allclose(
        r @ np.swapaxes(r, -1, -2), np.broadcast_to(np.eye(3), r.shape), atol=1e-12
    )
    # d3 = R e3 is the cable axis (up to the small shear strain).
    edge = np.diff(cable.positions, axis=1)
    edge /= np.linalg.norm(edge, axis=-1, keepdims=True)
    d3 = to_global(cable.quaternions, np.broadcast_to([0.0, 0.0, 1.0], edge.shape))
    assert np.einsum("...i,...i", d3, edge).min() > 0.999


def test_vtp_series_round_trip(cable, tmp_path):
    s = cable.arc_length
    dm = DamageMap(s, np.linspace(0, 2 * np.pi, 8, endpoint=False), np.outer(s, np.ones(8)))
    pvd = write_paraview(cable, tmp_path / "run.pvd", damage=dm)
    every = ET.parse(pvd).getroot().find("Collection").findall("DataSet")
    sets = [d for d in every if d.get("part") == "0"]  # part 1: the damage tube
    assert [float(d.get("timestep")) for d in sets] == pytest.approx(cable.time)
    tubes = [d for d in every if d.get("part") == "1"]
    assert [d.get("timestep") for d in tubes] == [d.get("timestep") for d in sets]
    n = cable.arc_length.size
    for k, ds in enumerate(sets):
        root = ET.parse(tmp_path / ds.get("file")).getroot()
        assert root.get("type") == "PolyData"
        piece = root.find("PolyData/Piece")
        assert int(piece.get("NumberOfPoints")) == n and int(piece.get("NumberOfLines")) == n - 1
        np.testing.assert_allclose(
            arrays(piece.find("Points"))["Points"], cable.positions[k], rtol=1e-8
        )
        pd = arrays(piece.find("PointData"))
        np.testing.assert_allclose(pd["moment"], cable.moments[k], rtol=1e-8, atol=1e-15)
        np.testing.assert_allclose(pd["curvature"], cable.curvature[k], rtol=1e-8, atol=1e-15)
        np.testing.assert_allclose(
            pd["displacement"], cable.positions[k] - cable.positions[0], atol=1e-12
        )
        np.testing.assert_allclose(pd["damage"], s, rtol=1e-8)
        assert np.all(pd["bend_radius"] <= 1e9)
        cd = arrays(piece.find("CellData"))
        assert cd["force"].shape == (n - 1, 3)
        np.testing.assert_allclose(cd["tension"], cable.forces[k, :, 2], rtol=1e-8, atol=1e-15)
        np.testing.assert_allclose(
            np.linalg.norm(cd["force_global"], axis=1),
            np.linalg.norm(cable.forces[k], axis=1),
            rtol=1e-7,
        )
        fd = arrays(root.find("PolyData/FieldData"))
        assert fd["tube_radius"][0] == cable.section["outer_radius"]
        assert fd["time"][0] == pytest.approx(cable.time[k])
        lines = arrays(piece.find("Lines"))
        assert lines["connectivity"].size == 2 * (n - 1)


def test_steps_and_bad_damage(cable, tmp_path):
    pvd = write_paraview(cable, tmp_path / "every2", steps=slice(None, None, 2))
    assert pvd.suffix == ".pvd"
    assert len(ET.parse(pvd).getroot().find("Collection")) == len(cable.time[::2])
    with pytest.raises(ValueError, match="damage has shape"):
        write_paraview(cable, tmp_path / "x.pvd", damage=np.ones(3))


def test_paraview_command(cable, tmp_path):
    import typer
    from cablelife.export.cli import paraview_command
    from cablelife.results import Result
    from typer.testing import CliRunner

    path = Result("quasistatic", {"hose": cable}).save(tmp_path / "r.h5")
    app = typer.Typer()
    app.command()(paraview_command)
    out = tmp_path / "pv" / "hose.pvd"
    run = CliRunner().invoke(app, [str(path), "-o", str(out), "--every", "3"])
    assert run.exit_code == 0, run.output
    assert len(list((tmp_path / "pv" / "hose").glob("*.vtp"))) == len(cable.time[::3])
    bad = CliRunner().invoke(app, [str(path), "--cable", "nope", "-o", str(out)])
    assert bad.exit_code == 2 and "cable = 'nope'" in bad.output
