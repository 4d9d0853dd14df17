"""A session that changes while its batch runs is judged at its turn, and a fit made while
its session changed under it says so.

A batch judged every session once, when it began: a session whose capture was resumed while
the batch fitted another was reported "skipped (finished earlier)", its fit of 5 images kept
beside a session of 8; and a session whose image was replaced while its own fit ran was said
"done" as if the fit matched it. The change is made at the point where the batch starts a
session's fit (``fit_batch.run_fit``), as a capture running beside the batch would make it.
"""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path

import pytest
from conftest import SMALL_DOME, interrupted, said, write_config
from typer.testing import CliRunner

from rti_rig.app.usecases import fit_batch
from rti_rig.cli import app

runner = CliRunner()


def batch(*sources: Path, out: Path):  # type: ignore[no-untyped-def]
    """``rti-rig fit S... --out OUT`` as a user runs it (PS: any light count from 3 fits)."""
    args = ["fit", *map(str, sources), "--out", str(out), "--model", "ps", "--no-qa"]
    return runner.invoke(app, args)


def read(fit: Path) -> str:
    """What a fit folder's fit.json says it was made from."""
    return str(json.loads((fit / "fit.json").read_text(encoding="utf-8"))["read"])


def on_fit(
    monkeypatch: pytest.MonkeyPatch, name: str, before: Callable[[], None], after: bool = False
) -> None:
    """Run ``before`` when the batch starts fitting session ``name`` (``after``: once that
    fit has read and written everything, before the batch puts it in place)."""
    real = fit_batch.run_fit

    def fit(req, bands=None):  # type: ignore[no-untyped-def]
        if req.source.name == name and not after:
            before()
        result = real(req, bands)
        if req.source.name == name and after:
            before()
        return result

    monkeypatch.setattr(fit_batch, "run_fit", fit)


def sessions(tmp_path: Path) -> tuple[Path, Path, Path]:
    """S (5 of 8 images, resumable) and T (6 images), both fitted by a batch into FB."""
    cfg = write_config(tmp_path, SMALL_DOME)
    s, t, fb = tmp_path / "S", tmp_path / "T", tmp_path / "FB"
    interrupted(cfg, s, after_step=4, lights=8)
    r = runner.invoke(app, ["run", str(cfg), "--out", str(t), "--lights", "6"])
    assert r.exit_code == 0, r.output
    r = batch(s, t, out=fb)
    assert r.exit_code == 0 and said(r).count(": done") == 2, r.output
    return s, t, fb


