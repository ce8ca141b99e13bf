"""The default dynamic Newton tolerance keeps the iteration error below the time-discretisation
error of the 1 ms step (the stopping rule compares the correction with an estimate of the local
time error; docs/dynamics.md, benchmarks/bench_newton_tolerance.py), with contact too
(docs/contact.md, "The Newton stopping rule with contact")."""

from __future__ import annotations

import copy
import warnings

import numpy as np
import pytest
from cablelife.scene import scene_from_dict
from cablelife.simulate import simulate


def two_clips(
    end: list[float], directions: tuple[list, list], youngs: float, channel: str, signal: dict
) -> dict:
    """A hose (1 m, 50 segments, r = 5 mm) clamped at the origin and at `end` on a body
    'engine' that `signal` moves along `channel`; 0.3 s at 1 ms, every step saved."""
    cable = {
        "name": "hose",
        "length": 1.0,
        "segments": 50,
        "section": {"shape": "circle", "radius": 0.005},
        "material": {"youngs_modulus": youngs, "poisson_ratio": 0.45, "density": 1500.0},
        "clips": [
            {"name": "a", "s": 0.0, "position": [0, 0, 0], "direction": directions[0]},
            {"name": "b", "s": 1.0, "body": "engine", "position": end, "direction": directions[1]},
        ],
    }
    return {
        "simulation": {
            "mode": "dynamic",
            "gravity": [0.0, 0.0, -9.81],
            "duration": 0.3,
            "time_step": 0.001,
            "output_step": 0.001,
        },
        "bodies": [
            {"name": "engine", "origin": end, "motion": [{"channel": channel, "signal": signal}]}
        ],
        "cables": [cable],
    }


def hose(channel: str, amplitude: float, damping: dict | None = None) -> dict:
    signal = {"type": "sine", "amplitude": amplitude, "frequency": 10.0, "fade_in": 0.1}
    d = two_clips([0.8, 0.2, 0.0], ([1, 0, 0], [1, 0, 0]), 5.0e7, channel, signal)
    if damping:
        d["cables"][0]["damping"] = damping
    return d


def run(d: dict, tolerance: float | None, dt: float = 0.001):
    """The cable's result of scene `d` at time step `dt` with `newton_tolerance` (None: the
    default)."""
    d = copy.deepcopy(d)
    d["simulation"]["time_step"] = dt
    if tolerance is not None:
        d["simulation"]["newton_tolerance"] = tolerance
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return simulate(scene_from_dict(d)).cable


def rel(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.sqrt(np.mean((a - b) ** 2) / np.mean(b**2)))


@pytest.mark.parametrize(
    "scene",
    [
        # heavily damped (τ = 0.27 s on every mode: the former default damping): a smooth
        # response with a small time error, where 5e-3 of the increment was 16× too loose
        hose("z", 0.005, {"retardation_time": 0.27}),
        hose("x", 0.02),
    ],
    ids=["overdamped-10Hz", "default-damping-10Hz"],
)
def test_iteration_error_is_below_the_time_discretisation_error(scene):
    default = run(scene, None).moments
    tight = run(scene, 1e-9).moments
    fine = run(scene, 1e-9, 0.00025).moments
    iteration, time = rel(default, tight), rel(tight, fine)
    assert iteration < 0.5 * time, (iteration, time)


def draped(signal: dict, friction: float = 0.3, duration: float = 0.3) -> dict:
    """A soft hose (1 m) between clips 0.7 m apart, its sag lying on a table 0.2 m below them
    (24–25 nodes touching, Coulomb friction μ); the right clip's body moved along z."""
    d = two_clips([0.7, 0.0, 0.0], ([1, 0, -0.5], [1, 0, 0.5]), 2.0e7, "z", signal)
    table = {"shape": "plane", "name": "table", "point": [0, 0, -0.2], "normal": [0, 0, 1]}
    d["simulation"]["duration"] = duration
    d["bodies"].append({"name": "floor", "geometry": [table]})
    d["contact"] = {"enabled": True, "friction": friction}
    return d


def random_motion(rms: float) -> dict:
    """10–200 Hz random displacement of `rms` (m), flat PSD."""
    level = rms**2 / 190.0
    return {
        "type": "psd",
        "quantity": "displacement",
        "seed": 7,
        "fade_in": 0.05,
        "breakpoints": [[10.0, level], [200.0, level]],
    }


