"""The ``signal`` command: spec file in, CSV/HDF5 and PNG out, clear errors."""

import shutil
from pathlib import Path

import h5py
import numpy as np
import pytest
import typer
from cablelife.signals import SignalWarning
from cablelife.signals.cli import signal_command
from cablelife.signals.measured import read_csv
from cablelife.signals.specfile import generate_channels, load_spec
from typer.testing import CliRunner

EXAMPLES = Path(__file__).parents[1] / "examples" / "signals"

SPEC = """
[signal]
duration = 4.0
time_step = 0.001

[[channels]]
name = "engine_z"
channel = "z"
signal = { type = "psd", profile = "iso16750-3:2007/IV-sprung-mass", seed = 1 }

[[channels]]
channel = "ry"
frame = "body"
signal = { type = "sine", amplitude = 1.0, unit = "deg", frequency = 2.0, fade_in = 0.5 }
"""


@pytest.fixture
def app():
    application = typer.Typer()
    application.command()(signal_command)
    return application


def run(app, *args):
    return CliRunner().invoke(app, [str(a) for a in args])


def test_writes_csv_and_png(app, tmp_path):
    spec = tmp_path / "shake.toml"
    spec.write_text(SPEC)
    result = run(app, spec, "--derivatives")
    assert result.exit_code == 0, result.output
    assert (tmp_path / "shake.csv").is_file() and (tmp_path / "shake.png").is_file()
    assert (tmp_path / "shake.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert "engine_z" in result.output and "warning" in result.output  # 1000 Hz > Nyquist
    with pytest.warns(SignalWarning):
        time, series = generate_channels(load_spec(spec), tmp_path)
    record = read_csv(tmp_path / "shake.csv", "ry_body")
    assert np.allclose(record.time, time) and np.allclose(record.value, series[1].kinematics.value)
    accel = read_csv(tmp_path / "shake.csv", "engine_z_acceleration").value
    assert np.allclose(accel, series[0].kinematics.acceleration, rtol=1e-9, atol=1e-9)


def test_writes_hdf5_without_plot(app, tmp_path):
    spec = tmp_path / "shake.toml"
    spec.write_text(SPEC)
    out = tmp_path / "out" / "signals.h5"
    result = run(app, spec, "--output", out, "--no-plot")
    assert result.exit_code == 0, result.output
    assert not list(tmp_path.glob("**/*.png"))
    with h5py.File(out) as f:
        assert f.attrs["format"] == "cablelife-signal"
        assert f["time"].attrs["unit"] == "s" and f["time"].shape == (4001,)
        z = f["channels/engine_z"]
        assert z.attrs["channel"] == "z" and z["acceleration"].attrs["unit"] == "m/s^2"
        assert f["channels/ry_body/value"].attrs["unit"] == "rad"
        assert "iso16750-3:2007/IV-sprung-mass" in f.attrs["spec_toml"]
    assert not [p for p in out.parent.iterdir() if p.suffix == ".tmp"]


def test_bad_spec_gives_key_path_and_exit_code(app, tmp_path):
    spec = tmp_path / "bad.toml"
    spec.write_text(SPEC.replace('frame = "body"', 'frame = "wheel"'))
    result = run(app, spec)
    assert result.exit_code == 2
    assert "channels.1.frame: Input should be 'global' or 'body' (got 'wheel')" in result.output
    assert "Traceback" not in result.output


def test_bad_output_extension(app, tmp_path):
    spec = tmp_path / "s.toml"
    spec.write_text(SPEC)
    result = run(app, spec, "-o", tmp_path / "s.xlsx")
    assert result.exit_code == 2
    assert "extension '.xlsx' is not supported; allowed: .csv, .h5, .hdf5" in result.output


def test_missing_spec_file(app, tmp_path):
    result = run(app, tmp_path / "none.toml")
    assert result.exit_code == 2 and "none.toml' does not exist" in result.output


@pytest.mark.parametrize("example", sorted(EXAMPLES.glob("*.toml")), ids=lambda p: p.name)
def test_examples_validate(example):
    spec = load_spec(example)
    assert spec.channels


def test_measured_example_runs(app, tmp_path):
    shutil.copytree(EXAMPLES, tmp_path / "ex")
    result = run(app, tmp_path / "ex" / "measured.toml")
    assert result.exit_code == 0, result.output
    z = read_csv(tmp_path / "ex" / "measured.csv", "z_road").value
    assert z[0] == pytest.approx(0.0, abs=1e-12) and 2e-3 < np.abs(z).max() < 3e-3


def test_error_text_with_brackets_is_printed_verbatim(app, tmp_path):
    spec = tmp_path / "s.toml"
    spec.write_text(SPEC.replace("seed = 1", "seed = 1, unit = '[m/s^2]^2/Hz'"))
    result = run(app, spec)
    assert result.exit_code == 2
    assert "unit '[m/s^2]^2/Hz' is not allowed with a profile" in result.output
