"""The processor check before the compiled core loads.

The core (``cablelife._core``) is built for the generic x86-64 instruction set, but a build
with other flags (``RUSTFLAGS="-C target-cpu=native"``: AVX2, FMA, AVX-512 where present) run
on a processor without one of its instruction sets — a copy of the installation on another
machine, a home folder shared by different computers — would stop at the first such
instruction with "Illegal instruction" and no further word. So before it loads, the features
stamped into it at build time (ELF section ``.cablelife_cpu``, names as in /proc/cpuinfo;
``crates/py/build.rs``) are compared with this processor's, from the file, without loading
it; a missing one is an ImportError that names them and the fix. Linux on x86-64 only (the
only target built so); reads a few kilobytes.
"""

from __future__ import annotations

import importlib.util
import platform
import struct
import sys

SECTION = b".cablelife_cpu"


def stamped_features(path: str) -> list[str] | None:
    """The features in the ELF section ``.cablelife_cpu`` of the shared library at ``path``
    (None: not a 64-bit little-endian ELF file, or no such section)."""
    with open(path, "rb") as f:
        head = f.read(64)
        if len(head) < 64 or head[:4] != b"\x7fELF" or head[4] != 2 or head[5] != 1:
            return None
        shoff = struct.unpack_from("<Q", head, 0x28)[0]
        shentsize, shnum, shstrndx = struct.unpack_from("<HHH", head, 0x3A)
        if shentsize < 40 or shnum == 0 or shstrndx >= shnum:
            return None
        f.seek(shoff)
        table = f.read(shentsize * shnum)
        if len(table) < shentsize * shnum:
            return None

        def section(i: int) -> tuple[int, int, int]:  # name offset, file offset, size
            at = i * shentsize
            name = struct.unpack_from("<I", table, at)[0]
            offset, size = struct.unpack_from("<QQ", table, at + 24)
            return name, offset, size

        _, names_at, names_size = section(shstrndx)
        f.seek(names_at)
        names = f.read(names_size)
        for i in range(shnum):
            name, offset, size = section(i)
            end = names.find(b"\0", name)
            if names[name:end] == SECTION:
                f.seek(offset)
                return f.read(size).decode("ascii", "replace").split()
    return None


def processor_features() -> set[str] | None:
    """This processor's features from /proc/cpuinfo (None where unreadable)."""
    try:
        with open("/proc/cpuinfo", encoding="ascii", errors="replace") as f:
            for line in f:
                if line.startswith("flags"):
                    return set(line.partition(":")[2].split())
    except OSError:
        return None
    return None


def missing_features(built: list[str], have: set[str]) -> list[str]:
    """The features the build uses that the processor lacks, in the build's order."""
    return [f for f in built if f not in have]


def message(missing: list[str], path: str) -> str:
    return (
        f"cablelife's compiled core ({path}) was built on a processor with instruction sets "
        f"this one lacks: {', '.join(missing)}. It would stop with 'Illegal instruction'. "
        "Rebuild it for the generic instruction set: unset RUSTFLAGS, then "
        "python3 -m pip install -e . in the cablelife folder (or set RUSTFLAGS to the oldest "
        "processor's level, e.g. '-C target-cpu=x86-64-v2')."
    )


def check_processor() -> None:
    """Raises ImportError if the core was built for instruction sets this processor lacks."""
    if sys.platform != "linux" or platform.machine() != "x86_64":
        return
    spec = importlib.util.find_spec("cablelife._core")
    path = getattr(spec, "origin", None) if spec is not None else None
    if not path or not path.endswith(".so"):
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
