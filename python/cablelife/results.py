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
    /cables/<name>/clips/<clip>/slid_length      (T,)   m    sliding clips: cable slid through
    /cables/<name>/section       attrs: shape, outer_radius, inner_radius, poisson_ratio,
                                        EA, GA1, GA2, EI1, EI2, GJ, mass_per_length, from_measured
    /cables/<name>/solver        attrs and datasets: iterations (T,), residual (T,), ...
    /cables/<name>/clearance, clearance_body, clearance_part   (T, N+1) with geometry
                                 (see cablelife.surroundings.data)
    /junctions/<name>/time, position (T, 3) m, quaternion (T, 4) 1   harnesses (docs/harness.md)
    /junctions/<name>/branches/<cable:end>/force, moment  (T, 3) N, N m: what that branch
                                 applies to the junction (global, about the junction point)
    /junctions/<name>/clip/force, moment  (T, 3) N, N m: a junction held by a clip: the clip's
                                 force and moment on it (global, about the junction point)
    /junctions/<name>/velocity, angular_velocity  (T, 3) m/s, rad/s, global: dynamic runs
    /harness/time, kinetic_energy, elastic_energy, load_potential, dissipated_energy  (T,) s, J:
                                 dynamic harness runs, totals of all cables and junctions

Datasets are chunked and compressed (gzip level 1 with the shuffle filter: lossless, readable by
any HDF5 tool); the histories (positions … clip reactions) are float64, or float32 when the
scene asks for it (``simulation.output_precision``). :func:`load_result` reads a dataset when it
is first used (see docs/results.md).
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from cablelife.h5files import atomic_h5, open_h5, plain, put_deflated
from cablelife.surroundings.data import CableClearance
from cablelife.surroundings.display import SurroundingsGeometry

if TYPE_CHECKING:
    import h5py

FORMAT = "cablelife-result"
FORMAT_VERSION = 1

#: Compression of every dataset: gzip level 1 after byte shuffling. Measured on the demo's
#: dynamic run (benchmarks/bench_results.py): 1.9× smaller than raw float64 (lzf: 1.8×, gzip 4:
#: 1.9×, slower), the write 2× faster than gzip 4; any HDF5 reader decodes gzip (lzf needs
#: h5py's filter).
COMPRESSION = {"compression": "gzip", "compression_opts": 1, "shuffle": True}
#: Saved steps per chunk of a history (T, …): ~0.3–0.6 MB chunks for 100 segments.
CHUNK_STEPS = 256
#: Precisions of the saved histories (``simulation.output_precision``).
PRECISIONS = ("float64", "float32")
HISTORIES = ("positions", "quaternions", "forces", "moments")

ENERGIES = (
    "kinetic_energy",
    "elastic_energy",
    "dissipated_energy",
    "load_potential",
    "contact_energy",
)
# Contact outputs (docs/contact.md): per node normal and friction force of the geometry on the
# cable (T, N+1, 3, N, global), node state (T, N+1: 0 none, 1 stick, 2 slip), force per body
# (T, B, 3; B = world and the scene's bodies), smallest gap of the sampled cable surface (T,;
# capped at the barrier's reach d̂).
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


class Deferred:
    """A dataset of a result file, read (as float64) when first used."""

    def __init__(self, path: str, name: str):
        self.path, self.name = path, name

    def read(self) -> np.ndarray:
        import h5py

        from cablelife.resultcheck import check_finite

        with h5py.File(self.path, "r") as f:
            ds = f[self.name]
            a = ds.astype(np.float64)[()] if ds.dtype.kind == "f" else ds[()]
        _, _, cable, *key = self.name.split("/")  # /cables/<cable>/<dataset…>
        check_finite(a, repr(self.path), cable, "/".join(key))
        return a

    def __repr__(self) -> str:
        return f"Deferred({self.path!r}, {self.name!r})"


