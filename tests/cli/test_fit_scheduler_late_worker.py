"""`rti-rig fit --scheduler`: a worker that joins after the rti-rig check is given no task.

The check asked the workers there when the fit began; a worker joining later (restarted with
another rti-rig, or another user's added to the cluster) was given tasks unchecked: a batch's
session sent to an older rti-rig failed there ("ModuleNotFoundError"), and a worker with other
code would have fitted it with that code. Every task is now kept to the checked workers
(Dask's ``workers=`` / ``allow_other_workers=False``); when they have all left, the fit stops
and says so instead of waiting for ever.
"""

from __future__ import annotations

import os
import shutil
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
    """Another worker joins ``clusters[0]``, then every checked one leaves."""

    def then(client: Any, checked: frozenset[str]) -> None:
        clusters[0].scale(len(checked) + 1)
        client.wait_for_workers(len(checked) + 1, timeout=300)  # a bound on a hang
        client.retire_workers(sorted(checked), close_workers=True)

    return then


@pytest.mark.slow
@pytest.mark.parametrize("batch", [False, True], ids=["one session", "a batch"])
def test_a_fit_whose_checked_workers_all_left_stops_and_says_so(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, batch: bool
) -> None:
    from distributed import LocalCluster

    from rti_rig.app.usecases import fit_dask

    monkeypatch.setattr(
        fit_dask, "CHECKED_POLL_S", 0.2, raising=False
    )  # how often it looks, not a wait
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
        "the fit began have all left it; workers that joined since were not checked"
    ) in said, said
    assert "Traceback" not in r.output
    assert not any((out / s.name / "fit.json").exists() for s in sources)
    assert not (out / "fit.json").exists()
