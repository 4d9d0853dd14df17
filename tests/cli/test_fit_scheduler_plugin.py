"""`rti-rig fit --scheduler`: the worker plugin that tags the workers checked to run this
rti-rig, met again and failing, on real Dask schedulers and workers started here.

* A fit whose client was killed (SIGKILL) left its plugin on the scheduler for ever: every
  worker joining later ran it, each killed fit adding one. A later fit removes the plugins of
  clients the scheduler no longer has.
* A worker whose rti-rig source changed after it imported it (an editable install edited)
  runs the code it imported, yet was checked by its files now: taken for this code, it fitted
  with the old one. It is now refused, named, and told to restart.
* A check that failed on a worker still in the cluster (its tag refused) was told, after a
  minute, as "every checked worker has left"; it is now said at once, naming the worker and
  the error.
"""

from __future__ import annotations

import os
import shutil
import signal
import subprocess
import sys
import textwrap
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import pytest
from conftest import line_within
from test_fit_scheduler_late_worker import _other_rti_rig, _until, quick_looks
from typer.testing import CliRunner

import rti_rig
from rti_rig.app.usecases.worker_code import local_identity
from rti_rig.cli import app

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from fit_sessions import make_session

runner = CliRunner()
PREFIX = "rti-rig-code-check-"


def _tcp_cluster(n_workers: int) -> Any:
    """A scheduler (and ``n_workers`` in-process workers) other processes can reach."""
    from distributed import LocalCluster

    return LocalCluster(
        n_workers=n_workers,
        threads_per_worker=1,
        processes=False,
        protocol="tcp",
        host="127.0.0.1",
        dashboard_address=None,
    )


def _ours(scheduler: Any) -> list[str]:
    return [n for n in list(scheduler.worker_plugins) if n.startswith(PREFIX)]


@pytest.mark.slow
def test_the_plugin_of_a_fit_whose_client_was_killed_is_removed_by_the_next_fit(
    tmp_path: Path,
) -> None:
    session = make_session(tmp_path / "S", size=(24, 32))[0]
    holder = tmp_path / "holder.py"
    holder.write_text(
        textwrap.dedent(
            """
            import sys
            from rti_rig.app.usecases.fit_dask import scheduler_client

            with scheduler_client(sys.argv[1]) as cluster:
                print("registered", flush=True)
                sys.stdin.read()  # held until killed
            """
        ),
        encoding="utf-8",
    )
    with _tcp_cluster(1) as cluster:
        scheduler = cluster.scheduler
        before = set(scheduler.clients)
        held = subprocess.Popen(
            [sys.executable, str(holder), cluster.scheduler_address],
            stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL,
            env={**os.environ, "PYTHONPATH": str(Path.cwd())},
        )  # fmt: skip
        try:
            line = line_within(held, 300, "the holding client's 'registered'")
            assert line == b"registered\n"  # its plugin is registered
            (name,) = _ours(scheduler)
            (owner,) = set(scheduler.clients) - before
            held.send_signal(signal.SIGKILL)
            assert held.wait(timeout=120) == -signal.SIGKILL
        finally:
            held.kill()
            held.wait(timeout=120)
        _until(lambda: owner not in scheduler.clients, "the killed client stayed")
        assert _ours(scheduler) == [name]  # the killed fit could not remove it
        out = tmp_path / "FIT"
        r = runner.invoke(
            app,
            ["fit", str(session), "--out", str(out), "--no-qa", "--model", "ps",
             "--scheduler", cluster.scheduler_address],
        )  # fmt: skip
        said = " ".join(r.output.split())
        assert r.exit_code == 0, said
        assert (out / "fit.json").exists()
        assert _ours(scheduler) == []  # neither the stale plugin nor this fit's own


@pytest.mark.slow
def test_a_worker_whose_source_changed_after_it_imported_it_is_refused(tmp_path: Path) -> None:
    """The worker runs a copy of rti-rig that fits with other code; it imports it, then the
    copy is made the same as this rti-rig (as an edit, or a `git pull`, of an editable
    install): its files say this code, its memory holds the other."""
    session = make_session(tmp_path / "S", size=(24, 32))[0]
    where = _other_rti_rig(tmp_path / "other")
    fit_py = Path("rti_rig", "app", "usecases", "fit.py")
    mine = Path(rti_rig.__file__).parents[1]
    init = Path("rti_rig", "__init__.py")
    shutil.copyfile(mine / init, where / init)  # this version: only the fit differs
    out = tmp_path / "FIT"

    def made_this_rti_rig_again() -> None:  # the copy, after the worker imported it
        shutil.copyfile(mine / fit_py, where / fit_py)

    r, address, scheduler = _fit_on_a_worker_of(where, session, out, made_this_rti_rig_again)
    said = " ".join(r.output.split())
    assert r.exit_code == 2, said
    assert f"1 of the 1 workers of the Dask cluster at '{scheduler}'" in said
    assert address in said, said
    assert (
        f"(rti-rig {rti_rig.__version__}, code {local_identity().fingerprint}, but its rti-rig "
        "source changed after this process imported it (rti_rig/app/usecases/fit.py): it runs "
        "the code it imported, not the files there now; restart it)"
    ) in said, said
    assert "restart it" in said, said
    assert not out.exists(), said  # nothing was sent


