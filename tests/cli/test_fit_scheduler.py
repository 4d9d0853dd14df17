"""`rti-rig fit --scheduler ADDRESS` through the front door: a real two-worker Dask cluster
(separate processes) gives the single-process fit's bytes, for one session (bands as tasks) and
for a batch (sessions as tasks, resumable); an address nobody answers is a clear error."""

from __future__ import annotations

import json
import logging
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from conftest import dead_pid
from typer.testing import CliRunner

from rti_rig.cli import app

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from fit_sessions import make_session

runner = CliRunner()
RTI_RIG = [sys.executable, "-c", "from rti_rig.cli import main; main()"]
#: Files whose bytes must match; fit.json names the source path as given (a cluster batch
#: records it absolute, workers do not share our working directory); lights.dome's label is
#: absolute in both.
OUTPUTS = ("normals.npy", "normals.png", "albedo.npy", "albedo.png", "fit.ptm", "fit.rti")


def test_an_unreachable_scheduler_is_a_clear_error(tmp_path: Path, monkeypatch) -> None:
    from rti_rig.app.usecases import fit_dask

    monkeypatch.setattr(fit_dask, "CONNECT_TIMEOUT_S", 1.0)
    session = make_session(tmp_path / "s", size=(24, 32))[0]
    for extra in ([], [str(session)]):  # one session, and a batch
        r = runner.invoke(
            app,
            [
                "fit",
                str(session),
                *extra,
                "--out",
                str(tmp_path / "o"),
                "--scheduler",
                "tcp://127.0.0.1:1",
            ],
        )
        assert r.exit_code == 2, r.output
        assert "tcp://127.0.0.1:1" in r.output and "dask scheduler" in r.output
        assert "same paths" in r.output and "Traceback" not in r.output
        assert not (tmp_path / "o" / "s" / "fit.json").exists()


def test_a_scheduler_without_workers_is_a_clear_error(tmp_path: Path, monkeypatch) -> None:
    from distributed import LocalCluster

    from rti_rig.app.usecases import fit_dask

    monkeypatch.setattr(fit_dask, "WORKERS_TIMEOUT_S", 1.0)
    session = make_session(tmp_path / "s", size=(24, 32))[0]
    with LocalCluster(n_workers=0, processes=False, dashboard_address=None) as cluster:
        address = cluster.scheduler_address
        r = runner.invoke(
            app, ["fit", str(session), "--out", str(tmp_path / "o"), "--scheduler", address]
        )
    assert r.exit_code == 2, r.output
    assert "has no workers" in r.output and f"dask worker {address}" in r.output
    assert "Traceback" not in r.output


def test_a_scheduler_of_another_dask_version_is_refused_naming_both(tmp_path: Path) -> None:
    """The scheduler answers Dask's ``versions`` request as distributed 2025.1.0 does (a
    scheduler of 2025.1.0 against this client: Dask's ``Client`` failed as it connected with
    "TypeError: Scheduler.identity() got an unexpected keyword argument 'n_workers'", said as
    "cannot reach the Dask scheduler … Start one with `dask scheduler`", then hung 40 s in its
    ``__del__`` and printed a traceback). Refused before any Client, one session or a batch."""
    import distributed
    from distributed import LocalCluster
    from distributed.versions import get_versions

    session = make_session(tmp_path / "s", size=(24, 32))[0]
    theirs = get_versions()
    theirs["packages"] = {**theirs["packages"], "dask": "2025.1.0", "distributed": "2025.1.0"}
    with LocalCluster(  # tcp://: an inproc:// address is not probed (only this process's)
        n_workers=1, threads_per_worker=1, processes=False, protocol="tcp", dashboard_address=None
    ) as cluster:
        cluster.scheduler.handlers["versions"] = lambda packages=None: theirs
        address = cluster.scheduler_address
        for extra in ([], [str(session)]):  # one session, and a batch
            out = tmp_path / "o"
            r = runner.invoke(
                app, ["fit", str(session), *extra, "--out", str(out), "--scheduler", address]
            )
            assert r.exit_code == 2, (r.output, r.exception)
            said = " ".join(r.output.split())
            mine = distributed.__version__
            assert (
                f"the Dask scheduler at '{address}' runs distributed 2025.1.0, and this machine "
                f"distributed {mine}" in said
            ), said
            assert "cannot reach" not in said and not out.exists()


