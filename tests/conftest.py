"""Shared fixtures: small scenes built as dicts (the parsed form of TOML)."""

from __future__ import annotations

import copy

import pytest

BASE = {
    "simulation": {"mode": "static", "gravity": [0.0, 0.0, -9.81]},
    "cables": [
        {
            "name": "hose",
            "length": 1.0,
            "segments": 40,
            "section": {"shape": "circle", "radius": 0.005},
            "material": {"youngs_modulus": 5.0e7, "poisson_ratio": 0.45, "density": 1500.0},
            "clips": [
                {
                    "name": "a",
                    "s": 0.0,
                    "position": [0.0, 0.0, 0.0],
                    "direction": [1.0, 0.0, 0.0],
                    "normal": [0.0, 0.0, 1.0],
                },
                {
                    "name": "b",
                    "s": 1.0,
                    "position": [0.8, 0.2, 0.0],
                    "direction": [1.0, 0.0, 0.0],
                    "normal": [0.0, 0.0, 1.0],
                },
            ],
        }
    ],
}


@pytest.fixture
def scene_dict():
    """A two-clip hose scene as a dict; tests modify their own copy."""
    return copy.deepcopy(BASE)


def pytest_terminal_summary(terminalreporter):
    """The number of bad-input cases run (tests/test_bad_input_*.py), when there were any."""
    import sys

    badinput = sys.modules.get("badinput")
    if badinput is not None and badinput.CASES_RUN:
        terminalreporter.write_line(f"bad-input cases run: {len(badinput.CASES_RUN)}")
