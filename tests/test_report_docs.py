"""The example of docs/visuals.md runs as written."""

from __future__ import annotations

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_visuals_example_runs(tmp_path, monkeypatch):
    text = (ROOT / "docs" / "visuals.md").read_text()
    code = re.search(r"```python\n(.*?)```", text, re.S).group(1)
    code = code.replace('"examples/', f'"{ROOT}/examples/')
    monkeypatch.chdir(tmp_path)
    exec(compile(code, "docs/visuals.md", "exec"), {"__name__": "docs_example"})
    out = tmp_path / "out"
    for name in (
        "volume.stl",
        "fig2.png",
        "modes.png",
        "damage.png",
        "rainflow.png",
        "run.pvd",
        "run/run_tube_00000.vtp",
        "report.html",
    ):
        assert (out / name).stat().st_size > 0, name
    assert "rainflow matrix of hose" in (out / "report.html").read_text()
