"""Sine and sweep signals: analytic displacement, fade-in, frequency laws, octaves per minute."""

import math

import numpy as np
import pytest
from cablelife.signals import SineSignal, SweepSignal, generate, kinematics, time_grid
from cablelife.signals.sweep import sweep_frequency
from scipy.integrate import cumulative_trapezoid


def sine(**kw):
    return SineSignal(type="sine", **kw)


def sweep(**kw):
    return SweepSignal(type="sweep", **kw)


def upward_zero_crossings(t, x):
    """Times of upward zero crossings, linearly interpolated."""
    i = np.flatnonzero((x[:-1] < 0) & (x[1:] >= 0))
    return t[i] - x[i] * (t[i + 1] - t[i]) / (x[i + 1] - x[i])


def crossing_frequencies(t, x):
    """Frequency between successive upward zero crossings, at the mid time."""
    tc = upward_zero_crossings(t, x)
    return 0.5 * (tc[1:] + tc[:-1]), 1.0 / np.diff(tc)


def test_sine_displacement_amplitude_phase_offset():
    t = time_grid(1.0, 1e-4)
    x = generate(sine(amplitude=2e-3, frequency=5, phase=0.3, offset=1e-3), t)
    assert np.allclose(x, 2e-3 * np.sin(2 * np.pi * 5 * t + 0.3) + 1e-3, atol=1e-15)


def test_sine_in_acceleration_integrates_to_analytic_displacement():
    amplitude, f, phase = 2.0, 25.0, 0.4  # 2 g sine at 25 Hz
    spec = sine(amplitude=amplitude, unit="g", quantity="acceleration", frequency=f, phase=phase)
    t = time_grid(0.4, 1e-5)
    kin = kinematics(spec, t)
    a_si, w = amplitude * 9.80665, 2 * np.pi * f
    assert np.allclose(kin.acceleration, a_si * np.sin(w * t + phase), atol=1e-9 * a_si)
    assert np.allclose(kin.value, -a_si / w**2 * np.sin(w * t + phase), atol=1e-12)
    # twice integrating the acceleration from the initial state gives the same displacement
    v = kin.velocity[0] + cumulative_trapezoid(kin.acceleration, t, initial=0)
    x = kin.value[0] + cumulative_trapezoid(v, t, initial=0)
    assert np.max(np.abs(x - kin.value)) < 1e-4 * a_si / w**2


def test_sine_in_velocity():
    kin = kinematics(sine(amplitude=0.1, quantity="velocity", frequency=4), time_grid(1, 1e-3))
    assert np.max(np.abs(kin.velocity)) == pytest.approx(0.1, rel=1e-4)
    assert np.max(np.abs(kin.value)) == pytest.approx(0.1 / (2 * np.pi * 4), rel=1e-4)


def test_sine_fade_in_is_smooth():
    spec = sine(amplitude=1e-3, frequency=10, fade_in=0.5, offset=2e-3)
    t = time_grid(1.0, 1e-5)
    kin = kinematics(spec, t)
    assert kin.value[0] == pytest.approx(2e-3) and kin.velocity[0] == 0
    assert kin.acceleration[0] == 0
    late = t > 0.5
    assert np.allclose(kin.value[late], 1e-3 * np.sin(2 * np.pi * 10 * t[late]) + 2e-3)
    fd_v = np.gradient(kin.value, t)
    fd_a = np.gradient(kin.velocity, t)
    assert np.max(np.abs(fd_v - kin.velocity)[2:-2]) < 1e-4 * np.max(np.abs(kin.velocity))
    assert np.max(np.abs(fd_a - kin.acceleration)[2:-2]) < 1e-4 * np.max(np.abs(kin.acceleration))


def test_sine_in_degrees():
    x = generate(sine(amplitude=2, unit="deg", frequency=1), time_grid(1, 1e-3))
    assert np.max(np.abs(x)) == pytest.approx(np.deg2rad(2), rel=1e-5)


def test_linear_sweep_follows_linear_law():
    spec = sweep(f0=5, f1=45, law="linear", duration=8, amplitude=1e-3)
    t = time_grid(8.0, 1e-4)
    x = generate(spec, t)
    tm, fm = crossing_frequencies(t, x)
    assert np.allclose(fm, 5 + 40 * tm / 8, rtol=2e-3)


def test_log_sweep_follows_log_law_and_octaves_per_minute():
    rate = 6.0  # octaves per minute
    spec = sweep(f0=10, f1=80, octaves_per_minute=rate, amplitude=1e-3)
    assert spec.sweep_duration == pytest.approx(60 * 3 / rate)  # 3 octaves
    t = time_grid(spec.sweep_duration, 1e-4)
    x = generate(spec, t)
    tm, fm = crossing_frequencies(t, x)
    assert np.allclose(fm, 10 * 2 ** (rate * tm / 60), rtol=2e-3)
    # one octave every 60/rate = 10 s: count periods between f0 and 2 f0
    periods = np.sum(upward_zero_crossings(t, x) < 10.0)
    expected = 10 * 60 / (rate * math.log(2))  # ∫ f dt over the first octave
    assert abs(periods - expected) <= 1


def test_downward_log_sweep_given_duration():
    spec = sweep(f0=40, f1=10, duration=20, amplitude=1.0)
    f, _, _, _ = sweep_frequency(spec, np.array([0.0, 10.0, 20.0]))
    assert np.allclose(f, [40, 20, 10])


@pytest.mark.parametrize("quantity, k", [("velocity", 1), ("acceleration", 2)])
def test_sweep_constant_amplitude_of_the_chosen_quantity(quantity, k):
    spec = sweep(f0=5, f1=40, octaves_per_minute=30, amplitude=3.0, quantity=quantity)
    t = time_grid(spec.sweep_duration, 1e-4)
    kin = kinematics(spec, t)
    series = kin.velocity if quantity == "velocity" else kin.acceleration
    f = sweep_frequency(spec, t)[0]
    middle = (t > 0.5) & (t < spec.sweep_duration - 0.5)
    assert np.max(np.abs(series[middle])) == pytest.approx(3.0, rel=0.01)
    assert np.min(np.abs(series[middle])) < 0.05
    envelope = np.abs(kin.value[middle]) * (2 * np.pi * f[middle]) ** k
    assert envelope.max() <= 3.0 * 1.01


def test_sweep_derivatives_and_fades():
    spec = sweep(f0=2, f1=20, law="linear", duration=4, amplitude=1e-3, fade=0.5)
    t = time_grid(5.0, 1e-5)
    kin = kinematics(spec, t)
    assert kin.value[0] == 0 and np.all(kin.value[t > 4.0] == 0)
    fd_v = np.gradient(kin.value, t)
    fd_a = np.gradient(kin.velocity, t)
    scale_v, scale_a = np.max(np.abs(kin.velocity)), np.max(np.abs(kin.acceleration))
    assert np.max(np.abs(fd_v - kin.velocity)[2:-2]) < 1e-3 * scale_v
    assert np.max(np.abs(fd_a - kin.acceleration)[2:-2]) < 1e-3 * scale_a
