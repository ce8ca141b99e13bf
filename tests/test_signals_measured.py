"""Measured signals: CSV, MDF4 and TDMS round trips, resampling, and every bad-input error."""

import numpy as np
import pytest
from cablelife.signals import MeasuredSignal, SignalError, generate, kinematics, time_grid
from cablelife.signals.measured import read_record


def measured(**kw):
    return MeasuredSignal(type="measured", **kw)


def write_csv(path, time, columns, delimiter=",", decimal="."):
    names = ["time", *columns]
    rows = [delimiter.join(names)]
    for i, t in enumerate(time):
        values = [t] + [columns[name][i] for name in columns]
        rows.append(delimiter.join(repr(float(v)).replace(".", decimal) for v in values))
    path.write_text("# a comment line\n" + "\n".join(rows) + "\n")


def write_mdf4(path, time, columns):
    from asammdf import MDF, Signal

    mdf = MDF(version="4.10")
    mdf.append([Signal(values, time, name=name) for name, values in columns.items()])
    mdf.save(path, overwrite=True)
    mdf.close()


def write_tdms(path, time, columns, with_time_channel=False):
    from nptdms import ChannelObject, GroupObject, TdmsWriter

    props = {"wf_increment": float(time[1] - time[0]), "wf_start_offset": float(time[0])}
    objects = [GroupObject("measurement")]
    if with_time_channel:
        objects.append(ChannelObject("measurement", "t", time))
        props = {}
    objects += [ChannelObject("measurement", n, v, properties=props) for n, v in columns.items()]
    with TdmsWriter(path) as writer:
        writer.write_segment(objects)


T_FILE = np.arange(2001) * 1e-3  # 2 s at 1 kHz
Z_FILE = 1e-3 * np.sin(2 * np.pi * 3 * T_FILE) + 5e-4
Y_FILE = 2e-3 * np.cos(2 * np.pi * 7 * T_FILE)


@pytest.mark.parametrize(
    "suffix, writer",
    [
        (".csv", write_csv),
        (".mf4", write_mdf4),
        (".tdms", write_tdms),
        (".tdms", lambda p, t, c: write_tdms(p, t, c, with_time_channel=True)),
    ],
)
def test_round_trip_on_the_file_grid(tmp_path, suffix, writer):
    path = tmp_path / f"record{suffix}"
    writer(path, T_FILE, {"z": Z_FILE, "y": Y_FILE})
    extra = {"time_channel": "t"} if suffix == ".tdms" and "t" in read_names(path) else {}
    spec = measured(file=path.name, channel="z", **extra)
    value = generate(spec, T_FILE, base_dir=tmp_path)
    assert np.allclose(value, Z_FILE, atol=1e-12)
    y = generate(measured(file=str(path), channel="y", **extra), T_FILE)
    assert np.allclose(y, Y_FILE, atol=1e-12)


def read_names(path):
    from nptdms import TdmsFile

    return [c.name for g in TdmsFile.read(path).groups() for c in g.channels()]


def test_csv_with_semicolons_and_decimal_commas(tmp_path):
    path = tmp_path / "lab.csv"
    write_csv(path, T_FILE, {"z": Z_FILE}, delimiter=";", decimal=",")
    assert np.allclose(generate(measured(file=path, channel="z"), T_FILE), Z_FILE, atol=1e-12)


def test_downsampling_keeps_a_sine_below_nyquist_and_removes_aliases(tmp_path):
    t_file = np.arange(5 * 5000 + 1) / 5000.0  # 5 s at 5 kHz
    wanted = 1e-3 * np.sin(2 * np.pi * 50 * t_file + 0.2)
    alias = 2e-4 * np.sin(2 * np.pi * 1200 * t_file)  # would fold to 200 Hz at 1 kHz
    path = tmp_path / "fast.csv"
    write_csv(path, t_file, {"z": wanted + alias})
    t = time_grid(5.0, 1e-3)
    value = generate(measured(file=path, channel="z"), t)
    expected = 1e-3 * np.sin(2 * np.pi * 50 * t + 0.2)
    assert np.max(np.abs(value - expected)) < 0.002 * 1e-3  # < 0.2 % of the amplitude (ends)
    assert np.max(np.abs(value - expected)[20:-20]) < 1e-6 * 1e-3


