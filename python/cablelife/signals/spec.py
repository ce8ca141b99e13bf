"""Signal specifications (pydantic v2): what the scene file and the ``signal`` CLI accept.

A body's motion is a list of :class:`ChannelMotion` (channel x, y, z, rx, ry, rz; frame global or
body; one signal). A signal is one of sine, sweep, psd, measured, table, told apart by ``type``.
Amplitudes are in SI (m, rad and their time derivatives) unless ``unit`` says otherwise.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Annotated, Literal

from pydantic import BaseModel, ConfigDict, Field, Strict, model_validator

from cablelife.scene_types import NonNegativeFloat, PositiveFloat, Real, Time
from cablelife.signals.profiles import get_profile
from cablelife.signals.psd import PowerLawPsd
from cablelife.signals.units import (
    QUANTITIES,
    Quantity,
    Unit,
    amplitude_unit,
    psd_unit,
)

Channel = Literal["x", "y", "z", "rx", "ry", "rz"]
Frame = Literal["global", "body"]
TRANSLATIONS = ("x", "y", "z")
ROTATIONS = ("rx", "ry", "rz")

# Fades and sweep durations: at most 1e6 s (11 days; longer overflows the ramp polynomials).
Seconds = Time


class _Spec(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)


def _an(word: str) -> str:
    return f"an {word}" if word[0] in "aeiou" else f"a {word}"


def _checked_amplitude_unit(text: str | None, quantity: str) -> Unit | None:
    if text is None:
        return None
    unit = amplitude_unit(text)
    if unit.quantity != quantity:
        raise ValueError(
            f"unit {text!r} is {_an(unit.quantity)} unit but quantity is {quantity!r}; "
            f"give {_an(quantity)} unit or set quantity = {unit.quantity!r}"
        )
    return unit


class SineSignal(_Spec):
    """q(t) = amplitude · sin(2π·frequency·t + phase) of ``quantity``; displacement + offset.

    The displacement follows analytically (an acceleration sine A sin θ is the displacement
    −A/ω² sin θ). A fade-in multiplies the displacement by a smooth (C², quintic) ramp from 0 to 1
    over ``fade_in`` seconds. ``offset`` (m or rad) is added to the displacement, not faded.
    """

    type: Literal["sine"]
    amplitude: NonNegativeFloat
    frequency: PositiveFloat  # Hz
    phase: Real = 0.0  # rad
    offset: Real = 0.0  # m or rad
    quantity: Quantity = "displacement"
    unit: str | None = None  # of amplitude; default SI (m, m/s, m/s² or rad, ...)
    fade_in: Seconds = 0.0  # s

    @model_validator(mode="after")
    def _check(self) -> SineSignal:
        _checked_amplitude_unit(self.unit, self.quantity)
        return self

    @property
    def amplitude_unit(self) -> Unit | None:
        return _checked_amplitude_unit(self.unit, self.quantity)


class SweepSignal(_Spec):
    """A sine sweep f0 → f1 (linear or logarithmic) starting at t = 0.

    The rate is ``octaves_per_minute`` (logarithmic sweeps, the test-lab convention) or the
    ``duration``. The ``amplitude`` of ``quantity`` is constant; the displacement amplitude is
    amplitude/(2πf)^k (k = 0, 1, 2). Outside 0 ≤ t ≤ duration the signal is zero; ``fade``
    seconds of smooth ramp at both ends avoid the jumps there.
    """

    type: Literal["sweep"]
    f0: PositiveFloat  # Hz
    f1: PositiveFloat  # Hz
    law: Literal["linear", "log"] = "log"
    octaves_per_minute: PositiveFloat | None = None
    duration: Annotated[float, Strict(), Field(gt=0, le=1e6)] | None = None  # s
    amplitude: NonNegativeFloat
    quantity: Quantity = "displacement"
    unit: str | None = None
    phase: Real = 0.0  # rad
    fade: Seconds = 0.0  # s, at start and end

    @model_validator(mode="after")
    def _check(self) -> SweepSignal:
        _checked_amplitude_unit(self.unit, self.quantity)
        if self.f0 == self.f1:
            raise ValueError(f"f0 and f1 are both {self.f0} Hz; allowed: different frequencies")
        if (self.octaves_per_minute is None) == (self.duration is None):
            raise ValueError(
                "give exactly one of octaves_per_minute (log sweeps) and duration (s); got "
                f"octaves_per_minute={self.octaves_per_minute}, duration={self.duration}"
            )
        if self.octaves_per_minute is not None and self.law != "log":
            raise ValueError(
                f"octaves_per_minute applies to law = 'log', not {self.law!r}; "
                "give duration for a linear sweep"
            )
        if 2 * self.fade > self.sweep_duration:
            raise ValueError(
                f"fade = {self.fade} s is more than half the sweep duration "
                f"{self.sweep_duration:g} s; allowed: fade <= {self.sweep_duration / 2:g} s"
            )
        return self

    @property
    def sweep_duration(self) -> float:
        """Duration in s (given, or 60·log2(f1/f0)/rate for a rate in octaves per minute)."""
        if self.duration is not None:
            return self.duration
        return 60.0 * abs(math.log2(self.f1 / self.f0)) / self.octaves_per_minute

    @property
    def amplitude_unit(self) -> Unit | None:
        return _checked_amplitude_unit(self.unit, self.quantity)


class PsdSignal(_Spec):
    """A Gaussian random signal with a one-sided PSD: breakpoints or a named profile.

    ``breakpoints`` are [[Hz, value], ...] in ``unit`` (default SI of ``quantity``), log-log
    interpolated. ``profile`` names a standard profile (see ``cablelife.signals.profiles``).
    ``scale`` multiplies the signal (the PSD by scale²). Content outside [f_low, f_high] is zero;
    defaults: the lowest and highest breakpoints. ``seed`` makes the signal reproducible; give
    channels that must be independent different seeds. ``fade_in`` (s) multiplies the signal by
    the quintic ramp of the sine's fade-in, so a dynamic run starts at rest instead of with the
    random signal's velocity at t = 0 (a start-up transient); the RMS then counts the ramp.
    """

    type: Literal["psd"]
    breakpoints: list[tuple[PositiveFloat, PositiveFloat]] | None = None
    profile: str | None = None
    quantity: Quantity | None = None
    unit: str | None = None
    scale: PositiveFloat = 1.0
    seed: Annotated[int, Strict(), Field(ge=0)] = 0
    f_low: PositiveFloat | None = None  # Hz
    f_high: PositiveFloat | None = None  # Hz
    fade_in: Seconds = 0.0  # s

    @model_validator(mode="after")
    def _check(self) -> PsdSignal:
        if (self.breakpoints is None) == (self.profile is None):
            raise ValueError("give exactly one of breakpoints and profile")
        if self.profile is not None:
            profile = get_profile(self.profile)
            if self.quantity is not None and self.quantity != profile.quantity:
                raise ValueError(
                    f"quantity {self.quantity!r} does not match profile {profile.name!r}, "
                    f"which is {_an(profile.quantity)} PSD; allowed: {profile.quantity!r} or omit"
                )
            if self.unit is not None:
                raise ValueError(
                    f"unit {self.unit!r} is not allowed with a profile: profile "
                    f"{profile.name!r} is in {profile.unit}"
                )
        else:
            if self.quantity is None:
                raise ValueError(
                    f"quantity is required with breakpoints; allowed: {', '.join(QUANTITIES)}"
                )
            self._check_breakpoints()
            if self.unit is not None:
                unit = psd_unit(self.unit)
                if unit.quantity != self.quantity:
                    raise ValueError(
                        f"unit {self.unit!r} is {_an(unit.quantity)} PSD unit but quantity is "
                        f"{self.quantity!r}"
                    )
        f = self.psd().frequency
        f_low = f[0] if self.f_low is None else self.f_low
        f_high = f[-1] if self.f_high is None else self.f_high
        if not f[0] <= f_low < f[-1]:
            raise ValueError(
                f"f_low = {self.f_low} Hz lies outside the breakpoints; "
                f"allowed: {f[0]:g} <= f_low < {f[-1]:g} Hz"
            )
        if not f_low < f_high <= f[-1]:
            raise ValueError(
                f"f_high = {self.f_high} Hz: allowed {f_low:g} < f_high <= {f[-1]:g} Hz"
            )
        return self

    def _check_breakpoints(self) -> None:
        bp = self.breakpoints
        if len(bp) < 2:
            raise ValueError(f"breakpoints: need at least 2 [Hz, value] pairs, got {len(bp)}")
        for i in range(1, len(bp)):
            if bp[i][0] <= bp[i - 1][0]:
                raise ValueError(
                    f"breakpoints: frequencies must increase strictly; breakpoint {i} has "
                    f"{bp[i][0]} Hz after {bp[i - 1][0]} Hz"
                )

    def psd(self) -> PowerLawPsd:
        """The target PSD in SI units of its quantity, scale applied."""
        if self.profile is not None:
            base = get_profile(self.profile).psd()
        else:
            factor = psd_unit(self.unit).factor if self.unit is not None else 1.0
            f = [p[0] for p in self.breakpoints]
            g = [p[1] * factor for p in self.breakpoints]
            base = PowerLawPsd.from_breakpoints(f, g, self.quantity)
        return PowerLawPsd(
            base.frequency, base.coefficient * self.scale**2, base.exponent, base.quantity
        )

    @property
    def band(self) -> tuple[float, float]:
        """(f_low, f_high) in Hz, defaults resolved."""
        f = self.psd().frequency
        return (
            float(f[0] if self.f_low is None else self.f_low),
            float(f[-1] if self.f_high is None else self.f_high),
        )

    @property
    def target_quantity(self) -> str:
        return self.psd().quantity

    @property
    def psd_unit(self) -> Unit | None:
        """The unit the PSD was given in (None: SI)."""
        if self.profile is not None:
            return psd_unit(get_profile(self.profile).unit)
        return psd_unit(self.unit) if self.unit is not None else None


class MeasuredSignal(_Spec):
    """A measured displacement or angle from a file, resampled to the simulation time grid.

    ``file`` is relative to the scene/spec file. ``format`` defaults from the extension (.csv,
    .mf4/.mdf, .tdms). ``value = scale · (file value in unit)``; ``remove_offset`` subtracts the
    mean or the first value. File time ``start_time`` (default: its first time stamp) maps to
    t = 0. Past the end of the record: an error, the last value held, or zero.
    """

    type: Literal["measured"]
    file: Path
    channel: Annotated[str, Field(min_length=1)]
    format: Literal["csv", "mdf4", "tdms"] | None = None
    time_channel: str | None = None  # CSV default "time"; TDMS default: waveform properties
    group: str | int | None = None  # TDMS group name / MDF group index, if the name repeats
    unit: str | None = None  # of the file values (displacement/angle), default m or rad
    scale: Real = 1.0
    remove_offset: Literal["none", "mean", "first"] = "none"
    start_time: Real | None = None  # s, file time
    beyond_end: Literal["error", "hold", "zero"] = "error"

    @model_validator(mode="after")
    def _check(self) -> MeasuredSignal:
        _checked_amplitude_unit(self.unit, "displacement")
        if self.format is None:
            self.resolved_format  # noqa: B018  (raises for unknown extensions)
        return self

    @property
    def resolved_format(self) -> str:
        if self.format is not None:
            return self.format
        suffix = self.file.suffix.lower()
        formats = {".csv": "csv", ".txt": "csv", ".mf4": "mdf4", ".mdf": "mdf4", ".tdms": "tdms"}
        if suffix not in formats:
            raise ValueError(
                f"file {str(self.file)!r}: cannot tell the format from extension {suffix!r}; "
                f"allowed: {', '.join(formats)} or set format = 'csv', 'mdf4' or 'tdms'"
            )
        return formats[suffix]

    @property
    def amplitude_unit(self) -> Unit | None:
        return _checked_amplitude_unit(self.unit, "displacement")


class TableSignal(_Spec):
    """An inline displacement/angle table: ``t`` (s, strictly increasing) and ``value``.

    Interpolated linearly (default), by PCHIP (monotone, C¹) or by a cubic spline (C²); the end
    values are held outside the table.
    """

    type: Literal["table"]
    t: list[Real]
    value: list[Real]
    unit: str | None = None  # displacement/angle unit, default m or rad
    interpolation: Literal["linear", "pchip", "cubic"] = "linear"

    @model_validator(mode="after")
    def _check(self) -> TableSignal:
        _checked_amplitude_unit(self.unit, "displacement")
        if len(self.t) != len(self.value):
            raise ValueError(
                f"t has {len(self.t)} entries but value has {len(self.value)}; "
                "allowed: the same length"
            )
        if len(self.t) < 2:
            raise ValueError(f"t: need at least 2 points, got {len(self.t)}")
        for i in range(1, len(self.t)):
            if self.t[i] <= self.t[i - 1]:
                raise ValueError(
                    f"t: must increase strictly; t[{i}] = {self.t[i]} s after "
                    f"t[{i - 1}] = {self.t[i - 1]} s"
                )
        return self

    @property
    def amplitude_unit(self) -> Unit | None:
        return _checked_amplitude_unit(self.unit, "displacement")


Signal = Annotated[
    SineSignal | SweepSignal | PsdSignal | MeasuredSignal | TableSignal,
    Field(discriminator="type"),
]


def signal_dimension(signal: Signal) -> str | None:
    """``length`` or ``angle`` if the signal's unit fixes it, None for SI defaults."""
    if isinstance(signal, PsdSignal):
        unit = signal.psd_unit
    else:
        unit = signal.amplitude_unit
    return None if unit is None else unit.dimension