class _LazyArray:
    """A dataclass field whose value may be a :class:`Deferred` dataset, read on first access
    (the file is opened per read, never held open)."""

    def __set_name__(self, owner, name: str) -> None:
        self.slot = "_" + name

    def __get__(self, obj, objtype=None):
        if obj is None:
            return None  # dataclass default
        value = obj.__dict__.get(self.slot)
        if isinstance(value, Deferred):
            value = value.read()
            obj.__dict__[self.slot] = value
        return value

    def __set__(self, obj, value) -> None:
        obj.__dict__[self.slot] = value


@dataclass(repr=False)
class ClipReaction:
    """Reaction of one clip on the cable over time (global frame)."""

    name: str
    s: float
    force: np.ndarray = _LazyArray()  # (T, 3) N
    moment: np.ndarray = _LazyArray()  # (T, 3) N m, about the clip point
    slid_length: np.ndarray | None = None  # (T,) m, sliding clips: cable slid through since s

    def __repr__(self) -> str:
        return f"ClipReaction({self.name!r}, s = {self.s:g} m)"


@dataclass(repr=False)
class CableResult:
    """All saved steps of one cable. Read from a file, the histories (positions, quaternions,
    forces, moments, clip reactions) are read when first used."""

    name: str
    time: np.ndarray
    arc_length: np.ndarray
    positions: np.ndarray = _LazyArray()
    quaternions: np.ndarray = _LazyArray()
    forces: np.ndarray = _LazyArray()
    moments: np.ndarray = _LazyArray()
    clips: dict[str, ClipReaction] = field(default_factory=dict)
    section: dict = field(default_factory=dict)
    solver: dict = field(default_factory=dict)
    energies: dict[str, np.ndarray] = field(default_factory=dict)
    surroundings: CableClearance | None = None  # clearance to the scene's geometry
    contact: dict[str, np.ndarray] = field(default_factory=dict)  # CONTACT_KEYS, if enabled

    @property
    def clearance(self) -> np.ndarray | None:
        """(T, N+1) clearance of the cable surface to the nearest geometry, m (None without
        geometry); negative inside. See docs/environment.md."""
        return None if self.surroundings is None else self.surroundings.value

    @property
    def clearance_body(self) -> np.ndarray | None:
        """(T, N+1) index of the nearest body into ``surroundings.bodies``."""
        return None if self.surroundings is None else self.surroundings.body

    def __repr__(self) -> str:
        return (
            f"CableResult({self.name!r}, {self.n_steps} steps, {self.arc_length.size - 1} "
            f"segments, clips {list(self.clips)})"
        )

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


@dataclass(repr=False)
class JunctionResult:
    """A harness junction over time (docs/harness.md): its position, orientation (scalar-first
    quaternion; identity at the reference: the junction's axes are then the global axes), and
    per joined end "cable:start|end" the force and moment (about the junction point, global)
    that branch applies to the junction."""

    name: str
    time: np.ndarray
    position: np.ndarray  # (T, 3) m
    quaternion: np.ndarray  # (T, 4)
    branch_force: dict[str, np.ndarray] = field(default_factory=dict)  # (T, 3) N
    branch_moment: dict[str, np.ndarray] = field(default_factory=dict)  # (T, 3) N m
    # A junction held by a clip: the clip's force and moment on it (global, about the
    # junction point); None for a free junction.
    reaction_force: np.ndarray | None = None  # (T, 3) N
    reaction_moment: np.ndarray | None = None  # (T, 3) N m
    # Dynamic runs: the junction's velocity and angular velocity, global; None otherwise.
    velocity: np.ndarray | None = None  # (T, 3) m/s
    angular_velocity: np.ndarray | None = None  # (T, 3) rad/s

    def __repr__(self) -> str:
        return f"JunctionResult({self.name!r}, branches {list(self.branch_force)})"


