"""Variant studies (issue 7): study files, parameters, the Dask runner, resuming, failures."""

from __future__ import annotations

import contextlib
import json
import os
import shutil
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from cablelife.study import StudyError, expand, load_study, run_study

ROOT = Path(__file__).resolve().parents[1]
# After Ctrl-C the study cancels its variants and closes the local cluster (a hang detector).
STOP_BOUND = 30.0  # s
SCENE = ROOT / "examples" / "clip-variants" / "scene.toml"

# A short, coarse study: 0.3 s of the demo scene, a coarse LDA and motion volume.
STUDY = f"""
[study]
name = "small"
scene = "{SCENE.as_posix()}"
mode = "dynamic"
duration = 0.3
{{combine}}

[lda]
points = 8
plane_step = 30.0
section_step = 4

[volume]
voxel = 0.008
max_steps = 30

[[parameters]]
name = "shift"
kind = "clip_position"
clip = "body-2"
direction = [1.0, 0.25, -0.125]
values = {{shifts}}

[[parameters]]
name = "length"
kind = "cable_length"
values = {{lengths}}
"""


def write_study(tmp_path: Path, shifts="[0.0, 0.04]", lengths="[1.25, 1.26]", extra="") -> Path:
    path = tmp_path / "study.toml"
    text = STUDY.replace("{combine}", 'combine = "grid"')
    text = text.replace("{shifts}", shifts).replace("{lengths}", lengths)
    path.write_text(text + extra)
    return path


def test_grid_expands_to_every_combination_with_the_parameters_applied(tmp_path):
    study, folder = load_study(write_study(tmp_path, "[0.0, 0.02, 0.04]", "[1.25, 1.3]"))
    variants = expand(study, folder)
    assert len(variants) == 6
    assert variants[0].name == "shift=0_length=1.25"
    v = next(v for v in variants if v.values == {"shift": 0.04, "length": 1.3})
    base = next(v for v in variants if v.values == {"shift": 0.0, "length": 1.25})
    clips = {c["name"]: c for c in v.scene["cables"][0]["clips"]}
    base_clips = {c["name"]: c for c in base.scene["cables"][0]["clips"]}
    d = np.array([1.0, 0.25, -0.125])
    moved = np.subtract(clips["body-2"]["position"], base_clips["body-2"]["position"])
    np.testing.assert_allclose(moved, 0.04 * d / np.linalg.norm(d), atol=1e-15)
    assert clips["body-2"]["s"] == base_clips["body-2"]["s"]  # no slide
    # 5 cm more cable go into the longest span (body-2 → engine-1): the clips after it move.
    assert v.scene["cables"][0]["length"] == 1.3
    assert clips["body-1"]["s"] == base_clips["body-1"]["s"]
    assert clips["body-2"]["s"] == base_clips["body-2"]["s"]
    assert clips["engine-1"]["s"] == pytest.approx(base_clips["engine-1"]["s"] + 0.05)
    assert clips["engine-2"]["s"] == pytest.approx(base_clips["engine-2"]["s"] + 0.05)
    assert all(v.mode == "dynamic" and v.scene["simulation"]["duration"] == 0.3 for v in variants)
    assert len({v.fingerprint({}) for v in variants}) == 6


