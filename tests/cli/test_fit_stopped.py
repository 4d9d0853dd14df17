"""A stopped ``rti-rig fit`` (SIGTERM or Ctrl-C) cleans up and says so, through the front door.

Found by an audit: a SIGTERM (``timeout``, a scheduler) ended ``fit`` at once, silently, exit
143, leaving half-written outputs (``fit.ptm.part``, a normal map without its QA) in --out; the
same command run again was refused as "not empty". The stop is raised deterministically here:
the signal is sent to this process from inside the fit, after its first outputs are written.
"""

from __future__ import annotations

import os
import shutil
import signal
from pathlib import Path

import pytest
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.reconstruct import exporters

REPO = Path(__file__).resolve().parents[2]
ACQ = REPO / "tests" / "data" / "neuralrti_replay" / "dirs.lp"
runner = CliRunner()


def said(result) -> str:  # type: ignore[no-untyped-def]
    return " ".join(result.output.split())


class Unhandled(Exception):
    """Raised by this test's own SIGTERM handler: the command installed none (without one, the
    signal sent below would end the test process itself)."""


@pytest.fixture(autouse=True)
def _sigterm_fails_the_test_not_the_run():  # type: ignore[no-untyped-def]
    def unhandled(signum, frame):  # type: ignore[no-untyped-def]
        raise Unhandled("SIGTERM reached the test's handler: fit installed none")

    previous = signal.signal(signal.SIGTERM, unhandled)
    yield unhandled
    signal.signal(signal.SIGTERM, previous)


def _stop_at_the_normal_map(monkeypatch: pytest.MonkeyPatch, how: str) -> None:
    """The fit is stopped as it writes its normal map (fit.ptm and fit.rti written by then)."""
    real = exporters.write_normal_map

    def stopped(*args, **kwargs):  # type: ignore[no-untyped-def]
        assert any(p.name == "fit.ptm" for p in Path(args[0]).parent.iterdir())
        if how == "SIGTERM":
            os.kill(os.getpid(), signal.SIGTERM)  # its handler raises at the next bytecode
        else:
            raise KeyboardInterrupt
        return real(*args, **kwargs)

    monkeypatch.setattr(exporters, "write_normal_map", stopped)


@pytest.mark.parametrize(("how", "code"), [("SIGTERM", 143), ("Ctrl-C", 130)])
def test_a_stopped_fit_leaves_its_out_folder_as_it_was_and_the_rerun_works(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, how: str, code: int
) -> None:
    out = tmp_path / "fit"
    before = signal.getsignal(signal.SIGTERM)  # the fixture's
    with monkeypatch.context() as m:
        _stop_at_the_normal_map(m, how)
        r = runner.invoke(app, ["fit", str(ACQ), "--out", str(out), "--no-qa"])
    assert r.exit_code == code, r.output
    assert f"Stopped ({how}) before the fit finished: nothing it wrote was left in" in said(r), (
        r.output
    )
    assert not out.exists()  # created by this fit: removed with what it held
    assert signal.getsignal(signal.SIGTERM) == before  # the handler is the command's only
    again = runner.invoke(app, ["fit", str(ACQ), "--out", str(out), "--no-qa"])
    assert again.exit_code == 0, again.output
    assert (out / "fit.ptm").is_file() and (out / "normals.png").is_file()


def test_a_stopped_batch_keeps_the_sessions_it_finished(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    a, b = tmp_path / "a", tmp_path / "b"
    for folder in (a, b):
        shutil.copytree(ACQ.parent, folder)
    calls: list[int] = []
    real = exporters.write_normal_map

    def second_stopped(*args, **kwargs):  # type: ignore[no-untyped-def]
        calls.append(1)
        if len(calls) == 2:
            os.kill(os.getpid(), signal.SIGTERM)
        return real(*args, **kwargs)

    monkeypatch.setattr(exporters, "write_normal_map", second_stopped)
    root = tmp_path / "fits"
    r = runner.invoke(
        app, ["fit", str(a / "dirs.lp"), str(b / "dirs.lp"), "--out", str(root), "--no-qa"]
    )
    assert r.exit_code == 143, r.output
    assert "Stopped (SIGTERM): the sessions finished are kept in" in said(r)
    assert sorted(p.name for p in root.iterdir()) == ["a-dirs"]  # no partial folder left


def test_a_stopped_cluster_batch_does_not_claim_its_running_sessions_discarded(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """On a Dask cluster a session already running on a worker is not stopped by the client's
    SIGTERM (Dask does not interrupt a running task): it goes on and is renamed into place.
    "The one being fitted was discarded" had been said, and the session appeared later."""
    import time

    from distributed import LocalCluster

    from rti_rig.app.usecases import fit_dask

    a = tmp_path / "a"
    shutil.copytree(ACQ.parent, a)
    real = fit_dask.fit_one

    def stopped_then_fitted(*args, **kwargs):  # type: ignore[no-untyped-def]
        os.kill(os.getpid(), signal.SIGTERM)  # the client (this process's main thread) stops
        return real(*args, **kwargs)

    monkeypatch.setattr(fit_dask, "fit_one", stopped_then_fitted)
    root = tmp_path / "fits"
    with LocalCluster(
        n_workers=1, threads_per_worker=1, processes=False, dashboard_address=None
    ) as cluster:
        args = ["fit", str(a / "dirs.lp"), str(ACQ), "--out", str(root), "--no-qa"]
        r = runner.invoke(app, [*args, "--scheduler", cluster.scheduler_address])
        assert r.exit_code == 143, r.output
        assert "discarded" not in said(r), r.output
        assert "already running on the Dask workers cannot be stopped from here" in said(r)

        def landed() -> list[Path]:  # the session the worker was running (either one)
            return [p for p in root.iterdir() if not p.name.startswith(".")]

        for _ in range(2400):  # what is said: the running session goes on and lands
            if landed():
                break
            time.sleep(0.25)
        assert [(p / "fit.ptm").is_file() for p in landed()] == [True]