@dataclass
class Result:
    """The result of one run: one :class:`CableResult` per cable."""

    mode: str
    cables: dict[str, CableResult]
    scene_toml: str = ""
    complete: bool = True
    message: str = ""
    #: Precision of the histories in the file ("float64" or "float32"; docs/results.md).
    precision: str = "float64"
    surroundings: SurroundingsGeometry | None = None  # body geometry and poses, for pictures
    junctions: dict[str, JunctionResult] = field(default_factory=dict)  # harnesses only
    #: Dynamic harness runs: ``time`` and the total ``kinetic_energy``, ``elastic_energy``,
    #: ``load_potential``, ``dissipated_energy`` (T,) of all cables and junctions (J).
    harness_energies: dict[str, np.ndarray] = field(default_factory=dict)

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


def _put(
    group: h5py.Group,
    name: str,
    data: np.ndarray,
    unit: str | None = None,
    dtype: str | None = None,
) -> None:
    """A chunked, compressed dataset (scalars and tiny arrays as they are)."""
    a = np.asarray(data)
    if dtype is not None and a.dtype.kind == "f":
        a = a.astype(dtype)
    if a.ndim == 0 or a.size < 64:
        ds = group.create_dataset(name, data=a)
    elif COMPRESSION.get("compression") == "gzip" and COMPRESSION.get("shuffle"):
        # the default filters, the chunks deflated in threads (the same bytes)
        ds = put_deflated(group, name, a, CHUNK_STEPS, COMPRESSION.get("compression_opts", 4))
    else:
        chunks = (min(CHUNK_STEPS, a.shape[0]), *a.shape[1:])
        ds = group.create_dataset(name, data=a, chunks=chunks, **COMPRESSION)
    ds.attrs["unit"] = unit if unit is not None else _UNITS.get(name, "1")


def save_result(result: Result, path: str | os.PathLike, precision: str | None = None) -> Path:
    """Write ``result`` to ``path`` (HDF5) atomically; ``precision`` of the histories
    ("float64" or "float32", default ``result.precision``)."""
    from cablelife import __version__

    precision = precision or result.precision
    if precision not in PRECISIONS:
        raise ValueError(f"precision = {precision!r}: allowed are {', '.join(PRECISIONS)}")
    hist = None if precision == "float64" else precision
    path = Path(path)
    with atomic_h5(path) as f:
        f.attrs["format"] = FORMAT
        f.attrs["format_version"] = FORMAT_VERSION
        f.attrs["cablelife_version"] = __version__
        f.attrs["mode"] = result.mode
        f.attrs["scene_toml"] = result.scene_toml
        f.attrs["complete"] = result.complete
        f.attrs["message"] = result.message
        f.attrs["precision"] = precision
        cables = f.create_group("cables")
        for name, c in result.cables.items():
            g = cables.create_group(name)
            for key in ("time", "arc_length"):
                _put(g, key, getattr(c, key))
            for key in HISTORIES:
                _put(g, key, getattr(c, key), dtype=hist)
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
                _put(cg, "reaction_force", clip.force, "N", hist)
                _put(cg, "reaction_moment", clip.moment, "N m", hist)
                if clip.slid_length is not None:
                    _put(cg, "slid_length", clip.slid_length, "m", hist)
            sec = g.create_group("section")
            for key, value in c.section.items():
                sec.attrs[key] = value
            sol = g.create_group("solver")
            for key, value in c.solver.items():
                if isinstance(value, np.ndarray):
                    _put(sol, key, value)
                else:
                    sol.attrs[key] = value
            if c.surroundings is not None:
                c.surroundings.write(g, lambda *a, **k: _put(*a, **k, dtype=hist))
        if result.surroundings is not None:
            result.surroundings.write(f)
        if result.junctions:
            _write_junctions(f, result.junctions, hist)
        if result.harness_energies:
            g = f.create_group("harness")
            for key, value in result.harness_energies.items():
                _put(g, key, value, "s" if key == "time" else "J")
    return path


