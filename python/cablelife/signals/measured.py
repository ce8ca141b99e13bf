"""Measured signals: CSV, ASAM MDF4 and TDMS readers, checks, and resampling to the time grid.

Resampling: when the simulation step is coarser than the record's, the record is first
low-pass filtered (Butterworth, order 8, zero phase by forward-backward filtering, cut-off at
80 % of the simulation's Nyquist frequency: the anti-aliasing filter); then a cubic spline
through the (filtered) samples is evaluated on the simulation grid. Velocity and acceleration
are the spline's derivatives.
"""

from __future__ import annotations

import io
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from cablelife.paths import SceneFileError, resolve_scene_file, shown_names
from cablelife.signals.errors import SignalError
from cablelife.signals.kinematics import Kinematics, time_step_of
from cablelife.signals.spec import MeasuredSignal

#: Allowed deviation of a record's time step from its median step (relative).
IRREGULAR_TOLERANCE = 0.01
#: Anti-aliasing cut-off as a fraction of the target Nyquist frequency.
ANTI_ALIAS_FRACTION = 0.8
ANTI_ALIAS_ORDER = 8


@dataclass
class Record:
    """Samples of one channel as stored in a file (file time, file units)."""

    time: np.ndarray
    value: np.ndarray
    source: str  # "file 'x.csv', channel 'z'" for messages


def read_record(
    path: Path,
    channel: str,
    fmt: str,
    time_channel: str | None = None,
    group: str | int | None = None,
) -> Record:
    """Read one channel and its time stamps from a CSV, MDF4 or TDMS file, checked."""
    if not path.is_file():
        raise SignalError(f"file {str(path)!r} does not exist (channel {channel!r})")
    if fmt == "csv":
        record = read_csv(path, channel, time_channel or "time")
    elif fmt == "mdf4":
        record = read_mdf4(path, channel, group)
    elif fmt == "tdms":
        record = read_tdms(path, channel, group, time_channel)
    else:
        raise SignalError(f"format {fmt!r} is not known; allowed: csv, mdf4, tdms")
    check_record(record)
    return record


def _find_column(names: list[str], wanted: str, path: Path, what: str) -> int:
    if wanted in names:
        return names.index(wanted)
    lowered = [n.lower() for n in names]
    if wanted.lower() in lowered:
        return lowered.index(wanted.lower())
    raise SignalError(
        f"file {str(path)!r}: {what} {wanted!r} not found; columns: {shown_names(names)}"
    )


def read_csv(path: Path, channel: str, time_channel: str = "time") -> Record:
    """A CSV with a header row of names; delimiter ``,``, ``;`` (decimal comma allowed) or tab.

    Lines starting with ``#`` are comments.
    """
    try:
        text = path.read_text(encoding="utf-8-sig")
    except UnicodeDecodeError as err:
        raise SignalError(
            f"file {str(path)!r}: not UTF-8 text (invalid byte at offset {err.start}); a CSV "
            "file must be UTF-8 text with a header row of column names"
        ) from None
    lines = text.splitlines()
    header_row = next(
        (i for i, line in enumerate(lines) if line.strip() and not line.lstrip().startswith("#")),
        None,
    )
    if header_row is None:
        raise SignalError(f"file {str(path)!r}: no header row with column names")
    header = lines[header_row]
    delimiter = ";" if ";" in header else "\t" if "\t" in header else ","
    names = [h.strip().strip('"').strip() for h in header.split(delimiter)]
    t_col = _find_column(names, time_channel, path, "time column")
    v_col = _find_column(names, channel, path, "channel")
    body = "\n".join(lines[header_row + 1 :])
    if delimiter != ",":
        body = body.replace(",", ".")  # decimal comma
    try:
        data = np.loadtxt(
            io.StringIO(body),
            delimiter=delimiter,
            usecols=(t_col, v_col),
            comments="#",
            ndmin=2,
            dtype=float,
        )
    except ValueError as err:
        # where, not what: the message must not quote the file's content
        where = re.search(r"row \d+, column \d+", str(err))
        raise SignalError(
            f"file {str(path)!r}: cannot read columns {names[t_col]!r} and {names[v_col]!r} as "
            f"numbers ({where.group(0) + ' after the header' if where else 'a non-numeric value'})"
        ) from None
    return Record(data[:, 0], data[:, 1], f"file {str(path)!r}, channel {names[v_col]!r}")