def test_downsampling_keeps_ramps_at_the_record_ends(tmp_path):
    # A drifting record (e.g. a slow pose change) must keep its end values: the anti-alias
    # filter takes the end-to-end line out before filtering.
    t_file = np.linspace(0.0, 1.0, 11)
    path = tmp_path / "ramp.csv"
    write_csv(path, t_file, {"z": 0.05 * t_file})
    t = time_grid(1.0, 0.25)
    value = generate(measured(file=path, channel="z"), t)
    assert np.max(np.abs(value - 0.05 * t)) < 1e-12


def test_upsampling_keeps_a_sine(tmp_path):
    t_file = np.arange(401) / 200.0  # 2 s at 200 Hz
    path = tmp_path / "slow.csv"
    write_csv(path, t_file, {"z": np.sin(2 * np.pi * 5 * t_file)})
    t = time_grid(2.0, 1e-3)
    kin = kinematics(measured(file=path, channel="z"), t)
    assert np.max(np.abs(kin.value - np.sin(2 * np.pi * 5 * t))) < 1e-4
    inner = slice(50, -50)
    assert np.allclose(
        kin.velocity[inner],
        2 * np.pi * 5 * np.cos(2 * np.pi * 5 * t[inner]),
        atol=1e-2 * 2 * np.pi * 5,
    )


def test_unit_scale_offset_and_start_time(tmp_path):
    path = tmp_path / "mm.csv"
    write_csv(path, T_FILE + 100.0, {"z": 1e3 * Z_FILE})  # mm, file time starts at 100 s
    t = time_grid(1.0, 1e-3)
    spec = measured(
        file=path, channel="z", unit="mm", scale=2.0, remove_offset="first", start_time=100.5
    )
    value = generate(spec, t)
    expected = 2 * (np.interp(t + 0.5, T_FILE, Z_FILE) - np.interp(0.5, T_FILE, Z_FILE))
    assert np.allclose(value, expected, atol=1e-9)
    mean_removed = generate(
        measured(file=path, channel="z", unit="mm", remove_offset="mean"), T_FILE
    )
    assert abs(mean_removed.mean()) < 1e-12


def test_beyond_end_error_hold_zero(tmp_path):
    path = tmp_path / "short.csv"
    write_csv(path, T_FILE, {"z": Z_FILE})
    t = time_grid(3.0, 1e-3)
    with pytest.raises(SignalError, match=r"short.csv.*channel 'z'.*0 \.\. 2 s.*beyond_end"):
        generate(measured(file=path, channel="z"), t)
    held = generate(measured(file=path, channel="z", beyond_end="hold"), t)
    assert np.allclose(held[t > 2.01], Z_FILE[-1])
    zero = kinematics(measured(file=path, channel="z", beyond_end="zero"), t)
    assert np.all(zero.value[t > 2.01] == 0) and np.all(zero.velocity[t > 2.01] == 0)


# ---- bad input: one test each, the message names file, channel and what is wrong ----


def test_missing_file(tmp_path):
    with pytest.raises(SignalError, match=r"\(channel 'z'\) file = '.*nothere.csv' does not exist"):
        generate(measured(file=tmp_path / "nothere.csv", channel="z"), T_FILE)


def test_missing_csv_channel_lists_columns(tmp_path):
    path = tmp_path / "a.csv"
    write_csv(path, T_FILE, {"z": Z_FILE})
    with pytest.raises(SignalError, match=r"a.csv': channel 'q' not found; columns: 'time', 'z'"):
        generate(measured(file=path, channel="q"), T_FILE)