def _unreadable(path: Path):
    """An image opener standing for a worker that does not see the session's files."""
    raise FileNotFoundError(2, "No such file or directory", str(path))


def test_a_worker_that_cannot_read_the_images_exits_2_naming_the_cluster(
    tmp_path: Path, monkeypatch
) -> None:

    from rti_rig.app.usecases import fit_dask

    session = make_session(tmp_path / "s", size=(24, 32))[0]
    monkeypatch.setattr(fit_dask, "read_image", _unreadable)  # what the workers open with
    r, address = _fit_on_one_worker(session, tmp_path / "o")
    assert r.exit_code == 2, r.output
    assert address in r.output and "could not read the images" in r.output
    assert "same paths" in r.output and "Traceback" not in r.output


def _fit_on_one_worker(session: Path, out: Path):  # type: ignore[no-untyped-def]
    """``rti-rig fit SESSION --out OUT --scheduler ADDR`` on an in-process cluster of one
    single-threaded worker; the result and the scheduler's address."""
    from distributed import LocalCluster

    with LocalCluster(
        n_workers=1, threads_per_worker=1, processes=False, dashboard_address=None
    ) as cluster:
        address = cluster.scheduler_address
        r = runner.invoke(app, ["fit", str(session), "--out", str(out), "--scheduler", address])
    return r, address


def _scheduler_gone(*args, **kwargs):
    """What a task's result raises on the client once the scheduler has gone away: Dask
    cancels every future of the client (``FutureCancelledError``, reason
    ``scheduler-connection-lost``), not an ``OSError``."""
    from distributed.client import FutureCancelledError

    raise FutureCancelledError("task", "scheduler-connection-lost", "Client lost the connection.")


def test_a_lost_scheduler_mid_fit_is_said_so(tmp_path: Path, monkeypatch) -> None:
    """It had said "a band of the fit failed … Check the workers' logs (memory limit?)"."""

    from rti_rig.app.usecases import fit_dask

    session = make_session(tmp_path / "s", size=(24, 32))[0]
    monkeypatch.setattr(fit_dask, "fit_band_recording", _scheduler_gone)
    r, address = _fit_on_one_worker(session, tmp_path / "o")
    assert r.exit_code == 2, r.output
    said = " ".join(r.output.split())
    assert f"lost the Dask scheduler at '{address}' while fitting" in said, said
    assert "memory limit" not in said and "run the same command" in said
    assert not (tmp_path / "o").exists()


class _Kept(logging.Handler):
    """The log records that reach a logger's handlers (past its filters)."""

    def __init__(self) -> None:
        super().__init__()
        self.messages: list[str] = []

    def emit(self, record: logging.LogRecord) -> None:
        self.messages.append(record.getMessage())


def test_a_scheduler_lost_before_the_bands_are_sent_is_said_so(tmp_path: Path, monkeypatch) -> None:
    """The scheduler really stopped while this process reads the sample and chooses the model,
    before any band is sent: Dask's client retries for its timeout, then a client call raises
    ``CommClosedError``. It had reached the user as a 120-line traceback (exit 1), after Dask's
    own timestamped "Failed to reconnect to scheduler" ERROR line."""
    from distributed import LocalCluster

    from rti_rig.app.usecases import fit_dask

    monkeypatch.setattr(fit_dask, "CONNECT_TIMEOUT_S", 5.0)  # Dask's reconnection window
    session = make_session(tmp_path / "s", size=(24, 32))[0]
    with LocalCluster(
        n_workers=1, threads_per_worker=1, processes=False, dashboard_address=None
    ) as cluster:
        address = cluster.scheduler_address
        files_of = fit_dask.acquisition_files

        def scheduler_stops_first(source):  # type: ignore[no-untyped-def]
            cluster.close()  # the scheduler process stops (killed, its machine rebooted)
            return files_of(source)

        monkeypatch.setattr(fit_dask, "acquisition_files", scheduler_stops_first)
        out = tmp_path / "o"
        kept, log = _Kept(), logging.getLogger("distributed.client")
        log.addHandler(kept)
        try:
            r = runner.invoke(app, ["fit", str(session), "--out", str(out), "--scheduler", address])
        finally:
            log.removeHandler(kept)
    assert r.exit_code == 2, (r.output, r.exception)
    said = " ".join(r.output.split())
    assert f"lost the Dask scheduler at '{address}' while fitting" in said, said
    assert "run the same command" in said and not out.exists()
    assert not [m for m in kept.messages if "Failed to reconnect" in m], kept.messages


