"""Power spectral densities: log-log breakpoint tables and Gaussian signals synthesised from them.

A one-sided PSD G(f) given at breakpoints (f_i, G_i) is a power law on each segment,
G(f) = G_i (f/f_i)^b_i with b_i = ln(G_{i+1}/G_i)/ln(f_{i+1}/f_i) ("log-log interpolation"),
and zero outside [f_0, f_M]. Integrals of power laws are exact, so RMS values are exact too.

Synthesis (random-phase method): on the FFT grid f_j = j Δf, Δf = 1/(N dt), bin j gets the
power P_j = ∫ G df over [f_j − Δf/2, f_j + Δf/2] ∩ [f_low, f_high] (exact integral, so the sum of
the P_j is ∫ G df over the band), amplitude X_j = N √(P_j/2) e^{iφ_j} with uniformly random φ_j
from the seed, X_0 = X_{N/2} = 0, and the signal is irfft(X). By Parseval its mean square over
the grid is Σ P_j — the target, exactly; the random phases make the samples Gaussian (many
independent components). The signal is periodic with period N dt.

Velocity and acceleration PSDs become displacement in the frequency domain: the quantity's
spectrum is divided by (iω_j) (velocity) or (iω_j)² = −ω_j² (acceleration), i.e. the PSD by
(2πf)² or (2πf)⁴. Below f_low the spectrum is zero, so the displacement cannot drift.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np

from cablelife.signals.errors import SignalError, SignalWarning
from cablelife.signals.kinematics import Kinematics
from cablelife.signals.units import DERIVATIVE_ORDER


@dataclass(frozen=True)
class PowerLawPsd:
    """A one-sided PSD, power law between breakpoints, zero outside (SI units of `quantity`)."""

    frequency: np.ndarray  # (M,) Hz, strictly increasing, > 0
    coefficient: np.ndarray  # (M-1,) c_i in G = c_i f^b_i
    exponent: np.ndarray  # (M-1,) b_i
    quantity: str  # displacement, velocity or acceleration

    @classmethod
    def from_breakpoints(
        cls, frequency: np.ndarray, value: np.ndarray, quantity: str
    ) -> PowerLawPsd:
        f = np.asarray(frequency, dtype=float)
        g = np.asarray(value, dtype=float)
        exponent = np.log(g[1:] / g[:-1]) / np.log(f[1:] / f[:-1])
        coefficient = g[:-1] / f[:-1] ** exponent
        return cls(f, coefficient, exponent, quantity)

    def as_quantity(self, quantity: str) -> PowerLawPsd:
        """The PSD of another quantity: multiplied by (2πf)^(2k), k the change of derivative."""
        k = DERIVATIVE_ORDER[quantity] - DERIVATIVE_ORDER[self.quantity]
        return PowerLawPsd(
            self.frequency,
            self.coefficient * (2 * np.pi) ** (2 * k),
            self.exponent + 2 * k,
            quantity,
        )

    def __call__(self, f: np.ndarray) -> np.ndarray:
        """G(f), zero outside the breakpoint range."""
        f = np.asarray(f, dtype=float)
        last = len(self.exponent) - 1
        seg = np.clip(np.searchsorted(self.frequency, f, side="right") - 1, 0, last)
        inside = (f >= self.frequency[0]) & (f <= self.frequency[-1])
        safe = np.where(inside, f, self.frequency[0])
        return np.where(inside, self.coefficient[seg] * safe ** self.exponent[seg], 0.0)

    def cumulative(self, f: np.ndarray) -> np.ndarray:
        """∫ G df from the first breakpoint to f (exact)."""
        f = np.clip(np.asarray(f, dtype=float), self.frequency[0], self.frequency[-1])
        lo, hi = self.frequency[:-1], self.frequency[1:]
        total = np.zeros_like(f)
        for c, b, a, z in zip(self.coefficient, self.exponent, lo, hi, strict=True):
            upper = np.clip(f, a, z)
            if abs(b + 1) < 1e-12:
                total += c * np.log(upper / a)
            else:
                total += c * (upper ** (b + 1) - a ** (b + 1)) / (b + 1)
        return total

    def integral(self, f_low: float | None = None, f_high: float | None = None) -> float:
        """∫ G df over [f_low, f_high] (default: all breakpoints) — the mean square."""
        a = self.frequency[0] if f_low is None else f_low
        z = self.frequency[-1] if f_high is None else f_high
        return float(self.cumulative(np.array(z)) - self.cumulative(np.array(a)))

    def rms(self, f_low: float | None = None, f_high: float | None = None) -> float:
        return float(np.sqrt(self.integral(f_low, f_high)))


def synthesise(
    psd: PowerLawPsd,
    n: int,
    dt: float,
    seed: int,
    f_low: float | None = None,
    f_high: float | None = None,
) -> Kinematics:
    """A Gaussian signal of ``n`` samples at step ``dt`` whose ``psd.quantity`` has the PSD ``psd``.

    Returns the displacement (m or rad) with its velocity and acceleration, all from the same
    spectrum (exact spectral derivatives of the periodic signal).
    """
    f_low = psd.frequency[0] if f_low is None else f_low
    f_high = psd.frequency[-1] if f_high is None else f_high
    nyquist = 0.5 / dt
    df = 1.0 / (n * dt)
    freq = np.fft.rfftfreq(n, dt)
    band_high = min(f_high, nyquist - (df / 2 if n % 2 == 0 else 0.0))
    if band_high <= f_low or freq[-1] < f_low:
        raise SignalError(
            f"PSD band {f_low:g}..{f_high:g} Hz lies above the Nyquist frequency {nyquist:g} Hz "
            f"of time step {dt:g} s; allowed: a time step below {0.5 / f_low:g} s"
        )
    lower = np.clip(freq - df / 2, f_low, band_high)
    upper = np.clip(freq + df / 2, f_low, band_high)
    power = psd.cumulative(upper) - psd.cumulative(lower)
    below_first_line = power[0]  # the mean (0 Hz) line stays empty
    power[0] = 0.0
    if n % 2 == 0:
        power[-1] = 0.0
    if not np.any(power > 0):
        raise SignalError(
            f"PSD band {f_low:g}..{f_high:g} Hz holds no frequency line of the grid (lines every "
            f"{df:g} Hz = 1/duration); allowed: a duration of at least {2 / f_low:g} s"
        )
    if below_first_line > 1e-6 * power.sum():
        warnings.warn(
            f"PSD content below {df / 2:g} Hz (half the line spacing 1/duration) is left out: "
            f"{100 * below_first_line / (power.sum() + below_first_line):.3g} % of the "
            f"{psd.quantity} mean square; use a duration of at least {2 / f_low:g} s",
            SignalWarning,
            stacklevel=3,
        )
    if f_high > nyquist:
        _warn_truncated(psd, f_low, f_high, nyquist, dt)

    rng = np.random.default_rng(seed)
    phase = rng.uniform(0.0, 2 * np.pi, size=freq.size)
    spectrum = n * np.sqrt(power / 2) * np.exp(1j * phase)  # of psd.quantity
    omega = 2 * np.pi * freq
    order = DERIVATIVE_ORDER[psd.quantity]
    with np.errstate(divide="ignore", invalid="ignore"):
        displacement = np.where(power > 0, spectrum / (1j * omega) ** order, 0.0)
    return Kinematics(
        np.fft.irfft(displacement, n),
        np.fft.irfft(1j * omega * displacement, n),
        np.fft.irfft(-(omega**2) * displacement, n),
    )


def _warn_truncated(psd: PowerLawPsd, f_low: float, f_high: float, nyquist: float, dt: float):
    lost = 1 - psd.integral(f_low, nyquist) / psd.integral(f_low, f_high)
    disp = psd.as_quantity("displacement")
    lost_disp = 1 - disp.integral(f_low, nyquist) / disp.integral(f_low, f_high)
    warnings.warn(
        f"PSD reaches {f_high:g} Hz, above the Nyquist frequency {nyquist:g} Hz of time step "
        f"{dt:g} s: the content above is left out ({100 * lost:.3g} % of the {psd.quantity} "
        f"mean square, {100 * lost_disp:.3g} % of the displacement mean square)",
        SignalWarning,
        stacklevel=4,
    )
