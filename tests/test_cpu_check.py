"""The processor check before the compiled core loads (cablelife._cpu): the core is built with
AVX and FMA (.cargo/config.toml), and a processor lacking one of its instruction sets gets a
clear ImportError instead of 'Illegal instruction'."""

from __future__ import annotations

import os
import platform
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest
from cablelife import _core, _cpu

LINUX_X86 = sys.platform == "linux" and platform.machine() == "x86_64"
ROOT = Path(__file__).resolve().parents[1]


@pytest.mark.skipif(not LINUX_X86, reason="the stamp is made on Linux x86-64 only")
def test_the_core_carries_the_features_of_its_build_and_this_processor_has_them():
    stamped = _cpu.stamped_features(_core.__file__)
    assert stamped == _core.cpu_features.split()
    # the compilation's features (at least x86-64's baseline), every one on this processor
    assert {"sse", "sse2"} <= set(stamped)
    assert _cpu.missing_features(stamped, _cpu.processor_features()) == []


@pytest.mark.skipif(
    not LINUX_X86 or "RUSTFLAGS" in os.environ or "CARGO_ENCODED_RUSTFLAGS" in os.environ,
    reason="the config's flags apply on Linux x86-64 when RUSTFLAGS does not replace them",
)
def test_the_core_is_built_with_the_configs_instruction_sets():
    # .cargo/config.toml: rustflags = ["-C", "target-feature=+avx,+fma"] (the set the tests
    # check; a build without it would run other code than the one tested)
    config = tomllib.loads((ROOT / ".cargo" / "config.toml").read_text())
    flags = config["target"]["x86_64-unknown-linux-gnu"]["rustflags"]
    wanted = [f.lstrip("+") for f in flags[flags.index("-C") + 1].split("=")[1].split(",")]
    assert wanted == ["avx", "fma"]
    assert set(wanted) <= set(_core.cpu_features.split())


def test_files_without_the_stamp_give_none(tmp_path):
    text = tmp_path / "not-elf.so"
    text.write_text("hello")
    assert _cpu.stamped_features(str(text)) is None
    if LINUX_X86:  # an ELF file without the section: the Python interpreter
        assert _cpu.stamped_features(sys.executable) is None


def test_missing_features_are_named_in_the_build_order():
    assert _cpu.missing_features(["sse2", "avx2", "fma", "avx512f"], {"sse2", "fma"}) == [
        "avx2",
        "avx512f",
    ]
    text = _cpu.message(["avx2", "avx512f"], "/x/_core.abi3.so")
    assert "avx2, avx512f" in text and "pip install -e ." in text and "RUSTFLAGS" in text


@pytest.mark.skipif(not LINUX_X86, reason="the stamp is made on Linux x86-64 only")
def test_a_processor_without_the_builds_instruction_sets_gets_an_import_error_before_the_load():
    # a fresh interpreter whose /proc/cpuinfo lists the build's stamped features but the
    # last: `import cablelife` fails with the message, and the compiled core was never
    # loaded (no code of it ran)
    stamped = _core.cpu_features.split()
    fake = " ".join(["fpu", *stamped[:-1]])
    code = f"""
import builtins, io, sys
real = open
def fake_open(p, *a, **k):
    if p == "/proc/cpuinfo":
        return io.BytesIO(b"processor\\t: 0\\nflags\\t\\t: {fake}\\n")
    return real(p, *a, **k)
builtins.open = fake_open
try:
    import cablelife
except ImportError as e:
    print("ImportError:", e)
print("loaded:", "cablelife._core" in sys.modules)
"""
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True).stdout
    assert f"lacks: {stamped[-1]}." in out, out
    assert "loaded: False" in out, out