class ChannelMotion(_Spec):
    """One channel of a body's motion: which degree of freedom, in which frame, which signal."""

    channel: Channel
    frame: Frame = "global"
    signal: Signal

    @model_validator(mode="after")
    def _check(self) -> ChannelMotion:
        dimension = signal_dimension(self.signal)
        expected = "angle" if self.channel in ROTATIONS else "length"
        if dimension is not None and dimension != expected:
            kind = "rotation" if expected == "angle" else "translation"
            allowed = "rad or deg based" if expected == "angle" else "m, mm or g based"
            what = (
                f"profile {self.signal.profile!r}"
                if isinstance(self.signal, PsdSignal) and self.signal.profile
                else f"unit {self.signal.unit!r}"
            )
            raise ValueError(
                f"channel {self.channel!r} is a {kind}, but the signal's {what} is a "
                f"{dimension} unit; allowed: {allowed} units"
            )
        return self

    @property
    def unit(self) -> str:
        """SI unit of the channel value: m (x, y, z) or rad (rx, ry, rz)."""
        return "rad" if self.channel in ROTATIONS else "m"


class SignalSettings(_Spec):
    """The ``[signal]`` table of a signal spec file."""

    duration: PositiveFloat  # s
    time_step: PositiveFloat  # s
    start: Real = 0.0  # s

    @model_validator(mode="after")
    def _check(self) -> SignalSettings:
        if self.time_step > self.duration:
            raise ValueError(
                f"time_step = {self.time_step} s is longer than duration = {self.duration} s"
            )
        return self


class NamedChannel(ChannelMotion):
    """A channel of a signal spec file, with an optional name for the output column."""

    name: str | None = None


class SignalFile(_Spec):
    """A signal spec file: ``[signal]`` (duration, time_step) and ``[[channels]]``."""

    signal: SignalSettings
    channels: Annotated[list[NamedChannel], Field(min_length=1)]

    def channel_names(self) -> list[str]:
        """Output names: ``name``, else the channel (``_body`` appended for the body frame)."""
        names: list[str] = []
        for ch in self.channels:
            base = ch.name or (ch.channel if ch.frame == "global" else f"{ch.channel}_body")
            name, k = base, 2
            while name in names:
                name, k = f"{base}_{k}", k + 1
            names.append(name)
        return names
