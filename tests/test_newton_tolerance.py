"""The default dynamic Newton tolerance keeps the iteration error below the time-discretisation
error of the 1 ms step (the stopping rule compares the correction with an estimate of the local
time error; docs/dynamics.md, benchmarks/bench_newton_tolerance.py)."""

from __future__ import annotations

import copy
import warnings

import numpy as np
import pytest
from cablelife.scene import scene_from_dict
from cablelife.simulate import simulate


def hose(channel: str, amplitude: float, damping: dict | None = None) -> dict:
    cable = {
        "name": "hose",
        "length": 1.0,
        "segments": 50,
        "section": {"shape": "circle", "radius": 0.005},
        "material": {"youngs_modulus": 5.0e7, "poisson_ratio": 0.45, "density": 1500.0},
        "clips": [
            {"name": "a", "s": 0.0, "position": [0, 0, 0], "direction": [1, 0, 0]},
            {
                "name": "b",
                "s": 1.0,
                "body": "engine",
                "position": [0.8, 0.2, 0.0],
                "direction": [1, 0, 0],
            },
        ],
    }
    if damping:
        cable["damping"] = damping
    signal = {"type": "sine", "amplitude": amplitude, "frequency": 10.0, "fade_in": 0.1}
    return {
        "simulation": {
            "mode": "dynamic",
            "gravity": [0.0, 0.0, -9.81],
            "duration": 0.3,
            "time_step": 0.001,
            "output_step": 0.001,
        },
        "bodies": [
            {
                "name": "engine",
                "origin": [0.8, 0.2, 0.0],
                "motion": [{"channel": channel, "signal": signal}],
            }
        ],
        "cables": [cable],
    }


def moments(d: dict, tolerance: float | None, dt: float) -> np.ndarray:
    d = copy.deepcopy(d)
    d["simulation"]["time_step"] = dt
    if tolerance is not None:
        d["simulation"]["newton_tolerance"] = tolerance
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return simulate(scene_from_dict(d)).cable.moments


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
    default = moments(scene, None, 0.001)
    tight = moments(scene, 1e-9, 0.001)
    fine = moments(scene, 1e-9, 0.00025)
    iteration, time = rel(default, tight), rel(tight, fine)
    assert iteration < 0.5 * time, (iteration, time)