def read_mdf4(path: Path, channel: str, group: str | int | None = None) -> Record:
    """One channel of an ASAM MDF4 file (asammdf); ``group`` picks among duplicate names."""
    from asammdf import MDF

    try:
        mdf = MDF(path)
    except Exception as err:  # asammdf raises many types for foreign files
        # the reader's message may quote the file's first bytes: named by type only
        raise SignalError(
            f"file {str(path)!r}: cannot read as ASAM MDF ({type(err).__name__}: not an MDF "
            "file, or damaged)"
        ) from None
    try:
        occurrences = mdf.channels_db.get(channel)
        if not occurrences:
            names = sorted(n for n in mdf.channels_db if not n.startswith("time"))
            raise SignalError(
                f"file {str(path)!r}: channel {channel!r} not found; channels: "
                f"{', '.join(names[:30])}{' ...' if len(names) > 30 else ''}"
            )
        if group is None:
            if len(occurrences) > 1:
                groups = ", ".join(str(g) for g, _ in occurrences)
                raise SignalError(
                    f"file {str(path)!r}: channel {channel!r} is in several groups ({groups}); "
                    "set group to one of them"
                )
            grp, idx = occurrences[0]
        else:
            matches = [(g, i) for g, i in occurrences if str(g) == str(group)]
            if not matches:
                groups = ", ".join(str(g) for g, _ in occurrences)
                raise SignalError(
                    f"file {str(path)!r}: channel {channel!r} is not in group {group!r}; "
                    f"allowed: {groups}"
                )
            grp, idx = matches[0]
        signal = mdf.get(channel, group=grp, index=idx)
        values = np.asarray(signal.samples)
        if values.dtype.kind not in "fiub":
            raise SignalError(
                f"file {str(path)!r}: channel {channel!r} holds {values.dtype} samples; "
                "allowed: numbers"
            )
        return Record(
            np.asarray(signal.timestamps, dtype=float),
            values.astype(float),
            f"file {str(path)!r}, channel {channel!r}",
        )
    finally:
        mdf.close()


def read_tdms(
    path: Path, channel: str, group: str | int | None = None, time_channel: str | None = None
) -> Record:
    """One channel of a TDMS file (npTDMS).

    Time stamps come from ``time_channel`` in the same group, else from the channel's waveform
    properties (wf_start_offset, wf_increment).
    """
    from nptdms import TdmsFile

    try:
        tdms = TdmsFile.read(path)
    except Exception as err:
        raise SignalError(
            f"file {str(path)!r}: cannot read as TDMS ({type(err).__name__}: not a TDMS file, "
            "or damaged)"
        ) from None
    holding = [g for g in tdms.groups() if channel in [c.name for c in g.channels()]]
    if group is not None:
        holding = [g for g in holding if g.name == str(group)]
    if len(holding) != 1:
        available = ", ".join(f"{g.name}/{c.name}" for g in tdms.groups() for c in g.channels())
        if not holding:
            where = f" in group {group!r}" if group is not None else ""
            raise SignalError(
                f"file {str(path)!r}: channel {channel!r} not found{where}; channels: {available}"
            )
        raise SignalError(
            f"file {str(path)!r}: channel {channel!r} is in several groups "
            f"({', '.join(g.name for g in holding)}); set group to one of them"
        )
    grp = holding[0]
    source = f"file {str(path)!r}, channel {grp.name}/{channel}"
    values = np.asarray(grp[channel][:], dtype=float)
    if time_channel is not None:
        if time_channel not in [c.name for c in grp.channels()]:
            raise SignalError(
                f"file {str(path)!r}: time channel {time_channel!r} not in group {grp.name!r}; "
                f"channels: {', '.join(c.name for c in grp.channels())}"
            )
        time = np.asarray(grp[time_channel][:], dtype=float)
    else:
        try:
            time = np.asarray(grp[channel].time_track(), dtype=float)
        except (KeyError, ValueError) as err:
            raise SignalError(
                f"{source}: no time stamps (no waveform property wf_increment: {err}); "
                "set time_channel to the group's time channel"
            ) from None
    return Record(time, values, source)


def check_record(record: Record) -> float:
    """Check time stamps and values; return the median time step."""
    t, v = record.time, record.value
    if t.shape != v.shape or t.ndim != 1:
        raise SignalError(
            f"{record.source}: {v.size} values but {t.size} time stamps; allowed: one each"
        )
    if t.size < 2:
        raise SignalError(f"{record.source}: {t.size} sample(s); need at least 2")
    bad_t = np.flatnonzero(~np.isfinite(t))
    if bad_t.size:
        raise SignalError(
            f"{record.source}: time stamp {bad_t[0]} is {t[bad_t[0]]} "
            f"({bad_t.size} non-finite); allowed: finite numbers"
        )
    bad_v = np.flatnonzero(~np.isfinite(v))
    if bad_v.size:
        i = bad_v[0]
        raise SignalError(
            f"{record.source}: value {v[i]} at sample {i} (t = {t[i]:g} s), "
            f"{bad_v.size} non-finite value(s) in all; allowed: finite numbers "
            "(fill or cut the gap before use)"
        )
    steps = np.diff(t)
    if np.any(steps <= 0):
        i = int(np.flatnonzero(steps <= 0)[0])
        raise SignalError(
            f"{record.source}: time stamps must increase; sample {i + 1} has t = {t[i + 1]:g} s "
            f"after t = {t[i]:g} s"
        )
    dt = float(np.median(steps))
    deviation = np.abs(steps - dt) / dt
    if deviation.max() > IRREGULAR_TOLERANCE:
        i = int(np.argmax(deviation))
        raise SignalError(
            f"{record.source}: irregular time stamps; step {i} -> {i + 1} "
            f"(t = {t[i]:g} s) is {steps[i]:g} s, the median step is {dt:g} s "
            f"(allowed deviation {100 * IRREGULAR_TOLERANCE:g} %); resample the record first"
        )
    return dt