def test_list_mode_and_the_other_parameter_kinds(tmp_path):
    path = tmp_path / "list.toml"
    path.write_text(
        f"""
[study]
scene = "{SCENE.as_posix()}"
combine = "list"
[[parameters]]
name = "slide"
kind = "clip_position"
clip = "body-2"
slide = true
[[parameters]]
name = "E"
kind = "material"
field = "youngs_modulus"
[[parameters]]
name = "level"
kind = "excitation"
body = "engine"
channels = ["z"]
[[parameters]]
name = "step"
kind = "set"
path = "cables.harness.clips.engine-1.s"
[[variants]]
name = "soft"
E = 2e7
level = 2.0
[[variants]]
name = "slid"
slide = -0.01
step = 0.94
"""
    )
    study, folder = load_study(path)
    soft, slid = expand(study, folder)
    assert (soft.name, slid.name) == ("soft", "slid")
    cable = soft.scene["cables"][0]
    assert cable["material"]["youngs_modulus"] == 2e7
    motion = {m["channel"]: m["signal"] for m in soft.scene["bodies"][0]["motion"]}
    assert motion["z"]["scale"] == 2.0 and motion["x"].get("scale", 1.0) == 1.0
    clips = {c["name"]: c for c in slid.scene["cables"][0]["clips"]}
    assert clips["body-2"]["s"] == pytest.approx(0.44)  # slid along its own direction
    d = np.array([1.0, 0.3, -0.1])
    np.testing.assert_allclose(
        np.subtract(clips["body-2"]["position"], [0.36, 0.10, -0.05]),
        -0.01 * d / np.linalg.norm(d),
        atol=1e-15,
    )
    assert clips["engine-1"]["s"] == 0.94


@pytest.mark.parametrize(
    ("extra", "message"),
    [
        (
            '\n[[parameters]]\nname = "x"\nkind = "clip_position"\nclip = "nope"\nvalues = [0.0]\n',
            "no clip named 'nope'",
        ),
        (
            '\n[[parameters]]\nname = "x"\nkind = "material"\nfield = "colour"\nvalues = [1.0]\n',
            "field 'colour' is not a value",
        ),
        (
            '\n[[parameters]]\nname = "x"\nkind = "set"\npath = "cables.harness.nothing.s"\n'
            "values = [1.0]\n",
            "no 'cables.harness.nothing'",
        ),
        (
            '\n[[parameters]]\nname = "x"\nkind = "excitation"\nbody = "car"\nvalues = [1.0]\n',
            "no body named 'car'",
        ),
        (
            '\n[[parameters]]\nname = "x"\nkind = "material"\nfield = "density"\nvalues = [-1.0]\n',
            "material.density",
        ),
    ],
)
def test_bad_parameters_name_what_is_wrong(tmp_path, extra, message):
    study, folder = load_study(write_study(tmp_path, "[0.0]", "[1.25]", extra))
    with pytest.raises(StudyError, match=message.replace("(", r"\(")):
        expand(study, folder)


def test_bad_study_files_are_clear_errors(tmp_path):
    with pytest.raises(StudyError, match="does not exist"):
        load_study(tmp_path / "missing.toml")
    path = write_study(tmp_path, "[]", "[1.25]")
    with pytest.raises(StudyError, match=r"parameters \['shift'\] have no values"):
        load_study(path)
    path.write_text(path.read_text().replace('kind = "cable_length"', 'kind = "colour"'))
    with pytest.raises(StudyError, match="invalid study"):
        load_study(path)


def _rows(out: Path) -> dict[str, dict]:
    return {
        p.parent.name: json.loads(p.read_text()) for p in (out / "variants").glob("*/summary.json")
    }