def test_missing_csv_time_column(tmp_path):
    path = tmp_path / "a.csv"
    write_csv(path, T_FILE, {"z": Z_FILE})
    with pytest.raises(SignalError, match=r"time column 'secs' not found"):
        generate(measured(file=path, channel="z", time_channel="secs"), T_FILE)


def test_missing_mdf4_channel(tmp_path):
    path = tmp_path / "a.mf4"
    write_mdf4(path, T_FILE, {"z": Z_FILE})
    with pytest.raises(SignalError, match=r"a.mf4': channel 'q' not found; channels: .*z"):
        generate(measured(file=path, channel="q"), T_FILE)


def test_missing_tdms_channel(tmp_path):
    path = tmp_path / "a.tdms"
    write_tdms(path, T_FILE, {"z": Z_FILE})
    with pytest.raises(SignalError, match=r"channel 'q' not found; channels: measurement/z"):
        generate(measured(file=path, channel="q"), T_FILE)


def test_tdms_without_time_information(tmp_path):
    from nptdms import ChannelObject, TdmsWriter

    path = tmp_path / "no_time.tdms"
    with TdmsWriter(path) as writer:
        writer.write_segment([ChannelObject("g", "z", Z_FILE)])
    with pytest.raises(SignalError, match=r"g/z: no time stamps.*set time_channel"):
        generate(measured(file=path, channel="z"), T_FILE)


def test_nan_in_values(tmp_path):
    path = tmp_path / "gap.csv"
    z = Z_FILE.copy()
    z[700] = np.nan
    write_csv(path, T_FILE, {"z": z})
    with pytest.raises(
        SignalError,
        match=r"gap.csv', channel 'z': value nan at sample 700 "
        r"\(t = 0.7 s\)",
    ):
        generate(measured(file=path, channel="z"), T_FILE)


def test_empty_csv_cell(tmp_path):
    path = tmp_path / "hole.csv"
    path.write_text("time,z\n0,1\n0.001,\n0.002,3\n")
    with pytest.raises(SignalError, match=r"hole.csv': cannot read columns 'time' and 'z'"):
        generate(measured(file=path, channel="z"), T_FILE)


def test_non_increasing_time_stamps(tmp_path):
    path = tmp_path / "back.csv"
    t = T_FILE.copy()
    t[300] = t[299]
    write_csv(path, t, {"z": Z_FILE})
    with pytest.raises(SignalError, match=r"time stamps must increase; sample 300 has t = 0.299"):
        generate(measured(file=path, channel="z"), T_FILE)


def test_irregular_time_stamps(tmp_path):
    path = tmp_path / "jitter.mf4"
    t = T_FILE.copy()
    t[1000:] += 0.0005
    write_mdf4(path, t, {"z": Z_FILE})
    with pytest.raises(SignalError, match=r"channel 'z': irregular time stamps; step 999 -> 1000"):
        read_record(path, "z", "mdf4")


def test_unreadable_mdf4(tmp_path):
    path = tmp_path / "fake.mf4"
    path.write_text("not an mdf file")
    with pytest.raises(SignalError, match=r"fake.mf4': cannot read as ASAM MDF"):
        generate(measured(file=path, channel="z"), T_FILE)


def test_mdf4_channel_in_several_groups_needs_group(tmp_path):
    from asammdf import MDF, Signal

    path = tmp_path / "two.mf4"
    mdf = MDF(version="4.10")
    mdf.append([Signal(Z_FILE, T_FILE, name="z")])
    mdf.append([Signal(Y_FILE, T_FILE, name="z")])
    mdf.save(path, overwrite=True)
    mdf.close()
    with pytest.raises(SignalError, match=r"channel 'z' is in several groups \(0, 1\); set group"):
        generate(measured(file=path, channel="z"), T_FILE)
    assert np.allclose(generate(measured(file=path, channel="z", group=1), T_FILE), Y_FILE)
