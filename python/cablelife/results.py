"""Simulation results: per-cable arrays, HDF5 save/load (atomic), readable without cablelife.

HDF5 layout (every dataset carries a ``unit`` attribute)::

    /                        attrs: format="cablelife-result", format_version, cablelife_version,
                                    mode, scene_toml (the scene the run came from)
    /cables/<name>/time          (T,)        s
    /cables/<name>/arc_length    (N+1,)      m
    /cables/<name>/positions     (T, N+1, 3) m      node positions, global frame
    /cables/<name>/quaternions   (T, N, 4)   1      edge orientations, scalar first
    /cables/<name>/forces        (T, N, 3)   N      material frame, edges: F1, F2 shear, F3 tension
    /cables/<name>/moments       (T, N+1, 3) N m    material frame, nodes: M1, M2 bend, M3 torsion
    /cables/<name>/clips/<clip>/reaction_force   (T, 3) N    force of the clip on the cable
    /cables/<name>/clips/<clip>/reaction_moment  (T, 3) N m  moment about the clip point
    /cables/<name>/section       attrs: shape, outer_radius, inner_radius, poisson_ratio,
                                        EA, GA1, GA2, EI1, EI2, GJ, mass_per_length, from_measured
    /cables/<name>/solver        attrs and datasets: iterations (T,), residual (T,), ...
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path

import h5py
import numpy as np

from cablelife.h5files import atomic_h5, open_h5, plain

FORMAT = "cablelife-result"
FORMAT_VERSION = 1

ENERGIES = (
    "kinetic_energy",
    "elastic_energy",
    "dissipated_energy",
    "load_potential",
    "contact_energy",
)
# Contact outputs (docs/contact.md): per node normal and friction force of the geometry on the
# cable (T, N+1, 3, N, global), node state (T, N+1: 0 none, 1 stick, 2 slip), force per body
# (T, B, 3; B = world and the scene's bodies), smallest gap of the sampled cable surface (T,).
CONTACT_KEYS = (
    "contact_normal",
    "contact_friction",
    "contact_state",
    "body_contact_force",
    "contact_gap",
)
_CONTACT_UNITS = {
    "contact_normal": "N",
    "contact_friction": "N",
    "contact_state": "1",
    "body_contact_force": "N",
    "contact_gap": "m",
}

_UNITS = {
    "time": "s",
    "arc_length": "m",
    "positions": "m",
    "quaternions": "1",
    "forces": "N",
    "moments": "N m",
    "kinetic_energy": "J",
    "elastic_energy": "J",
    "dissipated_energy": "J",
    "load_potential": "J",
    "contact_energy": "J",
}


@dataclass
class ClipReaction:
    """Reaction of one clip on the cable over time (global frame)."""

    name: str
    s: float
    force: np.ndarray  # (T, 3) N
    moment: np.ndarray  # (T, 3) N m, about the clip point


@dataclass
class CableResult:
    """All saved steps of one cable."""

    name: str
    time: np.ndarray
    arc_length: np.ndarray
    positions: np.ndarray
    quaternions: np.ndarray
    forces: np.ndarray
    moments: np.ndarray
    clips: dict[str, ClipReaction] = field(default_factory=dict)
    section: dict = field(default_factory=dict)
    solver: dict = field(default_factory=dict)
    energies: dict[str, np.ndarray] = field(default_factory=dict)
    contact: dict[str, np.ndarray] = field(default_factory=dict)  # CONTACT_KEYS, if enabled

    @property
    def contact_force(self) -> np.ndarray | None:
        """Force of the geometry on the cable per node (T, N+1, 3), N, global: normal plus
        friction; None without contact."""
        if not self.contact:
            return None
        return self.contact["contact_normal"] + self.contact["contact_friction"]

    @property
    def n_steps(self) -> int:
        return int(self.time.shape[0])

    @property
    def curvature(self) -> np.ndarray:
        """Material-frame curvature (T, N+1, 3) from the elastic moments, 1/m (K = M / C^K).

        Damping moments are included in ``moments``; this is their elastic equivalent and only
        exact for static and quasistatic runs.
        """
        s = self.section
        stiff = np.array([s["EI1"], s["EI2"], s["GJ"]])
        return self.moments / stiff

    def bend_radius(self) -> np.ndarray:
        """Bend radius (T, N+1) in m from the bending curvature; inf where straight."""
        k = self.curvature[..., :2]
        kappa = np.hypot(k[..., 0], k[..., 1])
        with np.errstate(divide="ignore"):
            return np.where(kappa > 0, 1.0 / kappa, np.inf)


@dataclass
class Result:
    """The result of one run: one :class:`CableResult` per cable."""

    mode: str
    cables: dict[str, CableResult]
    scene_toml: str = ""
    complete: bool = True
    message: str = ""

    @property
    def cable(self) -> CableResult:
        """The only cable (an error if the scene has several)."""
        if len(self.cables) != 1:
            raise ValueError(
                f"result has {len(self.cables)} cables ({', '.join(self.cables)}); "
                "use result.cables[name]"
            )
        return next(iter(self.cables.values()))

    def save(self, path: str | os.PathLike) -> Path:
        """Write the result to HDF5 atomically (a temporary file renamed into place)."""
        return save_result(self, path)


def _put(group: h5py.Group, name: str, data: np.ndarray, unit: str | None = None) -> None:
    ds = group.create_dataset(name, data=np.asarray(data))
    ds.attrs["unit"] = unit if unit is not None else _UNITS.get(name, "1")


def save_result(result: Result, path: str | os.PathLike) -> Path:
    """Write ``result`` to ``path`` (HDF5) atomically."""
    from cablelife import __version__

    path = Path(path)
    with atomic_h5(path) as f:
        f.attrs["format"] = FORMAT
        f.attrs["format_version"] = FORMAT_VERSION
        f.attrs["cablelife_version"] = __version__
        f.attrs["mode"] = result.mode
        f.attrs["scene_toml"] = result.scene_toml
        f.attrs["complete"] = result.complete
        f.attrs["message"] = result.message
        cables = f.create_group("cables")
        for name, c in result.cables.items():
            g = cables.create_group(name)
            for key in ("time", "arc_length", "positions", "quaternions", "forces", "moments"):
                _put(g, key, getattr(c, key))
            for key, value in c.energies.items():
                _put(g, key, value)
            if c.contact:
                cg = g.create_group("contact")
                for key, value in c.contact.items():
                    _put(cg, key, value, _CONTACT_UNITS.get(key, "1"))
            clips = g.create_group("clips")
            for clip in c.clips.values():
                cg = clips.create_group(clip.name)
                cg.attrs["s"] = clip.s
                _put(cg, "reaction_force", clip.force, "N")
                _put(cg, "reaction_moment", clip.moment, "N m")
            sec = g.create_group("section")
            for key, value in c.section.items():
                sec.attrs[key] = value
            sol = g.create_group("solver")
            for key, value in c.solver.items():
                if isinstance(value, np.ndarray):
                    sol.create_dataset(key, data=value)
                else:
                    sol.attrs[key] = value
    return path


def load_result(path: str | os.PathLike) -> Result:
    """Read a result written by :func:`save_result`."""
    with open_h5(path, FORMAT, "result") as f:
        cables = {}
        for name, g in f["cables"].items():
            clips = {
                cn: ClipReaction(
                    cn, float(cg.attrs["s"]), cg["reaction_force"][()], cg["reaction_moment"][()]
                )
                for cn, cg in g["clips"].items()
            }
            energies = {k: g[k][()] for k in ENERGIES if k in g}
            solver = dict(g["solver"].attrs.items())
            solver.update({k: v[()] for k, v in g["solver"].items()})
            cables[name] = CableResult(
                name=name,
                time=g["time"][()],
                arc_length=g["arc_length"][()],
                positions=g["positions"][()],
                quaternions=g["quaternions"][()],
                forces=g["forces"][()],
                moments=g["moments"][()],
                clips=clips,
                section={k: plain(v) for k, v in g["section"].attrs.items()},
                solver={k: plain(v) for k, v in solver.items()},
                energies=energies,
                contact={k: v[()] for k, v in g["contact"].items()} if "contact" in g else {},
            )
        return Result(
            mode=str(f.attrs["mode"]),
            cables=cables,
            scene_toml=str(f.attrs.get("scene_toml", "")),
            complete=bool(f.attrs.get("complete", True)),
            message=str(f.attrs.get("message", "")),
        )
