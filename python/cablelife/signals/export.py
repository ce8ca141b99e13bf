"""Write generated signals to CSV or HDF5, atomically (temporary file, then os.replace)."""

from __future__ import annotations

from pathlib import Path

import h5py
import numpy as np

from cablelife.atomic import atomic_path
from cablelife.signals.errors import SignalError
from cablelife.signals.specfile import ChannelSeries
from cablelife.signals.units import si_amplitude_name

FORMAT = "cablelife-signal"
FORMAT_VERSION = 1


def _units(series: ChannelSeries) -> tuple[str, str, str]:
    dim = "angle" if series.motion.unit == "rad" else "length"
    return tuple(si_amplitude_name(q, dim) for q in ("displacement", "velocity", "acceleration"))


def write_csv(path: Path, time: np.ndarray, series: list[ChannelSeries], derivatives: bool):
    """Columns ``time``, then per channel its value (and ``_velocity``, ``_acceleration``)."""
    names, units, columns = ["time"], ["s"], [time]
    for s in series:
        u = _units(s)
        names.append(s.name)
        units.append(u[0])
        columns.append(s.kinematics.value)
        if derivatives:
            names += [f"{s.name}_velocity", f"{s.name}_acceleration"]
            units += [u[1], u[2]]
            columns += [s.kinematics.velocity, s.kinematics.acceleration]
    comment = "cablelife signal; units: " + ", ".join(
        f"{n} {u}" for n, u in zip(names, units, strict=True)
    )

    def write(tmp: Path) -> None:
        np.savetxt(
            tmp,
            np.column_stack(columns) + 0.0,  # + 0.0 turns -0.0 into 0.0
            delimiter=",",
            fmt="%.12g",
            header=f"# {comment}\n" + ",".join(names),
            comments="",
        )

    with atomic_path(path) as tmp:
        write(tmp)


def write_hdf5(path: Path, time: np.ndarray, series: list[ChannelSeries], spec_toml: str = ""):
    """``/time`` and ``/channels/<name>/{value,velocity,acceleration}`` with unit attributes."""

    def write(tmp: Path) -> None:
        with h5py.File(tmp, "w") as f:
            f.attrs["format"] = FORMAT
            f.attrs["format_version"] = FORMAT_VERSION
            f.attrs["spec_toml"] = spec_toml
            f.create_dataset("time", data=time).attrs["unit"] = "s"
            group = f.create_group("channels")
            for s in series:
                g = group.create_group(s.name)
                g.attrs["channel"] = s.motion.channel
                g.attrs["frame"] = s.motion.frame
                g.attrs["signal_json"] = s.motion.signal.model_dump_json()
                for key, unit in zip(("value", "velocity", "acceleration"), _units(s), strict=True):
                    g.create_dataset(key, data=getattr(s.kinematics, key)).attrs["unit"] = unit

    with atomic_path(path) as tmp:
        write(tmp)


def write_signals(
    path: Path,
    time: np.ndarray,
    series: list[ChannelSeries],
    derivatives: bool = False,
    spec_toml: str = "",
) -> None:
    """CSV (.csv) or HDF5 (.h5, .hdf5), chosen by the extension of ``path``."""
    suffix = Path(path).suffix.lower()
    if suffix == ".csv":
        write_csv(path, time, series, derivatives)
    elif suffix in (".h5", ".hdf5"):
        write_hdf5(path, time, series, spec_toml)
    else:
        raise SignalError(
            f"output {str(path)!r}: extension {suffix!r} is not supported; allowed: .csv, .h5, "
            ".hdf5"
        )
