"""`rti-rig fit --scheduler`: tasks go only to worker processes checked to run this rti-rig,
those that join or restart later included.

The check asked the workers there when the fit began; a worker joining later (restarted with
another rti-rig, or another user's added to the cluster) was given tasks unchecked: a batch's
session sent to an older rti-rig failed there ("ModuleNotFoundError"), and a worker with other
code would have fitted it with that code. Tasks were then kept to the checked workers'
addresses, but an address is not a worker: one restarted by its nanny came back elsewhere and
the fit stopped, one restarted on the same fixed port with other code was given the tasks. A
worker is now tagged (a Dask resource every task asks for) by its own process, as it joins,
once its code is found to be this one; with none such for a while, the fit stops and says so.
"""

from __future__ import annotations

import os
import shutil
import socket
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

import pytest
from typer.testing import CliRunner

import rti_rig
from rti_rig.cli import app

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from fit_sessions import make_session

runner = CliRunner()
#: What the other rti-rig's fit writes in each fit.json it makes.
OTHER_MARK = "fitted_by_other_code"


def _other_rti_rig(where: Path) -> Path:
    """A copy of rti-rig that reads the same tasks but fits with other code: another version,
    whose fit.json carries :data:`OTHER_MARK`."""
    package = where / "rti_rig"
    shutil.copytree(
        Path(rti_rig.__file__).parent, package, ignore=shutil.ignore_patterns("__pycache__")
    )
    fit = package / "app" / "usecases" / "fit.py"
    text = fit.read_text(encoding="utf-8")
    assert text.count('"source": str(req.source),') == 1
    fit.write_text(
        text.replace(
            '"source": str(req.source),', f'"source": str(req.source), "{OTHER_MARK}": 1,'
        ),
        encoding="utf-8",
    )
    init = package / "__init__.py"
    init.write_text(
        init.read_text().replace(f'"{rti_rig.__version__}"', '"0.0.9-other"'), encoding="utf-8"
    )
    return where


def after_the_check(monkeypatch: pytest.MonkeyPatch, then: Any) -> None:
    """Run ``then(client, checked)`` once the fit has checked the cluster's workers, before
    it sends any task (a worker joining, or leaving, at that moment)."""
    from rti_rig.app.usecases import fit_dask

    real = fit_dask._refuse_other_code

    def check(client: Any, address: str) -> Any:
        answer = real(client, address)
        then(client, frozenset(client.scheduler_info()["workers"]))  # those it asked
        return answer

    monkeypatch.setattr(fit_dask, "_refuse_other_code", check)