def anti_alias(value: np.ndarray, dt_source: float, dt_target: float) -> np.ndarray:
    """Zero-phase low-pass at 80 % of the target Nyquist frequency, if the target is coarser."""
    if dt_target <= dt_source * (1 + 1e-9):
        return value
    from scipy.signal import butter, sosfiltfilt

    cutoff = ANTI_ALIAS_FRACTION * 0.5 / dt_target  # Hz
    sos = butter(ANTI_ALIAS_ORDER, cutoff, btype="low", fs=1.0 / dt_source, output="sos")
    # pad (odd extension) over ~10 periods of the cut-off so the ends settle; the straight line
    # through the end values is taken out first (a low-pass passes it unchanged, but the filter's
    # start-up would not), so records that start or end on a ramp keep their ends
    trend = np.linspace(value[0], value[-1], value.size)
    padlen = int(np.ceil(10.0 / (cutoff * dt_source)))
    return trend + sosfiltfilt(sos, value - trend, padlen=min(padlen, value.size - 1))


def resample(
    time_source: np.ndarray, value_source: np.ndarray, time: np.ndarray
) -> tuple[Kinematics, np.ndarray]:
    """Resample a uniformly sampled record onto the uniform grid ``time`` (same time origin).

    Returns the kinematics and a mask of the grid points inside the record (up to one record
    step of extrapolation at either end); outside, the values are the record's end values.
    """
    from scipy.interpolate import CubicSpline

    dt_source = float(np.median(np.diff(time_source)))
    dt_target = time_step_of(time)
    filtered = anti_alias(value_source, dt_source, dt_target)
    spline = CubicSpline(time_source, filtered)
    first, last = time_source[0], time_source[-1]
    inside = (time >= first - dt_source) & (time <= last + dt_source)
    t = np.where(inside, time, np.clip(time, first, last))
    return Kinematics(spline(t), spline(t, 1), spline(t, 2)), inside


def measured(
    spec: MeasuredSignal,
    time: np.ndarray,
    base_dir: Path | None = None,
    allow_outside: bool = False,
) -> Kinematics:
    """The measured displacement/angle (SI) with derivatives on the simulation grid ``time``;
    ``spec.file`` follows the rule of files named in scenes (cablelife.paths)."""
    try:
        path = resolve_scene_file(
            base_dir, spec.file, allow_outside, f"measured signal (channel {spec.channel!r}) file"
        )
    except SceneFileError as err:
        raise SignalError(str(err)) from None
    record = read_record(path, spec.channel, spec.resolved_format, spec.time_channel, spec.group)
    unit = spec.amplitude_unit
    factor = spec.scale * (unit.factor if unit else 1.0)
    start = record.time[0] if spec.start_time is None else spec.start_time
    t = np.asarray(time, dtype=float)
    kin, inside = resample(record.time - start, factor * record.value, t)
    if not inside.all():
        if spec.beyond_end == "error" or not inside.any():
            raise SignalError(
                f"{record.source}: the record covers file time {record.time[0]:g} .. "
                f"{record.time[-1]:g} s, i.e. simulation time {record.time[0] - start:g} .. "
                f"{record.time[-1] - start:g} s, but the simulation needs {t[0]:g} .. "
                f"{t[-1]:g} s; allowed: a longer record, another start_time, or "
                "beyond_end = 'hold' or 'zero'"
            )
    if spec.remove_offset == "mean":
        kin.value = kin.value - kin.value[inside].mean()
    elif spec.remove_offset == "first":
        kin.value = kin.value - kin.value[np.flatnonzero(inside)[0]]
    if not inside.all():
        if spec.beyond_end == "zero":
            kin.value = np.where(inside, kin.value, 0.0)
        kin.velocity = np.where(inside, kin.velocity, 0.0)
        kin.acceleration = np.where(inside, kin.acceleration, 0.0)
    return kin
