"""`rti-rig fit --scheduler` on a cluster whose workers run another rti-rig: refused before any
task is sent, naming the workers that differ (a batch had printed Dask's raw "Failed to
deserialize" traceback and called a session "failed: ModuleNotFoundError: No module named
'rti_rig.app.usecases.fit_batch'" whose fit stood complete in --out)."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

from typer.testing import CliRunner

import rti_rig
from rti_rig.cli import app

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from fit_sessions import make_session

runner = CliRunner()


def _older_rti_rig(where: Path) -> Path:
    """A copy of rti-rig as an older release: another version, and no ``fit_batch`` module."""
    package = where / "rti_rig"
    shutil.copytree(
        Path(rti_rig.__file__).parent, package, ignore=shutil.ignore_patterns("__pycache__")
    )
    (package / "app" / "usecases" / "fit_batch.py").unlink()
    init = package / "__init__.py"
    init.write_text(
        init.read_text().replace(f'"{rti_rig.__version__}"', '"0.0.9-older"'), encoding="utf-8"
    )
    return where


def test_a_worker_running_other_rti_rig_code_is_refused_before_any_task(tmp_path: Path) -> None:
    from distributed import Client, LocalCluster

    for name in ("A", "B"):
        make_session(tmp_path / name, size=(24, 32))
    older = _older_rti_rig(tmp_path / "older")
    env = {**os.environ, "PYTHONPATH": str(older)}
    with LocalCluster(
        n_workers=1,
        threads_per_worker=1,
        processes=False,
        protocol="tcp",  # reachable from the worker process
        host="127.0.0.1",
        dashboard_address=None,
    ) as cluster:
        address = cluster.scheduler_address
        ours = set(cluster.scheduler.workers)
        # A worker process of its own, importing the older copy (its own rti_rig, its check
        # run there): started as `dask worker` is, from the venv's distributed.
        worker = subprocess.Popen(
            [sys.executable, "-m", "distributed.cli.dask_worker", address, "--nthreads", "1",
             "--no-nanny", "--no-dashboard"],
            cwd=tmp_path, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
        )  # fmt: skip
        try:
            with Client(address, set_as_default=False) as watcher:
                watcher.wait_for_workers(2, timeout=300)  # a bound on a hang, not a timing
                (other,) = set(watcher.scheduler_info()["workers"]) - ours
            out = tmp_path / "FB"
            args = ["fit", str(tmp_path / "A"), str(tmp_path / "B"), "--out", str(out)]
            r = runner.invoke(app, [*args, "--no-qa", "--model", "ps", "--scheduler", address])
        finally:
            worker.terminate()
            worker.wait(timeout=120)
    assert r.exit_code == 2, r.output
    said = " ".join(r.output.split())
    assert f"1 of the 2 workers of the Dask cluster at '{address}'" in said, said
    assert f"{other} (rti-rig 0.0.9-older, code " in said, said
    assert f"this machine (rti-rig {rti_rig.__version__}, code " in said, said
    assert "install this same rti-rig on every worker" in said
    assert "Traceback" not in r.output and "ModuleNotFoundError" not in r.output
    assert not (out / "A").exists() and not (out / "B").exists()


def test_dask_s_unreadable_result_traceback_stays_off_the_terminal(tmp_path: Path) -> None:
    """What the command line's ``main`` sets up keeps Dask's "Failed to deserialize" record
    (logged with its traceback by Dask's own stderr handler) from the user's terminal."""
    script = (
        "from rti_rig.cli.app import quiet_library_logs\n"
        "quiet_library_logs()\n"
        "from distributed.protocol.pickle import loads\n"
        "try:\n"
        "    loads(b'crti_rig.app.usecases.no_such_module\\nBatchItem\\n.')\n"
        "except ModuleNotFoundError:\n"
        "    print('raised')\n"
    )
    done = subprocess.run(
        [sys.executable, "-c", script], capture_output=True, text=True, cwd=tmp_path, timeout=300
    )
    assert done.stdout.strip() == "raised", done.stderr
    assert "Traceback" not in done.stderr and "deserialize" not in done.stderr, done.stderr


def test_a_worker_that_cannot_say_which_rti_rig_it_runs_is_not_called_another_version(
    tmp_path: Path, monkeypatch
) -> None:
    """A worker whose check fails there (the error returned in its place) is refused, nothing
    sent, in words that do not claim a version it was not heard to run."""
    from distributed import LocalCluster

    from rti_rig.app.usecases import worker_code

    real = worker_code._identity_function

    def failing_on_workers():  # type: ignore[no-untyped-def]
        here = real()

        def rti_rig_identity(dask_worker=None):  # type: ignore[no-untyped-def]
            if dask_worker is not None:  # run on a worker, not here
                raise OSError("connection reset by peer")
            return here()

        return rti_rig_identity

    monkeypatch.setattr(worker_code, "_identity_function", failing_on_workers)
    session = make_session(tmp_path / "s", size=(24, 32))[0]
    out = tmp_path / "o"
    with LocalCluster(
        n_workers=1, threads_per_worker=1, processes=False, dashboard_address=None
    ) as cluster:
        address = cluster.scheduler_address
        r = runner.invoke(app, ["fit", str(session), "--out", str(out), "--scheduler", address])
    said = " ".join(r.output.split())
    assert r.exit_code == 2, said
    assert f"1 of the 1 workers of the Dask cluster at '{address}' could not be asked" in said
    assert "OSError: connection reset by peer" in said and "other rti-rig code" not in said
    assert "Traceback" not in r.output and not out.exists()
