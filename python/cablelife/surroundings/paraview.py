"""ParaView time series of the surroundings: per body and saved step one .vtp surface (the
decimated display mesh moved with its body), indexed by ``<stem>_bodies.pvd`` (one part per
body)."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from cablelife.surroundings.display import SurroundingsGeometry


def write_bodies(geom: SurroundingsGeometry, output: str | os.PathLike, steps=None) -> Path:
    """Writes ``<output stem>_bodies.pvd`` and its files into ``<output stem>/``."""
    from cablelife.atomic import atomic_folder, write_text_atomic
    from cablelife.export.paraview import pvd_xml, surface_xml
    from cablelife.volume.sweep import select_steps

    output = Path(output)
    folder = output.parent / output.stem
    idx = select_steps(geom.time.size, steps)
    entries = []
    with atomic_folder(folder) as write:
        for b, name in enumerate(geom.bodies):
            _, faces = geom.meshes[b]
            safe = "".join(ch if ch.isalnum() or ch in "-_" else "_" for ch in name)
            for k in idx:
                file = f"{output.stem}_body_{safe}_{int(k):05d}.vtp"
                fields = {"time": float(geom.time[k])}
                write(file, surface_xml(geom.at(b, int(k)), faces, {}, {}, fields))
                entries.append((float(geom.time[k]), f"{folder.name}/{file}", b))
    return write_text_atomic(output.with_name(f"{output.stem}_bodies.pvd"), pvd_xml(entries))


def clearance_point_data(cable, k: int) -> dict[str, np.ndarray]:
    """Point data of the clearance at saved step ``k`` (empty without geometry)."""
    if cable.surroundings is None:
        return {}
    return {
        "clearance": cable.surroundings.value[k],
        "clearance_body": cable.surroundings.body[k].astype(float),
    }