def test_a_lost_scheduler_mid_batch_keeps_and_names_the_finished_sessions(
    tmp_path: Path, monkeypatch
) -> None:
    """A session can finish on its worker while the client waits for another's result; Dask
    then cancels its future with the rest. Every session had been reported "failed on the Dask
    cluster: FutureCancelledError", the finished one too, and no word of resuming."""
    from distributed import LocalCluster

    from rti_rig.app.usecases import fit_dask

    for name in ("s1", "s2"):
        make_session(tmp_path / name, size=(24, 32))
    real = fit_dask.fit_one

    def finishes_then_loses_the_scheduler(source, root, template, bands=None):  # type: ignore[no-untyped-def]
        if source.name == "s1":
            real(source, root, template)
        _scheduler_gone()

    monkeypatch.setattr(fit_dask, "fit_one", finishes_then_loses_the_scheduler)
    out = tmp_path / "o"
    with LocalCluster(
        n_workers=1, threads_per_worker=1, processes=False, dashboard_address=None
    ) as cluster:
        address = cluster.scheduler_address
        args = ["fit", str(tmp_path / "s1"), str(tmp_path / "s2"), "--out", str(out)]
        r = runner.invoke(app, [*args, "--no-qa", "--scheduler", address])
    assert r.exit_code == 2, r.output
    said = " ".join(r.output.split())
    assert f"lost the Dask scheduler at '{address}' during the batch" in said, said
    assert f"1 of 2 sessions are finished in {out.resolve()} ({tmp_path / 's1'})" in said
    assert "run the same command" in said and "s1: failed" not in said
    # a worker goes on with the task it runs: a real scheduler killed mid-batch had been said
    # as "no session is finished yet", and the session being fitted appeared in ROOT after
    assert (
        f"a session a worker had already begun may still finish there and appear in {out.resolve()}"
        in said
    )
    assert (out / "s1" / "fit.json").exists() and not (out / "s2").exists()


def test_a_cluster_batch_names_outputs_and_refuses_twice_given_sources_as_without_dask(
    tmp_path: Path, monkeypatch
) -> None:
    """Sources had been resolved before naming their outputs: a symlinked session folder was
    fitted into OUT/<the link's target> (OUT/<the link> without Dask: a rerun either way
    fitted it again), and one session given as s1 and ./s1 was merged into one fit silently
    where the batch without Dask refuses it."""
    from distributed import LocalCluster

    make_session(tmp_path / "sessions" / "s1", size=(24, 32))
    (tmp_path / "coin_day2").symlink_to(tmp_path / "sessions" / "s1")
    monkeypatch.chdir(tmp_path)
    with LocalCluster(
        n_workers=1, threads_per_worker=1, processes=False, dashboard_address=None
    ) as cluster:
        address = cluster.scheduler_address
        batch = ["fit", "coin_day2", "sessions/s1", "--no-qa", "--model", "ps"]
        r = runner.invoke(app, [*batch, "--out", "o", "--scheduler", address])
        assert r.exit_code == 0, r.output
        assert sorted(p.name for p in (tmp_path / "o").iterdir()) == ["coin_day2", "s1"]
        twice = ["fit", "sessions/s1", "./sessions/s1", "--no-qa", "--out", "o2"]
        r = runner.invoke(app, [*twice, "--scheduler", address])
    assert r.exit_code == 2, r.output
    assert "sources would write to the same output folder" in " ".join(r.output.split())
    assert not (tmp_path / "o2" / "s1").exists()


def test_a_cluster_batch_source_missing_here_too_is_not_blamed_on_the_workers(
    tmp_path: Path,
) -> None:
    """A mistyped source had been sent to a worker and reported "does not exist on worker host
    HOST: every Dask worker must see the session's files at the same paths", a wrong lead."""
    from distributed import LocalCluster

    make_session(tmp_path / "s1", size=(24, 32))
    with LocalCluster(
        n_workers=1, threads_per_worker=1, processes=False, dashboard_address=None
    ) as cluster:
        args = ["fit", str(tmp_path / "s1"), str(tmp_path / "s2"), "--no-qa", "--model", "ps"]
        r = runner.invoke(
            app, [*args, "--out", str(tmp_path / "o"), "--scheduler", cluster.scheduler_address]
        )
    assert r.exit_code == 2, r.output
    said = " ".join(r.output.split())
    assert f"{tmp_path / 's2'}: failed: {tmp_path / 's2'} does not exist: give a session" in said
    assert "worker host" not in said and f"{tmp_path / 's1'}: done" in said