@pytest.mark.slow
def test_a_worker_of_other_code_joining_after_the_check_fits_no_session(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from distributed import LocalCluster

    from rti_rig.app.usecases import fit_dask

    names = ("A", "B", "C")
    for name in names:
        make_session(tmp_path / name, size=(24, 32))
    env = {**os.environ, "PYTHONPATH": str(_other_rti_rig(tmp_path / "other"))}
    workers: list[subprocess.Popen[bytes]] = []

    def a_worker_of_other_code_joins(client: Any, checked: frozenset[str]) -> None:
        address = client.scheduler.address
        worker = subprocess.Popen(
            [sys.executable, "-m", "distributed.cli.dask_worker", address, "--nthreads", "1",
             "--no-nanny", "--no-dashboard"],
            cwd=tmp_path, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
        )  # fmt: skip
        workers.append(worker)
        client.wait_for_workers(len(checked) + 1, timeout=300)  # a bound on a hang

    after_the_check(monkeypatch, a_worker_of_other_code_joins)
    clusters: list[Any] = []
    real = fit_dask.fit_one

    def once_every_session_is_given_out(*args: Any, **kwargs: Any) -> Any:
        """The checked (in-process) worker starts a session only once no session waits in the
        scheduler's queue: each has been given to a worker, the late one too if it may take
        any (a fast checked worker had otherwise taken all three first)."""
        scheduler = clusters[0].scheduler
        deadline = time.monotonic() + 300  # a bound on a hang, not a timing
        while any(
            ts.state in ("released", "waiting", "queued", "no-worker")
            for ts in list(scheduler.tasks.values())
            if "_fit_one_task" in str(ts.key)
        ):
            assert time.monotonic() < deadline, "sessions never given out"
            time.sleep(0.05)
        return real(*args, **kwargs)

    monkeypatch.setattr(fit_dask, "fit_one", once_every_session_is_given_out)
    out = tmp_path / "FB"
    try:
        with LocalCluster(
            n_workers=1,
            threads_per_worker=1,
            processes=False,
            protocol="tcp",  # reachable from the worker process
            host="127.0.0.1",
            dashboard_address=None,
        ) as cluster:
            clusters.append(cluster)
            args = ["fit", *(str(tmp_path / n) for n in names), "--out", str(out), "--no-qa"]
            r = runner.invoke(
                app, [*args, "--model", "ps", "--scheduler", cluster.scheduler_address]
            )
    finally:
        for worker in workers:  # a throwaway: killed, since a SIGTERM'd dask worker may
            worker.kill()  # spend minutes closing gracefully towards a scheduler now gone
            worker.wait(timeout=120)
    assert len(workers) == 1
    said = " ".join(r.output.split())
    assert r.exit_code == 0, said
    assert said.count(": done") == 3 and "failed" not in said, said
    for n in names:  # each fitted by this machine's rti-rig, none by the late worker's
        assert OTHER_MARK not in (out / n / "fit.json").read_text(encoding="utf-8"), n


def retire_the_checked(clusters: list[Any]) -> Any:
    """Every checked worker of ``clusters[0]`` leaves, and none comes back."""

    def then(client: Any, checked: frozenset[str]) -> None:
        client.retire_workers(sorted(checked), close_workers=True)

    return then


def quick_looks(monkeypatch: pytest.MonkeyPatch, grace_s: float) -> None:
    """The fit looks often for a checked worker (not a wait) and stops once none has been
    there for ``grace_s``."""
    from rti_rig.app.usecases import fit_dask

    monkeypatch.setattr(fit_dask, "CHECKED_POLL_S", 0.2, raising=True)
    monkeypatch.setattr(fit_dask, "CHECKED_GRACE_S", grace_s, raising=True)


@pytest.mark.slow
@pytest.mark.parametrize("batch", [False, True], ids=["one session", "a batch"])
def test_a_fit_whose_checked_workers_all_left_stops_and_says_so(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, batch: bool
) -> None:
    from distributed import LocalCluster

    quick_looks(monkeypatch, grace_s=1.0)
    sources = [make_session(tmp_path / n, size=(24, 32))[0] for n in ("A", "B")[: 1 + batch]]
    clusters: list[Any] = []
    after_the_check(monkeypatch, retire_the_checked(clusters))
    out = tmp_path / "FB"
    with LocalCluster(
        n_workers=1, threads_per_worker=1, processes=False, dashboard_address=None
    ) as cluster:
        clusters.append(cluster)
        address = cluster.scheduler_address
        args = ["fit", *map(str, sources), "--out", str(out), "--no-qa", "--model", "ps"]
        r = runner.invoke(app, [*args, "--scheduler", address])
    said = " ".join(r.output.split())
    assert r.exit_code == 2, said
    assert (
        f"the 1 worker(s) of the Dask cluster at '{address}' whose rti-rig was checked when "
        f"the fit began have all left it, and no worker running this rti-rig (rti-rig "
        f"{rti_rig.__version__}, code "
    ) in said, said
    assert "no worker is there now" in said, said
    assert "Traceback" not in r.output
    assert not any((out / s.name / "fit.json").exists() for s in sources)
    assert not (out / "fit.json").exists()


def _free_port() -> int:
    """A TCP port free on 127.0.0.1 now (for a worker given a fixed ``--worker-port``)."""
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def _until(condition: Any, what: str, timeout: float = 300.0) -> None:
    """Wait for ``condition()`` (a bound on a hang, not a timing)."""
    deadline = time.monotonic() + timeout
    while not condition():
        assert time.monotonic() < deadline, what
        time.sleep(0.05)


@pytest.mark.slow
def test_a_worker_restarted_on_the_checked_port_with_other_code_fits_nothing(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A worker started with a fixed ``--worker-port`` is checked, then replaced on that same
    port by one running other code: it had been taken for the checked one (tasks were kept
    to the checked address) and fitted the sessions with its own code."""
    from distributed import LocalCluster

    quick_looks(monkeypatch, grace_s=1.0)
    names = ("A", "B")
    for name in names:
        make_session(tmp_path / name, size=(24, 32))
    other_env = {**os.environ, "PYTHONPATH": str(_other_rti_rig(tmp_path / "other"))}
    port = _free_port()
    workers: list[subprocess.Popen[bytes]] = []
    clusters: list[Any] = []

    def start_worker(env: dict[str, str]) -> None:
        workers.append(
            subprocess.Popen(
                [sys.executable, "-m", "distributed.cli.dask_worker",
                 clusters[0].scheduler_address, "--nthreads", "1", "--no-nanny",
                 "--no-dashboard", "--worker-port", str(port)],
                cwd=tmp_path, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
            )
        )  # fmt: skip

    def replaced_by_other_code(client: Any, checked: frozenset[str]) -> None:
        (address,) = checked
        assert address.endswith(f":{port}"), address
        scheduler = clusters[0].scheduler
        workers[0].kill()
        workers[0].wait(timeout=120)
        _until(lambda: address not in scheduler.workers, "the killed worker stayed")
        start_worker(other_env)
        _until(lambda: address in scheduler.workers, "the other worker never joined")

    after_the_check(monkeypatch, replaced_by_other_code)
    out = tmp_path / "FB"
    try:
        with LocalCluster(
            n_workers=0,
            processes=False,
            protocol="tcp",  # reachable from the worker processes
            host="127.0.0.1",
            dashboard_address=None,
        ) as cluster:
            clusters.append(cluster)
            start_worker(dict(os.environ))  # this rti-rig, on the fixed port
            _until(lambda: len(cluster.scheduler.workers) == 1, "the worker never joined")
            args = ["fit", *(str(tmp_path / n) for n in names), "--out", str(out), "--no-qa"]
            r = runner.invoke(
                app, [*args, "--model", "ps", "--scheduler", cluster.scheduler_address]
            )
    finally:
        for worker in workers:  # killed: a SIGTERM'd dask worker may take minutes to close
            worker.kill()
            worker.wait(timeout=120)
    assert len(workers) == 2
    said = " ".join(r.output.split())
    assert r.exit_code == 2, said
    assert (
        "the workers there now were refused, their rti-rig being another or none: "
        f"tcp://127.0.0.1:{port}"
    ) in said, said
    assert "Traceback" not in r.output
    for n in names:  # fitted by no one: not by the other code
        assert not (out / n / "fit.json").exists(), n


@pytest.mark.slow
@pytest.mark.parametrize("batch", [False, True], ids=["one session", "a batch"])
def test_a_worker_restarted_by_its_nanny_on_a_new_address_goes_on_fitting(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, batch: bool
) -> None:
    """The checked worker dies (as a memory kill does) once the fit has checked it, before any
    task is sent; its nanny starts it again on another port, with the same code, and it joins
    while the fit's tasks wait. The fit had stopped, saying every checked worker had left."""
    from distributed import LocalCluster

    quick_looks(monkeypatch, grace_s=600.0)  # a bound on a hang: the restart takes seconds
    sources = [make_session(tmp_path / n, size=(24, 32))[0] for n in ("A", "B")[: 1 + batch]]
    first: list[str] = []

    def the_worker_dies(client: Any, checked: frozenset[str]) -> None:
        first.extend(checked)
        client.run(os._exit, 1, on_error="return")  # its answer: the connection lost

    after_the_check(monkeypatch, the_worker_dies)
    out = tmp_path / "FB"
    with LocalCluster(
        n_workers=1,
        threads_per_worker=1,
        processes=True,  # under a nanny, which restarts it
        host="127.0.0.1",
        dashboard_address=None,
    ) as cluster:
        args = ["fit", *map(str, sources), "--out", str(out), "--no-qa"]
        r = runner.invoke(app, [*args, "--model", "ps", "--scheduler", cluster.scheduler_address])
        now = set(cluster.scheduler.workers)
    said = " ".join(r.output.split())
    assert len(first) == 1 and first[0] not in now, (first, now)  # it did restart elsewhere
    assert r.exit_code == 0, said
    if batch:
        assert said.count(": done") == 2 and "failed" not in said, said
        (now_there,) = now
        assert said.count(f"note: ran on the Dask worker at {now_there} (host ") == 2, said
        assert all((out / s.name / "fit.json").exists() for s in sources)
    else:
        assert (out / "fit.json").exists(), said
