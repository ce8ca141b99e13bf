"""ParaView time series: one VTK XML PolyData file (.vtp) per saved step and a .pvd index with
the times. The cable is N line cells (its edges) between N+1 points (its nodes).

Point data (nodes): ``moment`` (M1, M2, M3, material frame, N m), ``bending_moment`` |M1, M2|,
``torsion`` M3, ``curvature`` (1/m, material frame), ``bend_radius`` (m; straight stretches
get 1e9), ``displacement`` (from the first saved step, m), ``arc_length`` (m) and, when
given, ``damage``; with geometry in the scene ``clearance`` (m) and ``clearance_body``
(index of the nearest body). Cell data (edges): ``force`` (F1, F2, F3 material frame, N),
``force_global`` (N), ``shear_force`` |F1, F2|, ``tension`` F3. Field data: ``tube_radius``
(m), ``time`` (s).

With a damage map (an LDA result) every step also gets the tube surface as a second part
(``<stem>_tube_<k>.vtp``, triangles): point data ``damage`` at each vertex (surface angle γ
from d1 towards d2, as in the LDA), ``surface_angle`` (deg), ``arc_length``; cell data
``damage`` (mean of the triangle's vertices).
Data are written as ASCII (readable by any XML parser; fine for cables of a few hundred
nodes). Every file is written atomically.
"""

from __future__ import annotations

import os
from pathlib import Path
from xml.sax.saxutils import quoteattr

import numpy as np

from cablelife.atomic import atomic_folder, write_text_atomic
from cablelife.export.frames import to_global
from cablelife.results import CableResult
from cablelife.surroundings.paraview import clearance_point_data

#: Bend radius written where the cable is straight (VTK readers dislike inf).
STRAIGHT = 1e9


def _array(name: str, values: np.ndarray, fmt: str = "%.9g") -> str:
    v = np.asarray(values, dtype=np.float64)
    comps = 1 if v.ndim == 1 else v.shape[1]
    body = ((fmt + " ") * v.size % tuple(v.ravel().tolist()))[:-1]  # one format: 1.7× faster
    return (
        f'<DataArray type="Float64" Name={quoteattr(name)} NumberOfComponents="{comps}" '
        f'format="ascii">{body}</DataArray>'
    )


def _ints(name: str, values) -> str:
    body = " ".join(map(str, np.asarray(values, dtype=np.int64).ravel().tolist()))
    return f'<DataArray type="Int64" Name="{name}" format="ascii">{body}</DataArray>'


def polydata_xml(
    points: np.ndarray,
    point_data: dict[str, np.ndarray],
    cell_data: dict[str, np.ndarray],
    field_data: dict[str, float],
) -> str:
    """A VTK XML PolyData document of a polyline stored as one line cell per segment."""
    n = len(points)
    conn = np.column_stack([np.arange(n - 1), np.arange(1, n)]).ravel()
    offsets = 2 * np.arange(1, n)
    cells = f"<Lines>{_ints('connectivity', conn)}{_ints('offsets', offsets)}</Lines>\n"
    return _polydata(points, n - 1, 0, cells, point_data, cell_data, field_data)


def _polydata(points, n_lines, n_polys, cells, point_data, cell_data, field_data) -> str:
    """The PolyData document around the cell block ``cells`` (Lines or Polys)."""
    pd = "".join(_array(k, v) for k, v in point_data.items())
    cd = "".join(_array(k, v) for k, v in cell_data.items())
    fd = "".join(
        f'<DataArray type="Float64" Name={quoteattr(k)} NumberOfTuples="1" format="ascii">'
        f"{float(v)!r}</DataArray>"
        for k, v in field_data.items()
    )
    return (
        '<?xml version="1.0"?>\n'
        '<VTKFile type="PolyData" version="1.0" byte_order="LittleEndian" '
        'header_type="UInt64">\n<PolyData>\n'
        f"<FieldData>{fd}</FieldData>\n"
        f'<Piece NumberOfPoints="{len(points)}" NumberOfVerts="0" NumberOfLines="{n_lines}" '
        f'NumberOfStrips="0" NumberOfPolys="{n_polys}">\n'
        f"<PointData>{pd}</PointData>\n<CellData>{cd}</CellData>\n"
        f"<Points>{_array('Points', points)}</Points>\n"
        f"{cells}"
        "</Piece>\n</PolyData>\n</VTKFile>\n"
    )


def surface_xml(
    points: np.ndarray,
    faces: np.ndarray,
    point_data: dict[str, np.ndarray],
    cell_data: dict[str, np.ndarray],
    field_data: dict[str, float],
) -> str:
    """A VTK XML PolyData document of a triangle surface."""
    cells = (
        f"<Polys>{_ints('connectivity', np.ravel(faces))}"
        f"{_ints('offsets', 3 * np.arange(1, len(faces) + 1))}</Polys>\n"
    )
    return _polydata(points, 0, len(faces), cells, point_data, cell_data, field_data)


def pvd_xml(entries: list[tuple]) -> str:
    """A ParaView collection (.pvd) of (time, relative file name[, part]) entries."""
    rows = "".join(
        f'<DataSet timestep="{e[0]!r}" group="" part="{e[2] if len(e) > 2 else 0}" '
        f"file={quoteattr(e[1])}/>\n"
        for e in entries
    )
    return (
        '<?xml version="1.0"?>\n<VTKFile type="Collection" version="0.1" '
        f'byte_order="LittleEndian">\n<Collection>\n{rows}</Collection>\n</VTKFile>\n'
    )