def test_local_cluster_study_writes_the_summary_table_and_reruns_nothing(tmp_path):
    out = tmp_path / "out"
    outcome = run_study(write_study(tmp_path), out, workers=2)
    assert not outcome.failed and len(outcome.computed) == 4 and not outcome.skipped
    table = pd.read_csv(outcome.csv)
    again = pd.read_parquet(outcome.parquet)
    assert len(table) == len(again) == 4
    for column in (
        "variant",
        "shift",
        "length",
        "max_damage",
        "rank",
        "ratio_to_best",
        "hot_spot_s_m",
        "hot_spot_clip",
        "max_tension_N",
        "max_bending_Nm",
        "max_torsion_Nm",
        "max_clip_force_N",
        "motion_volume_l",
    ):
        assert column in table, column
    assert (table["status"] == "ok").all()
    assert sorted(table["rank"]) == [1, 2, 3, 4]
    assert table["ratio_to_best"].min() == pytest.approx(1.0)
    best = table.loc[table["rank"] == 1, "max_damage"].item()
    assert best == table["max_damage"].min() > 0
    assert (table["motion_volume_l"] > 0).all()
    assert outcome.plot is not None and outcome.plot.stat().st_size > 1000
    for name in table["variant"]:
        folder = out / "variants" / name
        assert {"scene.toml", "result.h5", "damage.h5", "summary.json"} <= {
            p.name for p in folder.iterdir()
        }
    stamps = {n: (out / "variants" / n / "result.h5").stat().st_mtime_ns for n in table.variant}
    rerun = run_study(write_study(tmp_path), out, workers=2)
    assert rerun.computed == [] and sorted(rerun.skipped) == sorted(table["variant"])
    assert stamps == {n: (out / "variants" / n / "result.h5").stat().st_mtime_ns for n in stamps}
    pd.testing.assert_frame_equal(pd.read_csv(rerun.csv), table)
    # The table as the CLI prints it at 80 columns (nothing to compute: all finished): one line
    # per variant with its parameters and figures, nothing cut or folded into a column of
    # single characters (the long variant names did that; the parameters name the variant).
    env = {**os.environ, "COLUMNS": "80"}
    printed = subprocess.run(
        [sys.executable, "-m", "cablelife", "study", str(write_study(tmp_path)), "-o", str(out)],
        capture_output=True, text=True, env=env, check=True,
    ).stdout  # fmt: skip
    lines = printed.splitlines()
    table = lines[: next(i for i, line in enumerate(lines) if "already finished" in line)]
    assert max(map(len, table)) <= 80, printed
    assert f"summary: {outcome.csv}, {outcome.parquet}" in lines  # paths whole, not folded
    header = next(line for line in lines if "max D" in line)
    assert all(h in header for h in ("#", "shift", "length", "ratio", "spot (m)", "vol (l)"))
    rows = [r for r in map(str.split, lines) if len(r) >= 6 and r[0].isdigit() and "," not in r[1]]
    assert [int(r[0]) for r in rows] == [1, 2, 3, 4], printed
    assert float(rows[0][4]) == pytest.approx(1.0)  # the ratio of the best, whole


def test_a_failing_variant_is_reported_and_the_others_finish(tmp_path):
    # 1.0 m of cable must stretch far beyond the strain validity range to reach the clips:
    # with simulation.strain_limit = "error" that variant fails in its simulation.
    scene = tmp_path / "scene.toml"
    text = SCENE.read_text()
    scene.write_text(text.replace("[simulation]\n", '[simulation]\nstrain_limit = "error"\n', 1))
    assert 'strain_limit = "error"' in scene.read_text()
    study = write_study(tmp_path, "[0.0]", "[1.0, 1.25]")
    study.write_text(study.read_text().replace(SCENE.as_posix(), scene.as_posix()))
    out = tmp_path / "out"
    outcome = run_study(study, out, workers=1)
    assert list(outcome.failed) == ["shift=0_length=1"]
    assert "exceeds the model's validity range" in outcome.failed["shift=0_length=1"]
    table = outcome.table.set_index("variant")
    assert table.loc["shift=0_length=1.25", "status"] == "ok"
    assert table.loc["shift=0_length=1", "status"] == "failed"
    assert pd.isna(table.loc["shift=0_length=1", "rank"])
    error = json.loads((out / "variants" / "shift=0_length=1" / "error.json").read_text())
    assert error["stage"] == "simulation" and "axial strain" in error["error"]
    # the next run retries the failed variant only
    rerun = run_study(study, out, workers=1)
    assert rerun.computed == ["shift=0_length=1"] and rerun.skipped == ["shift=0_length=1.25"]


def _cli(*args: str, **kw) -> subprocess.Popen:
    return subprocess.Popen(
        [sys.executable, "-m", "cablelife", *args],
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        start_new_session=True,
        **kw,
    )