def _cli(args: list[str], env: dict[str, str], cwd: Path) -> subprocess.CompletedProcess:
    return subprocess.run(
        [*RTI_RIG, *args], capture_output=True, text=True, env=env, cwd=cwd, timeout=900
    )


@pytest.mark.slow
@pytest.mark.e2e
def test_a_local_two_worker_cluster_gives_the_single_process_bytes(tmp_path: Path) -> None:
    from distributed import LocalCluster

    # LocalCluster sets OMP/OPENBLAS_NUM_THREADS=1 in this process's environment for its
    # workers; both command lines get the environment from before it, as a user's shell would
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join(
        [str(Path(__file__).resolve().parents[2]), env.get("PYTHONPATH", "")]
    )
    for name, seed in (("s1", 0), ("s2", 1), ("s3", 2)):
        make_session(tmp_path / name, size=(48, 64), seed=seed)
    with LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
    ) as cluster:
        address = cluster.scheduler_address
        # one session, its bands as tasks
        r = _cli(["fit", "s1", "--out", "plain1"], env, tmp_path)
        assert r.returncode == 0, r.stderr
        r = _cli(["fit", "s1", "--out", "dask1", "--scheduler", address], env, tmp_path)
        assert r.returncode == 0, r.stdout + r.stderr
        for name in sorted(p.name for p in (tmp_path / "plain1").iterdir()):
            assert (tmp_path / "plain1" / name).read_bytes() == (
                tmp_path / "dask1" / name
            ).read_bytes(), name
        # a batch, sessions as tasks; a killed earlier run finished s1 and left s2 partial
        batch = ["fit", "s1", "s2", "s3", "--out", "batch", "--model", "ps"]
        plain = ["fit", "s1", "s2", "s3", "--out", "plainbatch", "--model", "ps"]
        assert _cli(plain, env, tmp_path).returncode == 0
        (tmp_path / "batch").mkdir()
        shutil.copytree(tmp_path / "plainbatch" / "s1", tmp_path / "batch" / "s1")
        stamp = (tmp_path / "batch" / "s1" / "normals.npy").stat().st_mtime_ns
        left = tmp_path / "batch" / f".s2.{dead_pid()}-dead.partial"  # a killed run's
        left.mkdir()
        (left / "fit.ptm.part").write_text("x")
        r = _cli([*batch, "--scheduler", address], env, tmp_path)
        assert r.returncode == 0, r.stdout + r.stderr
        assert "s1: skipped (finished earlier)" in r.stdout
        assert "s2: done" in r.stdout and "s3: done" in r.stdout
        assert not list((tmp_path / "batch").glob(".*partial"))
        assert (tmp_path / "batch" / "s1" / "normals.npy").stat().st_mtime_ns == stamp
        for s in ("s2", "s3"):
            for name in OUTPUTS:
                a = (tmp_path / "plainbatch" / s / name).read_bytes()
                assert a == (tmp_path / "batch" / s / name).read_bytes(), (s, name)
            got = json.loads((tmp_path / "batch" / s / "fit.json").read_text())
            ref = json.loads((tmp_path / "plainbatch" / s / "fit.json").read_text())
            assert Path(got.pop("source")) == (tmp_path / s).resolve()
            read = got.pop("read")  # "36 images from <the .lp, absolute>"
            assert read == f"36 images from {(tmp_path / s / 'lights.lp').resolve()}"
            # the plain batch's too: it had kept the path as given ("from s2/lights.lp")
            assert ref.pop("read") == read
            ref.pop("source")
            assert got == ref
        r = _cli([*batch, "--scheduler", address], env, tmp_path)
        assert r.returncode == 0 and r.stdout.count("(finished earlier)") == 3, r.stdout
        # s2's lights recalibrated since: refitted on the cluster, said so; the rest stand
        from rti_rig.core.lp_format import LpEntry, read_lp, write_lp

        entries = read_lp(tmp_path / "s2" / "lights.lp")
        moved = np.add(entries[0].direction, [0.02, 0.0, 0.0])
        entries[0] = LpEntry(entries[0].name, tuple(moved / np.linalg.norm(moved)))
        write_lp(tmp_path / "s2" / "lights.lp", entries)
        r = _cli([*batch, "--scheduler", address], env, tmp_path)
        said = " ".join(r.stdout.split())
        assert r.returncode == 0, r.stdout + r.stderr
        changed = "its session changed since the earlier fit: 1 of 36 lights moved: "
        assert f"s2: refitted ({changed}{Path(entries[0].name).stem}'s by " in said
        assert said.count("(finished earlier)") == 2, said
        assert sorted(p.name for p in (tmp_path / "batch").iterdir()) == ["s1", "s2", "s3"]