@pytest.mark.slow
def test_a_check_that_fails_on_a_worker_still_there_names_it_and_the_error(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    quick_looks(monkeypatch, grace_s=1.0)  # without the check, said after this
    session = make_session(tmp_path / "S", size=(24, 32))[0]
    out = tmp_path / "FIT"
    with _tcp_cluster(1) as cluster:
        (worker,) = cluster.workers.values()

        async def refused(**resources: float) -> None:
            raise OSError("the scheduler refused the resource")

        worker.set_resources = refused  # the tag cannot be given there
        address = cluster.scheduler_address
        r = runner.invoke(
            app,
            ["fit", str(session), "--out", str(out), "--no-qa", "--model", "ps",
             "--scheduler", address],
        )  # fmt: skip
        still = set(cluster.scheduler.workers)
    said = " ".join(r.output.split())
    assert r.exit_code == 2, said
    assert still == {worker.address}
    assert (
        f"the rti-rig check could not tag any of the 1 worker(s) of the Dask cluster at '{address}'"
    ) in said, said
    assert f"{worker.address} (OSError: the scheduler refused the resource)" in said, said
    assert "have all left it" not in said, said
    assert "restart them" in said, said
    assert "Traceback" not in r.output
    assert not out.exists()


def _this_rti_rig(where: Path) -> Path:
    """``where``, holding a copy of this very rti-rig (no ``__pycache__``) as a worker's
    PYTHONPATH: its files can be dated or written again without touching the tests' own."""
    shutil.copytree(
        Path(rti_rig.__file__).parent,
        where / "rti_rig",
        ignore=shutil.ignore_patterns("__pycache__"),
    )
    return where


@contextmanager
def _one_worker_of(where: Path) -> Iterator[Any]:
    """A scheduler (the ``LocalCluster``) of one ``dask worker`` process importing rti-rig from
    ``where``, once it joined; the worker is killed and reaped whatever happens."""
    worker = None
    try:
        with _tcp_cluster(0) as cluster:
            worker = subprocess.Popen(
                [sys.executable, "-m", "distributed.cli.dask_worker", cluster.scheduler_address,
                 "--nthreads", "1", "--no-nanny", "--no-dashboard"],
                cwd=where.parent, env={**os.environ, "PYTHONPATH": str(where)},
                stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
            )  # fmt: skip
            _until(lambda: len(cluster.scheduler.workers) == 1, "the worker never joined")
            yield cluster
    finally:
        if worker is not None:  # killed: a SIGTERM'd dask worker may take minutes to close
            worker.kill()
            worker.wait(timeout=120)


def _fit(session: Path, out: Path, scheduler: str) -> Any:
    return runner.invoke(
        app,
        ["fit", str(session), "--out", str(out), "--no-qa", "--model", "ps",
         "--scheduler", scheduler],
    )  # fmt: skip


def _fit_on_a_worker_of(where: Path, session: Path, out: Path, then: Any = None) -> Any:
    """Fit ``session`` into ``out`` on :func:`_one_worker_of` ``where``, the worker having
    imported rti-rig's batch fit first (as for an earlier fit's tasks), then ``then()`` run.
    Returns the CLI's result, the worker's address and the scheduler's."""
    from distributed import Client

    with _one_worker_of(where) as cluster:
        with Client(cluster.scheduler_address, set_as_default=False) as client:
            (loaded,) = client.run(exec, "import rti_rig.app.usecases.fit_batch").values()
            assert loaded is None
        if then is not None:
            then()
        r = _fit(session, out, cluster.scheduler_address)
        (address,) = cluster.scheduler.workers
        return r, address, cluster.scheduler_address


@pytest.mark.slow
def test_a_worker_holding_an_rti_rig_that_kept_no_import_time_is_refused(tmp_path: Path) -> None:
    """A worker imported an rti-rig of this version number from before the import time was
    kept (for an earlier fit's tasks); its files were then replaced by this rti-rig with their
    dates kept (`cp -a`, `rsync -a`). Its files are this code and none is dated after the
    import, yet it runs the other: it was tagged and fitted with it."""
    session = make_session(tmp_path / "S", size=(24, 32))[0]
    where = _other_rti_rig(tmp_path / "other")
    mine = Path(rti_rig.__file__).parents[1]
    init, fit_py = Path("rti_rig", "__init__.py"), Path("rti_rig", "app", "usecases", "fit.py")
    text = (where / init).read_text(encoding="utf-8")
    assert text.count("IMPORTED_AT_NS = ") == 1
    older = text.replace("IMPORTED_AT_NS = ", "_WAS = ").replace(
        '"0.0.9-other"', f'"{rti_rig.__version__}"'
    )  # the same version number: an earlier commit of it
    (where / init).write_text(older, encoding="utf-8")

    def replaced_dates_kept() -> None:
        for name in (init, fit_py):
            shutil.copy2(mine / name, where / name)

    out = tmp_path / "FIT"
    r, address, scheduler = _fit_on_a_worker_of(where, session, out, replaced_dates_kept)
    said = " ".join(r.output.split())
    assert r.exit_code == 2, said
    assert f"1 of the 1 workers of the Dask cluster at '{scheduler}'" in said, said
    assert (
        f"{address} (rti-rig {rti_rig.__version__}, code {local_identity().fingerprint}, but it "
        "imported rti-rig before this check, from an rti-rig that kept no record of when: it "
        "may run other code than the files there now; restart it)"
    ) in said, said
    assert not out.exists(), said  # nothing was sent


@pytest.mark.slow
def test_a_worker_whose_source_is_dated_after_the_clock_is_told_to_date_it_not_only_restart(
    tmp_path: Path,
) -> None:
    """A worker's copy of this very rti-rig with one file dated a day ahead (a file server's
    clock ahead, a copy that kept a future date): it was said to have changed since the
    worker imported it and to restart, and a restart was refused the same way until the clock
    passed that date. Whether it changed cannot be told; the file is named to be dated now."""
    session = make_session(tmp_path / "S", size=(24, 32))[0]
    where = _this_rti_rig(tmp_path / "same")
    ahead = (where / "rti_rig" / "app" / "usecases" / "fit.py").resolve()
    day = 86_400 * 10**9
    os.utime(ahead, ns=(time.time_ns() + day, time.time_ns() + day))
    out = tmp_path / "FIT"
    r, address, scheduler = _fit_on_a_worker_of(where, session, out)
    said = " ".join(r.output.split())
    assert r.exit_code == 2, said
    assert f"1 of the 1 workers of the Dask cluster at '{scheduler}'" in said, said
    assert (
        f"{address} (rti-rig {rti_rig.__version__}, code {local_identity().fingerprint}, but its "
        f"rti-rig source file(s) {ahead} are dated after this computer's clock, so whether they "
        "changed since this process imported rti-rig cannot be told: give them the present "
        "date (`touch FILE`; set the clocks right if a file server's runs ahead), then restart it)"
    ) in said, said
    assert "changed after this process imported it" not in said, said
    assert not out.exists(), said  # nothing was sent


@pytest.mark.slow
def test_a_worker_checked_once_is_judged_by_its_files_contents_not_their_dates(
    tmp_path: Path,
) -> None:
    """A worker that imported this rti-rig for its first check, one of its files then written
    again unchanged (an editor's save, `git stash && git stash pop`, the same wheel installed
    again): it runs this code still, yet was called changed since its import and refused. A
    file edited, its date kept (`cp -a`, `rsync -a`), is still refused, and named."""
    session = make_session(tmp_path / "S", size=(24, 32))[0]
    where = _this_rti_rig(tmp_path / "same")
    fit_py = where / "rti_rig" / "app" / "usecases" / "fit.py"
    with _one_worker_of(where) as cluster:
        first = _fit(session, tmp_path / "FIT1", cluster.scheduler_address)
        assert first.exit_code == 0, first.output
        dated = fit_py.stat()
        os.utime(fit_py, ns=(dated.st_atime_ns, time.time_ns()))  # written again, unchanged
        assert fit_py.stat().st_mtime_ns > dated.st_mtime_ns
        again = _fit(session, tmp_path / "FIT2", cluster.scheduler_address)
        assert again.exit_code == 0, " ".join(again.output.split())
        text = fit_py.read_text(encoding="utf-8")
        fit_py.write_text(text + "\n# edited\n", encoding="utf-8")
        os.utime(fit_py, ns=(dated.st_atime_ns, dated.st_mtime_ns))  # its date kept
        edited = _fit(session, tmp_path / "FIT3", cluster.scheduler_address)
        (address,) = cluster.scheduler.workers
    said = " ".join(edited.output.split())
    assert edited.exit_code == 2, said
    assert (
        f"{address} (rti-rig {rti_rig.__version__}, code {local_identity().fingerprint}, but its "
        "rti-rig source changed after this process imported it (rti_rig/app/usecases/fit.py): "
        "it runs the code it imported, not the files there now; restart it)"
    ) in said, said
    assert not (tmp_path / "FIT3").exists(), said