def _wait_for(predicate, timeout: float, what: str, procs=()):
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        if predicate():
            return
        for p in procs:
            if p.poll() is not None:
                raise AssertionError(f"{what}: process ended early:\n{p.stdout.read()}")
        time.sleep(0.2)
    raise AssertionError(f"timed out waiting for {what}")


def test_rerun_after_an_interruption_computes_only_the_missing_variants(tmp_path):
    """The interruption comes at a known point: Ctrl-C (KeyboardInterrupt) raised by the
    progress callback when the first variant has finished; the worker busy with the second is
    shut down with the cluster."""
    out = tmp_path / "out"
    study = write_study(tmp_path, "[0.0, 0.02, 0.04]", "[1.25, 1.26]")

    def ctrl_c_after_the_first(done: int, total: int, row: dict) -> None:
        if row:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        run_study(study, out, workers=1, progress=ctrl_c_after_the_first)
    assert not (out / "summary.csv").exists()
    finished = sorted(_rows(out))
    assert len(finished) == 1, finished
    outcome = run_study(study, out, workers=2)
    assert outcome.skipped == finished
    assert sorted(outcome.computed) == sorted(set(outcome.table["variant"]) - set(finished))
    assert len(outcome.computed) == 5
    assert len(outcome.table) == 6 and (outcome.table["status"] == "ok").all()


def test_ctrl_c_stops_a_study_quietly_and_keeps_the_finished_variants(tmp_path):
    out = tmp_path / "out"
    study = write_study(tmp_path, "[0.0, 0.02, 0.04]", "[1.25, 1.26]")
    proc = _cli("study", str(study), "-o", str(out), "--workers", "1")
    try:
        _wait_for(lambda: len(_rows(out)) >= 1, 300, "the first finished variant", [proc])
        os.killpg(proc.pid, signal.SIGINT)  # as a terminal does: the workers get it too
        start = time.monotonic()
        text, _ = proc.communicate(timeout=STOP_BOUND)
        stopped = time.monotonic() - start
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
    assert proc.returncode == 130, text
    assert "Traceback" not in text and "CommClosedError" not in text, text
    assert "interrupted: finished variants are kept" in text.replace("\n", " "), text
    assert not (out / "summary.csv").exists()
    assert stopped < STOP_BOUND
    finished = _rows(out)
    assert len(finished) >= 1, "the finished variant was not kept"
    assert len(finished) < 6, f"all {len(finished)} variants ran: the interruption was ignored"
    assert all(r["status"] == "ok" for r in finished.values()), finished


@pytest.fixture(scope="module")
def dask_cluster(tmp_path_factory):
    """A Dask scheduler and two single-threaded workers on loopback, as separate processes."""
    folder = tmp_path_factory.mktemp("dask")
    file = folder / "scheduler.json"
    common = {
        "cwd": folder,
        "start_new_session": True,
        "stdout": subprocess.DEVNULL,
        "stderr": subprocess.DEVNULL,
    }
    scheduler = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "distributed.cli.dask_scheduler",
            "--host",
            "127.0.0.1",
            "--port",
            "0",
            "--no-dashboard",
            "--scheduler-file",
            str(file),
        ],
        **common,
    )
    workers = []
    try:
        _wait_for(file.exists, 60, "the scheduler file")
        address = json.loads(file.read_text())["address"]
        for i in range(2):
            workers.append(
                subprocess.Popen(
                    [
                        sys.executable,
                        "-m",
                        "distributed.cli.dask_worker",
                        address,
                        "--nthreads",
                        "1",
                        "--nworkers",
                        "1",
                        "--no-dashboard",
                        "--name",
                        f"w{i}",
                        "--local-directory",
                        str(folder / f"w{i}"),
                    ],
                    **common,
                )
            )
        from distributed import Client

        with Client(address, timeout="30s") as client:
            client.wait_for_workers(2, timeout=60)
        yield address, workers
    finally:
        for p in [*workers, scheduler]:
            if p.poll() is None:
                os.killpg(p.pid, signal.SIGKILL)
                p.wait(30)


