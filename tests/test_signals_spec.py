"""Spec validation: each bad input gives a clear error naming the field, the value, the rule."""

import numpy as np
import pytest
from cablelife.signals import ChannelMotion, SignalError, SignalWarning, generate, time_grid
from cablelife.signals.specfile import load_spec
from pydantic import ValidationError

PSD = {"type": "psd", "breakpoints": [[10, 1.0], [100, 1.0]], "quantity": "acceleration"}


def motion(signal, **kw):
    return ChannelMotion.model_validate({"channel": "z", "signal": signal, **kw})


def error_text(signal=None, **kw):
    with pytest.raises(ValidationError) as info:
        motion(signal if signal is not None else PSD, **kw)
    return str(info.value)


def test_valid_specs_parse():
    m = motion(
        {
            "type": "psd",
            "profile": "iso16750-3:2007/I-engine",
            "quantity": "acceleration",
            "scale": 1.0,
        }
    )
    assert m.frame == "global" and m.unit == "m"
    assert motion({"type": "sine", "amplitude": 1, "frequency": 2}, channel="rx").unit == "rad"


def test_unknown_signal_type():
    text = error_text({"type": "noise"})
    assert "'noise'" in text and "'sine', 'sweep', 'psd', 'measured', 'table'" in text


def test_unknown_channel():
    text = error_text(channel="w")
    assert "channel" in text and "'x', 'y', 'z', 'rx', 'ry' or 'rz'" in text and "'w'" in text


def test_unknown_frame():
    text = error_text(frame="local")
    assert "frame" in text and "'global' or 'body'" in text


def test_unknown_key_is_rejected():
    text = error_text({**PSD, "sed": 3})
    assert "sed" in text and "Extra inputs are not permitted" in text


def test_negative_amplitude():
    text = error_text({"type": "sine", "amplitude": -1, "frequency": 2})
    assert "amplitude" in text and "greater than or equal to 0" in text and "-1" in text


def test_nan_frequency():
    text = error_text({"type": "sine", "amplitude": 1, "frequency": float("nan")})
    assert "frequency" in text and "finite number" in text


def test_psd_needs_breakpoints_or_profile():
    assert "exactly one of breakpoints and profile" in error_text({"type": "psd"})
    both = {**PSD, "profile": "iso16750-3:2007/I-engine"}
    assert "exactly one of breakpoints and profile" in error_text(both)


def test_psd_breakpoints_must_increase():
    text = error_text({**PSD, "breakpoints": [[10, 1], [100, 1], [50, 1]]})
    assert "breakpoint 2 has 50.0 Hz after 100.0 Hz" in text


def test_psd_value_must_be_positive():
    text = error_text({**PSD, "breakpoints": [[10, 1], [100, 0]]})
    assert "breakpoints.1.1" in text and "greater than 0" in text


def test_psd_unknown_unit():
    text = error_text({**PSD, "unit": "G2/Hz"})
    assert "PSD unit 'G2/Hz' is not known; allowed:" in text and "g^2/Hz" in text


def test_psd_unit_does_not_match_quantity():
    text = error_text({**PSD, "quantity": "displacement", "unit": "g^2/Hz"})
    assert "unit 'g^2/Hz' is an acceleration PSD unit but quantity is 'displacement'" in text


def test_psd_quantity_required_with_breakpoints():
    text = error_text({k: v for k, v in PSD.items() if k != "quantity"})
    assert "quantity is required with breakpoints" in text


def test_unknown_profile():
    text = error_text({"type": "psd", "profile": "iso16750-3:2023/I"})
    assert "profile 'iso16750-3:2023/I' is not known; allowed: iso16750-3:2007/I-engine" in text


def test_profile_with_wrong_quantity_or_unit():
    p = {"type": "psd", "profile": "iso16750-3:2007/I-engine"}
    assert "quantity 'velocity' does not match profile" in error_text({**p, "quantity": "velocity"})
    assert "unit 'g^2/Hz' is not allowed with a profile" in error_text({**p, "unit": "g^2/Hz"})


def test_f_low_outside_breakpoints():
    text = error_text({**PSD, "f_low": 5.0})
    assert "f_low = 5.0 Hz lies outside the breakpoints; allowed: 10 <= f_low < 100 Hz" in text


def test_f_high_below_f_low():
    text = error_text({**PSD, "f_low": 50.0, "f_high": 40.0})
    assert "f_high = 40.0 Hz: allowed 50 < f_high <= 100 Hz" in text