def _damage_map(damage):
    """A DamageMap from a DamageMap or an LDA CableDamage; None for per-node arrays."""
    from cablelife.plots.fatigue_data import DamageMap

    if isinstance(damage, DamageMap):
        return damage
    if hasattr(damage, "damage_planes"):  # cablelife.lda CableDamage
        return DamageMap.from_lda(damage)
    return None


def _node_damage(cable: CableResult, damage) -> np.ndarray | None:
    if damage is None:
        return None
    dmap = _damage_map(damage)
    if dmap is not None:  # max around the section, at the nodes
        return np.interp(cable.arc_length, dmap.arc_length, dmap.along_cable)
    d = np.asarray(damage, dtype=float)
    if d.shape != cable.arc_length.shape:
        raise ValueError(
            f"damage has shape {d.shape}: must be one value per node {cable.arc_length.shape}, "
            "a DamageMap or an LDA CableDamage"
        )
    return d


def tube_angles(dmap) -> int:
    """Vertices per ring of the damage tube: the map's own surface points when there are at
    least 8 of them (no interpolation around the circumference at uniform angles), else 16."""
    return int(dmap.angle.size) if dmap.angle.size >= 8 else 16


def _tube_xml(cable: CableResult, k: int, dmap, radius: float, n_angles: int) -> str:
    from cablelife.report.tube import tube_mesh

    m = tube_mesh(cable.positions[k], cable.quaternions[k], radius, n_angles)
    d = dmap.on_surface(cable.arc_length, m.angles).ravel()
    point_data = {
        "damage": d,
        "surface_angle": np.tile(np.degrees(m.angles), cable.arc_length.size),
        "arc_length": np.repeat(cable.arc_length, n_angles),
    }
    cell_data = {"damage": d[m.faces].mean(axis=1)}
    fields = {"tube_radius": radius, "time": float(cable.time[k])}
    return surface_xml(m.vertices, m.faces, point_data, cell_data, fields)


def write_paraview(
    cable: CableResult,
    output: str | os.PathLike,
    *,
    damage=None,
    steps=None,
) -> Path:
    """Writes the saved steps (all, or a slice/indices ``steps``) of ``cable`` as
    ``<output>.pvd`` plus ``<output stem>/<stem>_<k>.vtp``; returns the .pvd path.
    ``damage``: one value per node, or a DamageMap or LDA CableDamage (its maximum around
    each section on the line, the full map on an extra tube part ``<stem>_tube_<k>.vtp``)."""
    from cablelife.volume.sweep import select_steps

    output = Path(output)
    if output.suffix != ".pvd":
        output = output.with_suffix(".pvd")
    folder = output.parent / output.stem
    idx = select_steps(cable.n_steps, steps)
    if idx.size == 0:
        raise ValueError(f"steps = {steps!r} selects no saved step")
    node_damage = _node_damage(cable, damage)
    dmap = _damage_map(damage) if damage is not None else None
    radius = float(cable.section.get("outer_radius", 0.0))
    if dmap is not None and not radius > 0:
        raise ValueError(
            f"cable {cable.name!r}: section outer_radius = {radius}: the damage tube needs > 0"
        )
    curvature = cable.curvature
    bend = cable.bend_radius()
    entries = []
    with atomic_folder(folder) as write:
        for k in idx:
            entries += _write_step(write, cable, k, output.stem, folder.name, node_damage, dmap,
                                   radius, curvature, bend)  # fmt: skip
    return write_text_atomic(output, pvd_xml(entries))


def _write_step(write, cable, k, stem, folder, node_damage, dmap, radius, curvature, bend):
    """The files of saved step ``k`` (the line, and the damage tube with ``dmap``); returns
    their .pvd entries."""
    x = cable.positions[k]
    m = cable.moments[k]
    f = cable.forces[k]
    point_data = {
        "arc_length": cable.arc_length,
        "moment": m,
        "bending_moment": np.hypot(m[:, 0], m[:, 1]),
        "torsion": m[:, 2],
        "curvature": curvature[k],
        "bend_radius": np.minimum(bend[k], STRAIGHT),
        "displacement": x - cable.positions[0],
    }
    if node_damage is not None:
        point_data["damage"] = node_damage
    point_data.update(clearance_point_data(cable, k))
    cell_data = {
        "force": f,
        "force_global": to_global(cable.quaternions[k], f),
        "shear_force": np.hypot(f[:, 0], f[:, 1]),
        "tension": f[:, 2],
    }
    fields = {"tube_radius": radius, "time": float(cable.time[k])}
    name = f"{stem}_{int(k):05d}.vtp"
    write(name, polydata_xml(x, point_data, cell_data, fields))
    entries = [(float(cable.time[k]), f"{folder}/{name}")]
    if dmap is not None:
        tube = f"{stem}_tube_{int(k):05d}.vtp"
        write(tube, _tube_xml(cable, k, dmap, radius, tube_angles(dmap)))
        entries.append((float(cable.time[k]), f"{folder}/{tube}", 1))
    return entries