def test_study_on_an_existing_cluster_via_scheduler(tmp_path, dask_cluster):
    address, _ = dask_cluster
    out = tmp_path / "out"
    proc = _cli("study", str(write_study(tmp_path)), "-o", str(out), "--scheduler", address)
    text, _ = proc.communicate(timeout=600)
    assert proc.returncode == 0, text
    assert "4 computed, 0 already finished, 0 failed" in text
    table = pd.read_csv(out / "summary.csv")
    assert len(table) == 4 and (table["status"] == "ok").all()


def test_killing_a_worker_mid_study_still_yields_every_variant(tmp_path, dask_cluster):
    address, workers = dask_cluster
    out = tmp_path / "out"
    study = write_study(tmp_path, "[0.0, 0.01, 0.02, 0.03]", "[1.25, 1.26]")
    proc = _cli("study", str(study), "-o", str(out), "--scheduler", address)
    try:
        _wait_for(lambda: len(_rows(out)) >= 1, 300, "the first finished variant", [proc])
        os.killpg(workers[0].pid, signal.SIGKILL)  # the worker and its nanny
        text, _ = proc.communicate(timeout=600)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
    assert proc.returncode == 0, text
    table = pd.read_csv(out / "summary.csv")
    assert len(table) == 8 and (table["status"] == "ok").all(), text
    assert len(_rows(out)) == 8


def _process_tree(pid: int) -> set[int]:
    pids, todo = set(), [pid]
    while todo:
        p = todo.pop()
        pids.add(p)
        for task in Path(f"/proc/{p}/task").glob("*"):
            with contextlib.suppress(OSError):
                todo += [int(c) for c in (task / "children").read_text().split()]
    return pids


def _listening_ports(pids: set[int]) -> set[int]:
    """TCP ports the processes ``pids`` listen on (from /proc: their sockets' inodes)."""
    inodes = set()
    for pid in pids:
        for fd in Path(f"/proc/{pid}/fd").glob("*"):
            with contextlib.suppress(OSError):
                link = os.readlink(fd)
                if link.startswith("socket:["):
                    inodes.add(link[8:-1])
    ports = set()
    for table in ("/proc/net/tcp", "/proc/net/tcp6"):
        with contextlib.suppress(OSError):
            for line in Path(table).read_text().splitlines()[1:]:
                f = line.split()
                if f[3] == "0A" and f[9] in inodes:  # 0A: LISTEN
                    ports.add(int(f[1].rsplit(":", 1)[1], 16))
    return ports


def _speaks_http(port: int) -> bool:
    with socket.create_connection(("127.0.0.1", port), timeout=5) as s:
        s.settimeout(3)
        s.sendall(b"GET / HTTP/1.0\r\nHost: localhost\r\n\r\n")
        try:
            return s.recv(5) == b"HTTP/"
        except (TimeoutError, OSError):  # a Dask comm waits for its handshake, or hangs up
            return False


def test_a_local_study_runs_no_http_server(tmp_path):
    """Dask starts unauthenticated HTTP servers (scheduler: port 8787, workers: random ports)
    even without a dashboard. While the study runs, every port its processes listen on is asked
    for a web page: none may answer (only Dask's own protocol listens)."""
    seen: dict[int, bool] = {}
    me = os.getpid()
    before = _process_tree(me) - {me}  # e.g. the dask_cluster fixture's processes: not ours

    def probe(done: int, total: int, row: dict) -> None:
        if row and not seen:
            for port in _listening_ports(_process_tree(me) - before):
                seen[port] = _speaks_http(port)

    outcome = run_study(write_study(tmp_path, "[0.0]", "[1.25, 1.26]"), tmp_path / "o", workers=1,
                        progress=probe)  # fmt: skip
    assert not outcome.failed
    # the scheduler, the nanny and the worker each listen for Dask's protocol: the probe works
    assert len(seen) >= 3, seen
    assert 8787 not in seen
    assert not any(seen.values()), f"HTTP servers on ports {[p for p, h in seen.items() if h]}"