def test_sweep_rate_and_duration_exclusive():
    text = error_text(
        {
            "type": "sweep",
            "f0": 5,
            "f1": 50,
            "amplitude": 1,
            "octaves_per_minute": 1,
            "duration": 10,
        }
    )
    assert "exactly one of octaves_per_minute" in text and "duration=10.0" in text


def test_sweep_octaves_per_minute_needs_log_law():
    text = error_text(
        {
            "type": "sweep",
            "f0": 5,
            "f1": 50,
            "amplitude": 1,
            "law": "linear",
            "octaves_per_minute": 1,
        }
    )
    assert "octaves_per_minute applies to law = 'log', not 'linear'" in text


def test_sweep_same_frequencies():
    text = error_text({"type": "sweep", "f0": 5, "f1": 5, "amplitude": 1, "duration": 3})
    assert "f0 and f1 are both 5.0 Hz" in text


def test_sweep_fade_too_long():
    text = error_text(
        {"type": "sweep", "f0": 5, "f1": 50, "amplitude": 1, "duration": 3, "fade": 2}
    )
    assert "fade = 2.0 s is more than half the sweep duration 3 s" in text


def test_sine_unit_does_not_match_quantity():
    text = error_text({"type": "sine", "amplitude": 1, "frequency": 2, "unit": "g"})
    assert "unit 'g' is an acceleration unit but quantity is 'displacement'" in text


def test_rotation_channel_with_length_unit():
    text = error_text({"type": "sine", "amplitude": 1, "frequency": 2, "unit": "mm"}, channel="rx")
    assert "channel 'rx' is a rotation, but the signal's unit 'mm' is a length unit" in text


def test_rotation_channel_with_translation_profile():
    text = error_text({"type": "psd", "profile": "iso16750-3:2007/I-engine"}, channel="ry")
    assert "channel 'ry' is a rotation" in text and "profile 'iso16750-3:2007/I-engine'" in text


def test_table_lengths_and_order():
    assert "t has 3 entries but value has 2" in error_text(
        {"type": "table", "t": [0, 1, 2], "value": [0, 1]}
    )
    assert "t[2] = 1.0 s after t[1] = 2.0 s" in error_text(
        {"type": "table", "t": [0, 2, 1], "value": [0, 1, 2]}
    )


def test_measured_unknown_extension():
    text = error_text({"type": "measured", "file": "log.xyz", "channel": "z"})
    assert "cannot tell the format from extension '.xyz'" in text


def test_time_grid_must_be_uniform_and_increasing():
    spec = motion({"type": "sine", "amplitude": 1, "frequency": 2}).signal
    t = time_grid(1.0, 0.01)
    with pytest.raises(SignalError, match=r"time: must be uniformly spaced; step 4"):
        generate(spec, np.delete(t, 5))
    with pytest.raises(SignalError, match=r"time: must increase"):
        generate(spec, t[::-1])
    with pytest.raises(SignalError, match=r"time_step: 2 s is longer than the duration 1 s"):
        time_grid(1.0, 2.0)


def test_psd_band_above_nyquist():
    spec = motion({**PSD, "breakpoints": [[600, 1.0], [900, 1.0]]}).signal
    with pytest.raises(SignalError, match=r"600..900 Hz lies above the Nyquist frequency 500 Hz"):
        generate(spec, time_grid(1.0, 1e-3))


def test_psd_duration_too_short_for_band():
    spec = motion({**PSD, "breakpoints": [[0.1, 1.0], [0.3, 1.0]]}).signal
    with pytest.raises(SignalError, match=r"holds no frequency line.*at least 20 s"):
        generate(spec, time_grid(1.0, 1e-3))


def test_psd_content_below_first_line_warns():
    spec = motion({**PSD, "breakpoints": [[0.3, 1.0], [3.0, 1.0]]}).signal
    with pytest.warns(SignalWarning, match=r"below 0.4995 Hz .* is left out: 7.39 %"):
        generate(spec, time_grid(1.0, 1e-3))


def test_spec_file_errors_name_the_key_path(tmp_path):
    path = tmp_path / "bad.toml"
    path.write_text(
        "[signal]\nduration = 1.0\ntime_step = 0.001\n\n[[channels]]\nchannel = 'z'\n"
        "signal = { type = 'sine', amplitude = 1, frequency = -3 }\n"
    )
    with pytest.raises(SignalError) as info:
        load_spec(path)
    assert "channels.0.signal.sine.frequency: Input should be greater than 0 (got -3)" in str(
        info.value
    )


def test_spec_file_not_toml(tmp_path):
    path = tmp_path / "broken.toml"
    path.write_text("[signal\n")
    with pytest.raises(SignalError, match=r"broken.toml' is not valid TOML"):
        load_spec(path)
