"""`rti-rig fit --scheduler`: a worker of another Python minor version that joins after the
cluster's Python was checked is refused in the check's words, naming it and both versions.

It had been said in the tag check's words alone, "other code" (or "could not be asked",
"other versions of the libraries"), its Python unnamed, so that the user did not learn to run
it under this machine's Python. The worker is a real `dask worker` process whose Python says
it is the next minor version (:data:`OTHER_PYTHON_WORKER`), as Dask's report and the rti-rig
check read it: a second interpreter is not needed to show what is said.
"""

from __future__ import annotations

import subprocess
import sys
import warnings
from pathlib import Path
from typing import Any

import pytest
from test_fit_scheduler_late_worker import after_the_check, quick_looks
from test_fit_scheduler_worker_versions import NEXT, OTHER_PYTHON_WORKER, OURS
from typer.testing import CliRunner

from rti_rig.cli import app

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from fit_sessions import make_session

runner = CliRunner()


def _join(address: str, cwd: Path, workers: list[subprocess.Popen[bytes]]) -> None:
    """Start a worker of the next Python minor version on the scheduler at ``address``."""
    worker = subprocess.Popen(
        [sys.executable, "-c", OTHER_PYTHON_WORKER, address, "--nthreads", "1",
         "--no-nanny", "--no-dashboard"],
        cwd=cwd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
    )  # fmt: skip
    workers.append(worker)


def _fit(tmp_path: Path) -> tuple[Any, str]:
    """Fit session A on a local cluster of one in-process worker (reachable from worker
    processes); the result and the scheduler's address."""
    from distributed import LocalCluster

    session = make_session(tmp_path / "A", size=(24, 32))[0]
    args = ["fit", str(session), "--out", str(tmp_path / "F"), "--no-qa", "--model", "ps"]
    with LocalCluster(
        n_workers=1,
        threads_per_worker=1,
        processes=False,
        protocol="tcp",
        host="127.0.0.1",
        dashboard_address=None,
    ) as cluster:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # Dask's own table of the versions
            r = runner.invoke(app, [*args, "--scheduler", cluster.scheduler_address])
        return r, cluster.scheduler_address


@pytest.mark.slow
def test_a_worker_of_another_python_joining_after_the_check_is_named_with_both(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """It joins once the cluster was checked and the checked worker leaves: the fit stops,
    saying the late worker runs another Python, both versions and what to do."""
    quick_looks(monkeypatch, grace_s=1.0)
    workers: list[subprocess.Popen[bytes]] = []
    joined: list[str] = []

    def another_python_joins_and_the_checked_leaves(client: Any, checked: frozenset[str]) -> None:
        _join(client.scheduler.address, tmp_path, workers)
        client.wait_for_workers(len(checked) + 1, timeout=300)  # a bound on a hang
        joined.extend(set(client.scheduler_info()["workers"]) - checked)
        client.retire_workers(sorted(checked), close_workers=True)

    after_the_check(monkeypatch, another_python_joins_and_the_checked_leaves)
    try:
        r, address = _fit(tmp_path)
    finally:
        for worker in workers:  # killed: a SIGTERM'd dask worker may spend minutes closing
            worker.kill()
            worker.wait(timeout=120)
    said = " ".join(r.output.split())
    assert r.exit_code == 2, said
    (late,) = joined
    assert "have all left it" in said, said
    assert (
        f"1 of the 1 workers there now run another Python than this machine (Python {OURS}): "
        f"{late} (Python {NEXT})"
    ) in said, said
    assert f"so they were given no task: run those workers under Python {OURS}" in said, said
    assert f"`dask worker {address}`" in said, said
    assert "other code than this fit" not in said and "Traceback" not in r.output, said
    assert not (tmp_path / "F" / "fit.json").exists()


def test_a_worker_of_another_python_joining_during_the_check_is_named_with_both(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """It joins after the Python check, before the rti-rig check asks the workers: refused
    before anything is sent, in the Python check's words (not "other versions of the
    libraries", nor "could not be asked", where this machine's functions cannot run)."""
    from rti_rig.app.usecases import fit_dask

    workers: list[subprocess.Popen[bytes]] = []
    joined: list[str] = []
    real = fit_dask.worker_identities

    def another_python_joins_first(client: Any) -> Any:
        before = set(client.scheduler_info()["workers"])
        if not workers:
            _join(client.scheduler.address, tmp_path, workers)
            client.wait_for_workers(len(before) + 1, timeout=300)  # a bound on a hang
            joined.extend(set(client.scheduler_info()["workers"]) - before)
        return real(client)

    monkeypatch.setattr(fit_dask, "worker_identities", another_python_joins_first)
    try:
        r, address = _fit(tmp_path)
    finally:
        for worker in workers:
            worker.kill()
            worker.wait(timeout=120)
    said = " ".join(r.output.split())
    assert r.exit_code == 2, said
    (late,) = joined
    assert (
        f"1 of the 2 workers of the Dask cluster at '{address}' run another Python than this "
        f"machine (Python {OURS}): {late} (Python {NEXT})"
    ) in said, said
    assert "nothing was sent" in said and "other versions of the libraries" not in said, said
    assert "Traceback" not in r.output
    assert not (tmp_path / "F").exists()