def _certificates(folder: Path) -> dict[str, Path]:
    """A CA and one certificate it signed (for scheduler, worker and client), by openssl."""
    if shutil.which("openssl") is None:
        pytest.skip("openssl is not installed (it makes the test certificates)")
    ca, ca_key = folder / "ca.pem", folder / "ca-key.pem"
    cert, key, csr = folder / "cert.pem", folder / "key.pem", folder / "cert.csr"
    ext = folder / "ext.cnf"
    ext.write_text("subjectAltName=DNS:localhost,IP:127.0.0.1\n")
    run = lambda *a: subprocess.run(["openssl", *a], check=True, capture_output=True)  # noqa: E731
    run("req", "-x509", "-newkey", "rsa:2048", "-nodes", "-keyout", ca_key, "-out", ca,
        "-days", "2", "-subj", "/CN=cablelife test CA")  # fmt: skip
    run("req", "-newkey", "rsa:2048", "-nodes", "-keyout", key, "-out", csr,
        "-subj", "/CN=localhost")  # fmt: skip
    run("x509", "-req", "-in", csr, "-CA", ca, "-CAkey", ca_key, "-CAcreateserial",
        "-out", cert, "-days", "2", "-extfile", ext)  # fmt: skip
    return {"ca": ca, "cert": cert, "key": key}


def test_study_on_a_tls_scheduler_with_client_certificates(tmp_path):
    pem = _certificates(tmp_path)
    tls = ["--tls-ca-file", str(pem["ca"]), "--tls-cert", str(pem["cert"]),
           "--tls-key", str(pem["key"])]  # fmt: skip
    file = tmp_path / "scheduler.json"
    common = {"cwd": tmp_path, "start_new_session": True, "stdout": subprocess.DEVNULL,
              "stderr": subprocess.DEVNULL}  # fmt: skip
    procs = [
        subprocess.Popen(
            [sys.executable, "-m", "distributed.cli.dask_scheduler", "--protocol", "tls",
             "--host", "127.0.0.1", "--port", "0", "--no-dashboard", "--scheduler-file",
             str(file), *tls],
            **common,
        )
    ]  # fmt: skip
    try:
        _wait_for(file.exists, 60, "the scheduler file", procs)
        address = json.loads(file.read_text())["address"]
        assert address.startswith("tls://")
        procs.append(
            subprocess.Popen(
                [sys.executable, "-m", "distributed.cli.dask_worker", address, "--nthreads",
                 "1", "--no-dashboard", "--local-directory", str(tmp_path / "w"), *tls],
                **common,
            )
        )  # fmt: skip
        study = str(write_study(tmp_path, "[0.0]", "[1.25]"))
        # without the certificates: a clear error, no traceback
        plain = _cli("study", study, "-o", str(tmp_path / "x"), "--scheduler", address)
        text, _ = plain.communicate(timeout=120)
        assert plain.returncode == 2 and "--tls-cert" in text and "Traceback" not in text, text
        bad = _cli("study", study, "--tls-cert", str(pem["cert"]))  # TLS options, no tls://
        text, _ = bad.communicate(timeout=120)
        assert bad.returncode == 2 and "need a tls:// scheduler" in text, text
        good = _cli("study", study, "-o", str(tmp_path / "out"), "--scheduler", address, *tls)
        text, _ = good.communicate(timeout=600)
        assert good.returncode == 0, text
        assert "1 computed, 0 already finished, 0 failed" in text
    finally:
        for p in procs:
            if p.poll() is None:
                os.killpg(p.pid, signal.SIGKILL)
                p.wait(30)