SINE_20HZ = {"type": "sine", "amplitude": 0.003, "frequency": 20.0, "fade_in": 0.05}


@pytest.mark.parametrize(
    "signal", [SINE_20HZ, random_motion(0.001)], ids=["sine-20Hz", "random-1mm"]
)
def test_iteration_error_with_contact_is_below_the_time_discretisation_error(signal):
    # Measured (moments, rms relative): sine 0.015 of the time error, random 0.12.
    d = draped(signal)
    default, tight = run(d, None), run(d, 1e-9)
    fine = run(d, 1e-9, 0.00025)
    assert (default.contact["contact_state"] > 0).sum(axis=1).min() >= 20  # it lies on the table
    iteration, time = rel(default.moments, tight.moments), rel(tight.moments, fine.moments)
    assert iteration < 0.5 * time, (iteration, time)


def test_the_scene_tolerance_governs_runs_with_contact():
    # Before session 15 a run with contact held fixed fractions of the step's increment alone:
    # `newton_tolerance` changed nothing, so a converged reference could not be computed.
    d = draped(SINE_20HZ, duration=0.15)
    default, tighter, tight = (run(d, t) for t in (None, 1e-4, 1e-9))
    assert tighter.solver["iterations"].mean() > default.solver["iterations"].mean()
    assert rel(tighter.moments, tight.moments) < 0.1 * rel(default.moments, tight.moments)


def test_a_hose_held_by_high_friction_on_a_table_completes():
    # μ = 1 under 1 mm of random motion: Newton cycled between the sides of a sample's stick
    # zone at step 36 (20 iterations, 3 N left; every split of the step too) until the line
    # search of a cycling iteration kept frictional samples from jumping across it
    # (`Contact::line_search`'s stick cut, as the step bound and the sliding clips' guides).
    res = run(draped(random_motion(0.001), friction=1.0, duration=0.06), None)
    assert len(res.time) == 61
    state = res.contact["contact_state"]
    assert (state > 0).sum(axis=1).min() >= 20
    assert (state[:50] == 1).sum(axis=1).min() >= 20  # held by friction up to there


def engine_harness(duration: float) -> dict:
    """The harness of benchmarks/bench_harness.py (6 cables, 400 segments, 2 junctions; the
    engine shaken by the ISO 16750-3 engine PSD to 100 Hz along z and x), 1 ms steps."""
    import sys
    from pathlib import Path

    benchmarks = str(Path(__file__).resolve().parents[1] / "benchmarks")
    if benchmarks not in sys.path:
        sys.path.append(benchmarks)
    from bench_harness import scene

    return scene("dynamic", duration)


def harness_run(d: dict, tolerance: float | None, dt: float = 0.001):
    d = copy.deepcopy(d)
    d["simulation"]["time_step"] = dt
    d["simulation"]["output_step"] = 0.001
    if tolerance is not None:
        d["simulation"]["newton_tolerance"] = tolerance
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return simulate(scene_from_dict(d)).cables


def test_the_learnt_predictor_saves_iterations_within_the_error_rule():
    # The accelerations' predictor fits a linear recursion to the past accelerations
    # (crate::predictor; of order two in session 16): on the harness shaken by the engine PSD
    # the iterations per step fall from 2.44 (constant acceleration) to 2.01 over 0.5 s (2.36
    # → 2.00 over 1 s); the stopping rule on the estimated remaining error
    # (crate::contraction, session 17) takes them to 1.64, the recursion of order 6 (session
    # 17) to 1.24. The iteration error stays below the time error.
    d = engine_harness(0.5)
    default, tight = harness_run(d, None), harness_run(d, 1e-9)
    fine = harness_run(d, 1e-9, 0.00025)
    its = next(iter(default.values())).solver["iterations"][1:]
    assert its.mean() < 1.45, its.mean()  # measured 1.24; order 2: 1.64; v̇_n 2.44
    for name in ("trunk", "c", "d"):  # c, d: the engine-driven branches
        iteration = rel(default[name].moments, tight[name].moments)
        time = rel(tight[name].moments, fine[name].moments)
        assert iteration < 0.5 * time, (name, iteration, time)  # measured 0.8e-3–2e-3 of it
