"""Atomic writes (issue 12): no temporary file is left by an interrupted write, stale ones of
killed processes are removed by the next write, and the target is never half-written."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import textwrap
import time

import numpy as np
import pytest
from cablelife.atomic import atomic_path, stale_temp_files, temp_name, write_atomic


def temp_files(folder):
    return sorted(p.name for p in folder.iterdir() if p.name.endswith(".tmp"))


def test_a_write_interrupted_by_ctrl_c_leaves_the_old_file_and_no_temporary(tmp_path):
    target = tmp_path / "run.h5"
    target.write_bytes(b"old")

    def write(f):
        f.write(b"new, half")
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        write_atomic(target, write)
    assert target.read_bytes() == b"old"
    assert temp_files(tmp_path) == []


def test_an_interrupted_result_save_leaves_no_temporary(tmp_path, scene_dict, monkeypatch):
    import h5py
    from cablelife.results import load_result
    from cablelife.scene import scene_from_dict
    from cablelife.simulate import simulate

    result = simulate(scene_from_dict(scene_dict))
    target = tmp_path / "run.h5"
    result.save(target)
    calls = {"n": 0}
    real = h5py.Group.create_dataset

    def interrupted_after_three(self, *args, **kw):
        calls["n"] += 1
        if calls["n"] > 3:
            raise KeyboardInterrupt
        return real(self, *args, **kw)

    monkeypatch.setattr(h5py.Group, "create_dataset", interrupted_after_three)
    with pytest.raises(KeyboardInterrupt):
        result.save(target)
    monkeypatch.undo()
    assert calls["n"] > 3  # the save really was cut short
    assert temp_files(tmp_path) == []
    again = load_result(target)  # the earlier file, whole
    np.testing.assert_array_equal(again.cable.forces, result.cable.forces)


def _dead_pid() -> int:
    proc = subprocess.Popen([sys.executable, "-c", "pass"])
    proc.wait()
    return proc.pid


def test_stale_temporaries_of_dead_processes_are_removed_at_the_next_write(tmp_path):
    target = tmp_path / "report.html"
    dead = tmp_path / f".report.html.{_dead_pid()}-0123abcd.tmp"
    legacy = tmp_path / ".report.html.k2j_9xq0.tmp"  # tempfile.mkstemp's, earlier versions
    live = tmp_path / f".report.html.{os.getppid()}-89abcdef.tmp"  # a writer still running
    other = tmp_path / f".other.html.{_dead_pid()}-0123abcd.tmp"  # another target's
    for p in (dead, legacy, live, other):
        p.write_bytes(b"x" * 1000)
    assert sorted(stale_temp_files(target)) == sorted([dead, legacy])
    write_atomic(target, lambda f: f.write(b"<html></html>"))
    assert target.read_bytes() == b"<html></html>"
    assert temp_files(tmp_path) == sorted([live.name, other.name])


def test_a_folder_of_files_is_cleaned_once_and_each_file_is_atomic(tmp_path):
    """`atomic_folder` (a time series of many files): the stale temporaries of the names it
    writes are removed, a live writer's and those of names it does not write are kept; an
    exception half-way leaves the files written so far whole, no temporary, and the rest
    unwritten."""
    from cablelife.atomic import atomic_folder

    dead = tmp_path / f".s_00001.vtp.{_dead_pid()}-0123abcd.tmp"
    legacy = tmp_path / ".s_00002.vtp.k2j_9xq0.tmp"
    live = tmp_path / f".s_00001.vtp.{os.getppid()}-89abcdef.tmp"
    other = tmp_path / f".other.vtp.{_dead_pid()}-0123abcd.tmp"
    for p in (dead, legacy, live, other):
        p.write_bytes(b"x")
    with atomic_folder(tmp_path) as write:
        for k in range(1, 4):
            write(f"s_{k:05d}.vtp", f"<step {k}/>")
    assert [(tmp_path / f"s_{k:05d}.vtp").read_text() for k in (1, 2, 3)] == [
        f"<step {k}/>" for k in (1, 2, 3)
    ]
    assert temp_files(tmp_path) == sorted([live.name, other.name])
    with pytest.raises(KeyboardInterrupt), atomic_folder(tmp_path / "b") as write:
        write("a.vtp", "A")
        write("b.vtp", "B")
        raise KeyboardInterrupt
    assert sorted(p.name for p in (tmp_path / "b").iterdir()) == ["a.vtp", "b.vtp"]


def test_temporary_names_follow_the_pattern_the_cleaning_knows(tmp_path):
    target = tmp_path / "a b.h5"
    name = temp_name(target)
    assert name.startswith(".a b.h5.") and name.endswith(".tmp")
    with atomic_path(target) as tmp:
        assert tmp.name.startswith(f".a b.h5.{os.getpid()}-")
        assert stale_temp_files(target) == []  # our own, alive
        tmp.write_bytes(b"1")
    assert target.read_bytes() == b"1" and temp_files(tmp_path) == []


WRITER = """
import sys, time
from pathlib import Path
from cablelife.atomic import write_atomic

target, ready = Path(sys.argv[1]), Path(sys.argv[2])

def write(f):
    f.write(b"N" * 1_000_000)
    f.flush()
    ready.touch()
    while True:  # a long write, killed half-way
        f.write(b"N" * 1_000_000)
        time.sleep(0.01)

write_atomic(target, write)
"""


def test_a_killed_writer_never_leaves_a_half_written_target(tmp_path):
    target = tmp_path / "volume.stl"
    target.write_bytes(b"old mesh")
    ready = tmp_path / "ready"
    proc = subprocess.Popen(
        [sys.executable, "-c", textwrap.dedent(WRITER), str(target), str(ready)]
    )
    try:
        end = time.monotonic() + 120
        while not ready.exists():
            assert proc.poll() is None, "the writer ended early"
            assert time.monotonic() < end, "the writer did not start"
            time.sleep(0.02)
        os.kill(proc.pid, signal.SIGKILL)
        proc.wait(30)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert target.read_bytes() == b"old mesh"  # untouched
    (left,) = temp_files(tmp_path)  # SIGKILL: nobody could remove it …
    assert (tmp_path / left).stat().st_size >= 1_000_000
    write_atomic(target, lambda f: f.write(b"new mesh"))  # … the next write does
    assert target.read_bytes() == b"new mesh"
    assert temp_files(tmp_path) == []