def _write_junctions(f, junctions: dict[str, JunctionResult], hist: str | None) -> None:
    top = f.create_group("junctions")
    for name, j in junctions.items():
        g = top.create_group(name)
        _put(g, "time", j.time)
        _put(g, "position", j.position, "m", hist)
        _put(g, "quaternion", j.quaternion, "1", hist)
        branches = g.create_group("branches")
        for end, force in j.branch_force.items():
            b = branches.create_group(end)
            _put(b, "force", force, "N", hist)
            _put(b, "moment", j.branch_moment[end], "N m", hist)
        if j.reaction_force is not None:
            clip = g.create_group("clip")
            _put(clip, "force", j.reaction_force, "N", hist)
            _put(clip, "moment", j.reaction_moment, "N m", hist)
        if j.velocity is not None:
            _put(g, "velocity", j.velocity, "m/s", hist)
            _put(g, "angular_velocity", j.angular_velocity, "rad/s", hist)


def _read_junctions(f) -> dict[str, JunctionResult]:
    if "junctions" not in f:
        return {}

    def get(ds) -> np.ndarray:
        return np.asarray(ds[()], dtype=np.float64)

    out = {}
    for name, g in f["junctions"].items():
        br = g["branches"]
        out[name] = JunctionResult(
            name=name,
            time=get(g["time"]),
            position=get(g["position"]),
            quaternion=get(g["quaternion"]),
            branch_force={e: get(b["force"]) for e, b in br.items()},
            branch_moment={e: get(b["moment"]) for e, b in br.items()},
            reaction_force=get(g["clip/force"]) if "clip" in g else None,
            reaction_moment=get(g["clip/moment"]) if "clip" in g else None,
            velocity=get(g["velocity"]) if "velocity" in g else None,
            angular_velocity=get(g["angular_velocity"]) if "angular_velocity" in g else None,
        )
    return out


def _read_harness_energies(f) -> dict[str, np.ndarray]:
    if "harness" not in f:
        return {}
    return {k: np.asarray(ds[()], dtype=np.float64) for k, ds in f["harness"].items()}


def load_result(path: str | os.PathLike, lazy: bool = True) -> Result:
    """Read a result written by :func:`save_result`. With ``lazy`` (default) the histories
    (positions, quaternions, forces, moments, clip reactions) are read when first used: the
    file must stay in place until then. Float32 histories are returned as float64."""
    from cablelife.resultcheck import check_result_file, check_result_values, warn_partial

    file = str(Path(path).resolve())

    def history(ds):
        d = Deferred(file, ds.name)
        return d if lazy else d.read()

    with open_h5(path, FORMAT, "result") as f:
        check_result_file(f, path)  # shapes, sizes, the stored scene: before reading
        cables = {}
        for name, g in f["cables"].items():
            clips = {
                cn: ClipReaction(
                    cn,
                    float(cg.attrs["s"]),
                    history(cg["reaction_force"]),
                    history(cg["reaction_moment"]),
                    cg["slid_length"][()] if "slid_length" in cg else None,
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
                positions=history(g["positions"]),
                quaternions=history(g["quaternions"]),
                forces=history(g["forces"]),
                moments=history(g["moments"]),
                clips=clips,
                section={k: plain(v) for k, v in g["section"].attrs.items()},
                solver={k: plain(v) for k, v in solver.items()},
                energies=energies,
                surroundings=CableClearance.read(g),
                contact={k: v[()] for k, v in g["contact"].items()} if "contact" in g else {},
            )
        result = Result(
            mode=str(f.attrs["mode"]),
            cables=cables,
            scene_toml=str(f.attrs.get("scene_toml", "")),
            complete=bool(f.attrs.get("complete", True)),
            message=str(f.attrs.get("message", "")),
            precision=str(f.attrs.get("precision", "float64")),
            surroundings=SurroundingsGeometry.read(f),
            junctions=_read_junctions(f),
            harness_energies=_read_harness_energies(f),
        )
    check_result_values(result, path)  # no NaN into reports, VTK files, damage maps
    warn_partial(result, path)
    return result