def test_a_batch_session_whose_result_cannot_be_read_back_but_whose_fit_stands_is_not_failed(
    tmp_path: Path, monkeypatch
) -> None:
    """A result the client cannot read (a worker running other rti-rig code) raised here
    although the session's fit ended on the worker, complete in --out: it had been said
    "A: failed on the Dask cluster: ModuleNotFoundError …", and the rerun "skipped (finished
    earlier)"."""
    from distributed import LocalCluster

    from rti_rig.app.usecases import fit_dask

    for name in ("A", "B"):
        make_session(tmp_path / name, size=(24, 32))
    real = fit_dask.fit_one

    def fits_then_its_result_cannot_be_read(source, root, template, bands=None):  # type: ignore[no-untyped-def]
        item = real(source, root, template)
        if source.name == "B":
            return item
        raise ModuleNotFoundError("No module named 'rti_rig.app.usecases.fit_batch'")

    monkeypatch.setattr(fit_dask, "fit_one", fits_then_its_result_cannot_be_read)
    out = tmp_path / "FB"
    with LocalCluster(
        n_workers=1, threads_per_worker=1, processes=False, dashboard_address=None
    ) as cluster:
        args = ["fit", str(tmp_path / "A"), str(tmp_path / "B"), "--out", str(out), "--no-qa"]
        r = runner.invoke(app, [*args, "--model", "ps", "--scheduler", cluster.scheduler_address])
    said = " ".join(r.output.split())
    assert r.exit_code == 0, said
    assert f"{tmp_path / 'A'}: finished on its worker; its report could not be read here" in said
    assert f"its fit stands complete in {out.resolve() / 'A'}" in said, said
    assert "failed" not in said and (out / "A" / "fit.json").exists()


@pytest.mark.parametrize("first", ["client", "server"])
def test_a_port_that_answers_as_another_service_is_said_not_a_dask_scheduler(
    tmp_path: Path, first: str
) -> None:
    """A proxy or web server on the port had been read by Dask as a message of 3 EiB: "cannot
    reach the Dask scheduler (MemoryError: Unable to allocate 3.01 EiB …). Start one with
    `dask scheduler`"."""
    import contextlib
    import socket
    import threading

    server = socket.create_server(("127.0.0.1", 0))
    port = server.getsockname()[1]
    done = threading.Event()

    def answer() -> None:
        server.settimeout(0.2)
        while not done.is_set():
            try:
                conn, _ = server.accept()
            except TimeoutError:
                continue
            with conn:
                conn.settimeout(2.0)
                if first == "client":  # as an HTTP server: the request, then its refusal
                    with contextlib.suppress(TimeoutError):
                        conn.recv(4096)
                conn.sendall(b"HTTP/1.0 426 Upgrade Required\r\n\r\n")

    thread = threading.Thread(target=answer, daemon=True)
    thread.start()
    session = make_session(tmp_path / "s", size=(24, 32))[0]
    address = f"tcp://127.0.0.1:{port}"
    try:
        argv = ["fit", str(session), "--out", str(tmp_path / "o"), "--scheduler", address]
        r = runner.invoke(app, argv, terminal_width=400)
    finally:
        done.set()
        thread.join(5.0)
        server.close()
    said = " ".join(r.output.split())
    assert r.exit_code == 2, said
    assert "Traceback" not in said and "MemoryError" not in said and "EiB" not in said, said
    assert (
        f"--scheduler '{address}': what answers there is not a Dask scheduler (its reply is not "
        "a Dask message"
    ) in said, said
    assert not (tmp_path / "o" / "fit.json").exists()
