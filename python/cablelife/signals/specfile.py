"""Signal spec files (TOML): load, validate and generate every channel.

A spec file::

    [signal]
    duration = 60.0     # s
    time_step = 0.001   # s

    [[channels]]
    name = "engine_z"   # optional, names the output column
    channel = "z"
    frame = "global"
    signal = { type = "psd", profile = "iso16750-3:2007/I-engine", seed = 1 }
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
from pydantic import ValidationError

from cablelife.signals.errors import SignalError
from cablelife.signals.generate import kinematics, quantity_series
from cablelife.signals.kinematics import Kinematics, time_grid
from cablelife.signals.spec import NamedChannel, PsdSignal, SignalFile
from cablelife.tomlfile import read_toml


@dataclass
class ChannelSeries:
    """One generated channel of a spec file."""

    name: str
    motion: NamedChannel
    kinematics: Kinematics


def format_validation_error(err: ValidationError, source: str) -> str:
    """One line per problem: key path, message, the bad value."""
    lines = [f"{source}: {err.error_count()} problem(s)"]
    for e in err.errors():
        path = ".".join(str(p) for p in e["loc"]) or "(top level)"
        message = e["msg"].removeprefix("Value error, ")
        value = e.get("input")
        shown = "" if isinstance(value, dict) or e["type"] == "missing" else f" (got {value!r})"
        lines.append(f"  {path}: {message}{shown}")
    return "\n".join(lines)


def load_spec(path: Path) -> SignalFile:
    """Read and validate a spec file; a SignalError with every problem otherwise."""
    path = Path(path)
    data = read_toml(path, "spec file", SignalError)
    try:
        return SignalFile.model_validate(data)
    except ValidationError as err:
        raise SignalError(format_validation_error(err, f"spec file {str(path)!r}")) from None


def generate_channels(
    spec: SignalFile, base_dir: Path | None = None, allow_outside: bool = False
) -> tuple[np.ndarray, list[ChannelSeries]]:
    """The time grid and every channel of a spec."""
    settings = spec.signal
    time = time_grid(settings.duration, settings.time_step, settings.start)
    series = [
        ChannelSeries(name, ch, kinematics(ch.signal, time, base_dir, allow_outside))
        for name, ch in zip(spec.channel_names(), spec.channels, strict=True)
    ]
    return time, series


def target_quantity(motion: NamedChannel) -> str:
    """The quantity the signal was specified in (PSD: its quantity; else displacement...)."""
    signal = motion.signal
    if isinstance(signal, PsdSignal):
        return signal.target_quantity
    return getattr(signal, "quantity", "displacement")


def rms_summary(series: ChannelSeries, time_step: float) -> tuple[str, float, float | None]:
    """(quantity, generated RMS, target RMS or None) in SI units; PSD target up to Nyquist."""
    quantity = target_quantity(series.motion)
    values = quantity_series(series.kinematics, quantity)
    generated = float(np.sqrt(np.mean((values - values.mean()) ** 2)))
    signal = series.motion.signal
    if not isinstance(signal, PsdSignal):
        return quantity, generated, None
    f_low, f_high = signal.band
    target = signal.psd().rms(f_low, min(f_high, 0.5 / time_step))
    return quantity, generated, target
