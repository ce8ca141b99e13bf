"""Spectral fatigue: damage rate of a stationary Gaussian stress from its one-sided PSD.

Curve in ranges N = α ΔS^(−k). Spectral moments m_n = ∫ f^n G(f) df, ν₀⁺ = √(m₂/m₀),
ν_p = √(m₄/m₂).

- Narrow band (Rayleigh ranges): E[D]/T = ν₀⁺ (2√(2m₀))^k Γ(1 + k/2) / α.
- Dirlik (1985), range form: x_m = (m₁/m₀)√(m₂/m₄), γ = m₂/√(m₀m₄),
  D₁ = 2(x_m − γ²)/(1 + γ²), R = (γ − x_m − D₁²)/(1 − γ − D₁ + D₁²),
  D₂ = (1 − γ − D₁ + D₁²)/(1 − R), D₃ = 1 − D₁ − D₂, Q = 1.25(γ − D₃ − D₂R)/D₁,
  E[D]/T = ν_p/α (2√m₀)^k [D₁ Q^k Γ(1+k) + (√2)^k Γ(1+k/2)(D₂|R|^k + D₃)].

:func:`gaussian_signal` draws a sample path with a given one-sided PSD (random phases on the
FFT grid); used to cross-check rainflow counting against Dirlik.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.special import gamma as gamma_fn


def _psd(f, g) -> tuple[np.ndarray, np.ndarray]:
    f = np.asarray(f, float)
    g = np.asarray(g, float)
    if f.ndim != 1 or f.shape != g.shape or f.size < 2:
        raise ValueError(f"f and G must be 1-D of equal length >= 2; got {f.shape}, {g.shape}")
    if np.any(np.diff(f) <= 0) or f[0] < 0:
        raise ValueError("f must be non-negative and strictly increasing")
    if np.any(g < 0) or not np.all(np.isfinite(g)):
        raise ValueError("G must be finite and >= 0")
    return f, g


def spectral_moments(f, g, orders=(0, 1, 2, 4)) -> dict[int, float]:
    """m_n = ∫ f^n G(f) df (trapezoid rule) for a one-sided PSD G on frequencies f (Hz)."""
    f, g = _psd(f, g)
    return {n: float(np.trapezoid(f**n * g, f)) for n in orders}


def narrow_band_damage_rate(f, g, k: float, alpha: float) -> float:
    """Expected damage per second of the narrow-band (Rayleigh) approximation."""
    m = spectral_moments(f, g)
    nu0 = math.sqrt(m[2] / m[0])
    return nu0 * (2 * math.sqrt(2 * m[0])) ** k * gamma_fn(1 + k / 2) / alpha


def dirlik_damage_rate(f, g, k: float, alpha: float) -> float:
    """Expected damage per second after Dirlik (1985), with the curve in ranges."""
    m = spectral_moments(f, g)
    m0, m1, m2, m4 = m[0], m[1], m[2], m[4]
    xm = (m1 / m0) * math.sqrt(m2 / m4)
    gam = m2 / math.sqrt(m0 * m4)
    d1 = 2 * (xm - gam**2) / (1 + gam**2)
    r = (gam - xm - d1**2) / (1 - gam - d1 + d1**2)
    d2 = (1 - gam - d1 + d1**2) / (1 - r)
    d3 = 1 - d1 - d2
    q = 1.25 * (gam - d3 - d2 * r) / d1
    nu_p = math.sqrt(m4 / m2)
    bracket = d1 * q**k * gamma_fn(1 + k) + math.sqrt(2) ** k * gamma_fn(1 + k / 2) * (
        d2 * abs(r) ** k + d3
    )
    return nu_p / alpha * (2 * math.sqrt(m0)) ** k * bracket


def gaussian_signal(psd, fs: float, n: int, seed: int | None = 0) -> np.ndarray:
    """A Gaussian sample path of ``n`` samples at rate ``fs`` with one-sided PSD ``psd(f)``
    (callable, unit²/Hz): X_j = √(G(f_j) n fs / 2) e^{iφ_j} on f_j = j fs/n, X₀ = X_{n/2} = 0,
    x = irfft(X). Its variance is Σ G(f_j) Δf."""
    if not (isinstance(n, int | np.integer) and n >= 4 and n % 2 == 0):
        raise ValueError(f"n = {n!r}: must be an even integer >= 4")
    if not (math.isfinite(fs) and fs > 0):
        raise ValueError(f"fs = {fs!r}: must be a sampling rate > 0 (Hz)")
    rng = np.random.default_rng(seed)
    fj = np.arange(n // 2 + 1) * fs / n
    amp = np.sqrt(np.maximum(np.asarray(psd(fj), float), 0.0) * n * fs / 2)
    x = amp * np.exp(2j * np.pi * rng.random(fj.size))
    x[0] = 0.0
    x[-1] = 0.0
    return np.fft.irfft(x, n)
