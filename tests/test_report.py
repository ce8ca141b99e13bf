"""The HTML report: self-contained, every figure renders in headless Chromium, no errors."""

from __future__ import annotations

import copy
import re
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

ARTIFACTS = Path(__file__).resolve().parents[1] / "test-artifacts"
BROWSERS = ("chromium", "chromium-browser", "google-chrome")
# Software WebGL (SwiftShader) so plotly's 3D scenes draw without a GPU; root needs no sandbox.
FLAGS = [
    "--headless",
    "--no-sandbox",
    "--use-angle=swiftshader",
    "--enable-unsafe-swiftshader",
    "--hide-scrollbars",
    "--virtual-time-budget=3000",  # the page checks itself 1.5 s after load
]


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    """Two variants (cable lengths 1.0 and 1.1 m) and a damage file for the first."""
    import h5py
    from cablelife.scene import scene_from_dict
    from cablelife.simulate import simulate
    from conftest import BASE

    folder = tmp_path_factory.mktemp("report")
    d = copy.deepcopy(BASE)
    d["simulation"].update(mode="quasistatic", duration=1.0, time_step=0.1)
    sine = {"type": "sine", "amplitude": 0.05, "frequency": 1.0}
    d["bodies"] = [
        {"name": "engine", "origin": [0.8, 0.2, 0.0], "motion": [{"channel": "z", "signal": sine}]}
    ]
    d["cables"][0]["clips"][1]["body"] = "engine"
    paths = [folder / "short.h5", folder / "long.h5"]
    simulate(scene_from_dict(d)).save(paths[0])
    d["cables"][0]["length"] = d["cables"][0]["clips"][1]["s"] = 1.1
    simulate(scene_from_dict(d)).save(paths[1])
    s = np.linspace(0, 1, 21)
    g = np.linspace(0, 2 * np.pi, 12, endpoint=False)
    with h5py.File(folder / "short_damage.h5", "w") as f:
        f["arc_length"], f["angle"] = s, g
        f["damage"] = np.outer(np.exp(-((s - 0.3) ** 2) / 0.01), 1 + np.cos(g)) + 1e-9
        f["rainflow/range_edges"], f["rainflow/mean_edges"] = np.arange(5.0), [-1.0, 0, 1]
        f["rainflow/counts"] = np.arange(8.0).reshape(4, 2)
    return [*paths, folder / "short_damage.h5"]


@pytest.fixture(scope="module")
def report(files, tmp_path_factory):
    import typer
    from cablelife.report.cli import report_command
    from typer.testing import CliRunner

    app = typer.Typer()
    app.command()(report_command)
    out = tmp_path_factory.mktemp("html") / "report.html"
    run = CliRunner().invoke(
        app, [*map(str, files), "-o", str(out), "--frames", "6", "--voxel", "5mm"]
    )
    assert run.exit_code == 0, run.output
    return out


def test_report_is_self_contained(report):
    text = report.read_text()
    # Works offline: plotly.js embedded, no external script, style sheet or image.
    assert '<script type="text/javascript">/**' in text and len(text) > 3_000_000
    markup = re.sub(r"<script\b[^>]*>.*?</script>", "", text, flags=re.S)
    assert not re.findall(r'(?:src|href)="(?!data:|#)', markup)
    expected = int(re.search(r'data-expected-figures="(\d+)"', text)[1])
    assert len(re.findall(r'<div id="figure-\d+"', text)) == expected > 0
    for needle in (
        "Comparison of the variants",
        "ranking by maximum bending moment",
        "motion volumes at 5 mm",
        "damage hot spots",
        "Run short (quasistatic)",
        "clip reactions",
        "b (engine)",  # clip labelled with its body in the 3D view
    ):
        assert needle in text, needle


def test_report_bad_input(files, tmp_path):
    import typer
    from cablelife.report.cli import report_command
    from typer.testing import CliRunner

    app = typer.Typer()
    app.command()(report_command)
    run = CliRunner().invoke(app, [str(files[2]), "-o", str(tmp_path / "r.html")])
    assert run.exit_code == 2 and "at least one result file" in run.output
    run = CliRunner().invoke(app, [str(tmp_path / "missing.h5")])
    assert run.exit_code == 2 and "does not exist" in run.output


def test_report_renders_in_headless_chromium(report):
    browser = next((b for b in map(shutil.which, BROWSERS) if b), None)
    if browser is None:
        pytest.skip("chromium not found (Debian package 'chromium'; .ci/run should install it)")
    url = report.resolve().as_uri()
    ARTIFACTS.mkdir(exist_ok=True)
    shot = ARTIFACTS / "report.png"
    shot.unlink(missing_ok=True)
    dom = subprocess.run(
        [browser, *FLAGS, "--enable-logging=stderr", "--window-size=1000,1200",
         f"--screenshot={shot}", "--dump-dom", url],
        capture_output=True,
        text=True,
        timeout=180,
    )  # fmt: skip
    body = re.search(r"<body([^>]*)>", dom.stdout)
    assert body, dom.stderr[-2000:]
    attrs = dict(re.findall(r'data-([\w-]+)="([^"]*)"', body[1]))
    assert attrs.get("checked") == "yes", attrs
    assert attrs["rendered-figures"] == attrs["expected-figures"] != "0"
    assert attrs["rendered-images"] == attrs["expected-images"] != "0"
    assert attrs["errors"] == "[]"
    uncaught = [ln for ln in dom.stderr.splitlines() if "CONSOLE" in ln and "Uncaught" in ln]
    assert not uncaught, uncaught
    assert shot.exists() and shot.stat().st_size > 10_000  # kept as a test artifact
