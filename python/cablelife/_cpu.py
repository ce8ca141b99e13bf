"""The processor check before the compiled core loads.

The core (``cablelife._core``) is built with AVX and FMA (``.cargo/config.toml``), or with
other flags from RUSTFLAGS. Run on a processor without one of its instruction sets — an old
or low-end processor, a copy of the installation on another machine, a home folder shared
by different computers — it would stop at the first such instruction with "Illegal
instruction" and no further word. So before it loads, the features
stamped into it at build time (ELF section ``.cablelife_cpu``, names as in /proc/cpuinfo;
``crates/py/build.rs``) are compared with this processor's, from the file, without loading
it; a missing one is an ImportError that names them and the fix. Linux on x86-64 only (the
only target built so); reads a few kilobytes.
"""

from __future__ import annotations

import os
import sys

# Only os and sys: this runs on every `import cablelife` (platform, struct and importlib.util
# would add ≈ 6 ms to its 3 ms).
SECTION = b".cablelife_cpu"


def _u(data: bytes, at: int, size: int) -> int:
    return int.from_bytes(data[at : at + size], "little")


def stamped_features(path: str) -> list[str] | None:
    """The features in the ELF section ``.cablelife_cpu`` of the shared library at ``path``
    (None: not a 64-bit little-endian ELF file, or no such section)."""
    with open(path, "rb") as f:
        head = f.read(64)
        if len(head) < 64 or head[:4] != b"\x7fELF" or head[4] != 2 or head[5] != 1:
            return None
        shoff = _u(head, 0x28, 8)
        shentsize, shnum, shstrndx = _u(head, 0x3A, 2), _u(head, 0x3C, 2), _u(head, 0x3E, 2)
        if shentsize < 40 or shnum == 0 or shstrndx >= shnum:
            return None
        f.seek(shoff)
        table = f.read(shentsize * shnum)
        if len(table) < shentsize * shnum:
            return None

        def section(i: int) -> tuple[int, int, int]:  # name offset, file offset, size
            at = i * shentsize
            return _u(table, at, 4), _u(table, at + 24, 8), _u(table, at + 32, 8)

        _, names_at, names_size = section(shstrndx)
        f.seek(names_at)
        names = f.read(names_size)
        for i in range(shnum):
            name, offset, size = section(i)
            end = names.find(b"\0", name)
            if names[name:end] == SECTION:
                f.seek(offset)
                return [w.decode() for w in f.read(size).split()]
    return None


def processor_features() -> set[str] | None:
    """This processor's features from /proc/cpuinfo (None where unreadable)."""
    try:
        with open("/proc/cpuinfo", "rb") as f:
            for line in f:
                if line.startswith(b"flags"):
                    return {w.decode() for w in line.partition(b":")[2].split()}
    except OSError:
        return None
    return None


def missing_features(built: list[str], have: set[str]) -> list[str]:
    """The features the build uses that the processor lacks, in the build's order."""
    return [f for f in built if f not in have]


def message(missing: list[str], path: str) -> str:
    return (
        f"cablelife's compiled core ({path}) was built for instruction sets this processor "
        f"lacks: {', '.join(missing)}. It would stop with 'Illegal instruction'. "
        "Build the generic core for this processor in the cablelife folder: "
        'RUSTFLAGS="" python3 -m pip install -e . (RUSTFLAGS replaces the build flags of '
        ".cargo/config.toml)."
    )


def core_file(package_path: list[str]) -> str | None:
    """The extension file ``_core`` that the import system would load from the package's
    folders (the first folder holding one, extension suffixes in the import system's order)."""
    from importlib.machinery import EXTENSION_SUFFIXES

    for folder in package_path:
        for suffix in EXTENSION_SUFFIXES:
            path = os.path.join(folder, "_core" + suffix)
            if os.path.isfile(path):
                return path
    return None


def check_processor(package_path: list[str]) -> None:
    """Raises ImportError if the core in the package's folders was built for instruction sets
    this processor lacks."""
    if sys.platform != "linux" or os.uname().machine != "x86_64":
        return
    path = core_file(package_path)
    if path is None or not path.endswith(".so"):
        return
    try:
        built = stamped_features(path)
    except OSError:
        return  # the import itself will say what is wrong with the file
    have = processor_features()
    if not built or have is None:
        return
    missing = missing_features(built, have)
    if missing:
        raise ImportError(message(missing, path))