@pytest.mark.e2e
@pytest.mark.slow
def test_a_session_resumed_while_the_batch_fits_another_is_refitted(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    import shutil

    s, t, fb = sessions(tmp_path)
    shutil.rmtree(fb / "T")  # T is fitted again: S's capture is resumed meanwhile

    def resume() -> None:
        r = runner.invoke(app, ["run", "--resume", str(s)])
        assert r.exit_code == 0, r.output

    on_fit(monkeypatch, "T", resume)
    r = batch(t, s, out=fb)
    text = said(r)
    assert r.exit_code == 0, r.output
    assert f"{s}: refitted (its session changed since the earlier fit: 5 → 8 images)" in text
    assert "skipped" not in text, r.output
    assert read(fb / "S").startswith("8 images")
    monkeypatch.undo()
    r = batch(t, s, out=fb)
    assert said(r).count("skipped (finished earlier)") == 2, r.output


@pytest.mark.e2e
@pytest.mark.slow
def test_an_image_replaced_while_its_fit_runs_is_said_and_refitted_next(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    s, t, fb = sessions(tmp_path)
    r = runner.invoke(app, ["run", "--resume", str(s)])  # S outgrows its fit: refitted
    assert r.exit_code == 0, r.output
    tif = s / "linear" / "image_003.tif"

    def replace() -> None:  # after the fit read it: the fit is of the image before
        data = bytearray(tif.read_bytes())
        data[-100] ^= 0xFF
        tif.write_bytes(bytes(data))

    on_fit(monkeypatch, "S", replace, after=True)
    r = batch(s, t, out=fb)
    text = said(r)
    assert r.exit_code == 1, r.output  # its fit is in place, but not of the session now
    assert (
        f"{s}: refitted (its session changed since the earlier fit: 5 → 8 images); but its "
        "session changed while it was being fitted (1 of 8 images changed on disk since their "
        "capture (same name, not the checksum their journal took): image_003)"
    ) in text, r.output
    assert f"{t}: skipped (finished earlier)" in text, r.output
    monkeypatch.undo()
    r = batch(s, t, out=fb)  # the fit it has was not made from the image there now
    text = said(r)
    assert f"{s}: refitted (its session changed since the earlier fit: 1 of 8 images" in text
    assert "while it was being fitted" not in text, r.output
    r = batch(s, t, out=fb)
    assert said(r).count("skipped (finished earlier)") == 2, r.output


@pytest.mark.e2e
@pytest.mark.slow
def test_a_session_resumed_while_its_own_fit_runs_exits_1_until_refitted(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The batch's exit code says a fit is stale (its session changed under it): 1, between
    0 (every fit matches its session) and 2 (a session failed). It had exited 0, a script
    chaining batches told only by the words on the session's line."""
    import shutil

    s, t, fb = sessions(tmp_path)
    shutil.rmtree(fb / "S")  # S is fitted again, and its capture resumed as it is

    def resume() -> None:
        r = runner.invoke(app, ["run", "--resume", str(s)])
        assert r.exit_code == 0, r.output

    on_fit(monkeypatch, "S", resume, after=True)
    r = batch(s, t, out=fb)
    text = said(r)
    assert r.exit_code == 1, r.output
    assert f"{s}: done; but its session changed while it was being fitted (5 → 8 images)" in text
    assert f"{t}: skipped (finished earlier)" in text, r.output
    assert "1 of 2 fit(s) are of their session as it was read" in text, r.output
    assert "run the same command again" in text and "Traceback" not in text, r.output
    assert read(fb / "S").startswith("5 images")
    monkeypatch.undo()
    r = batch(s, t, out=fb)  # run again, as said: refitted from the session there now
    text = said(r)
    assert r.exit_code == 0, r.output
    assert f"{s}: refitted (its session changed since the earlier fit: 5 → 8 images)" in text
    assert read(fb / "S").startswith("8 images")


@pytest.mark.e2e
@pytest.mark.slow
def test_a_cluster_batch_judges_a_planned_skip_again_at_its_turn(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """On a cluster, a session found standing is not sent; it had been reported in the words
    of the plan made when the batch began."""
    import shutil

    from distributed import LocalCluster

    from rti_rig.app.usecases import fit_dask

    s, t, fb = sessions(tmp_path)
    shutil.rmtree(fb / "T")
    real = fit_dask.fit_one

    def resumes_s_meanwhile(source, root, template, bands=None):  # type: ignore[no-untyped-def]
        if source.name == "T":
            r = runner.invoke(app, ["run", "--resume", str(s)])
            assert r.exit_code == 0, r.output
        return real(source, root, template, bands)

    monkeypatch.setattr(fit_dask, "fit_one", resumes_s_meanwhile)
    with LocalCluster(
        n_workers=1, threads_per_worker=1, processes=False, dashboard_address=None
    ) as cluster:
        args = ["fit", str(t), str(s), "--out", str(fb), "--model", "ps", "--no-qa"]
        r = runner.invoke(app, [*args, "--scheduler", cluster.scheduler_address])
    text = said(r)
    assert r.exit_code == 0, r.output
    assert f"{s}: refitted (its session changed since the earlier fit: 5 → 8 images)" in text
    assert read(fb / "S").startswith("8 images")
