"""`cablelife run` prints the run's warnings and hints naming the scene item (not Python's
file:line format): an unfaded sine and a time step that does not resolve the first mode."""

import re
from pathlib import Path

from cablelife.cli import app
from typer.testing import CliRunner

ROOT = Path(__file__).resolve().parents[1]


def test_dynamic_readme_hose_gets_its_hints(tmp_path):
    text = (ROOT / "examples" / "hose-three-clips.toml").read_text()
    text = re.sub(r'(?m)^mode = "static"', 'mode = "dynamic"', text)
    text = re.sub(r"(?m)^duration = 2.0", "duration = 0.4", text)
    scene = tmp_path / "hose.toml"
    scene.write_text(text)
    run = CliRunner().invoke(app, ["run", str(scene), "--quiet"], env={"COLUMNS": "200"})
    assert run.exit_code == 0, run.output
    out = run.output
    assert "warning: cable 'hose', clip 'engine-bracket': the motion starts with" in out
    assert "time_step = 0.02 s gives" in out and "first natural mode" in out
    assert not re.search(r"\.py:\d+", out)  # no Python file:line
