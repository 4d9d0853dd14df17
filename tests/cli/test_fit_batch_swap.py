"""A batch killed while it swaps a refit in for the earlier fit never leaves a session fitless.

The swap is two renames (the earlier fit aside, the new one in). A batch killed between them
had left neither in the session's output folder, and the next run removed both as partial
folders: a session whose refit then failed (an image lost since) had no fit at all. The next
run now finishes the swap (the new fit is complete) or undoes it, and says which.
"""

from __future__ import annotations

import json
import signal
from pathlib import Path

import numpy as np
import pytest
from conftest import SMALL_DOME, said, write_config
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.testing.kill_hooks import popen_argv

runner = CliRunner()


def batch(*sources: Path, out: Path):  # type: ignore[no-untyped-def]
    """``rti-rig fit S... --out OUT`` as a user runs it (PS: any light count from 3 fits)."""
    args = ["fit", *map(str, sources), "--out", str(out), "--model", "ps", "--no-qa"]
    return runner.invoke(app, args)


def lights_of_lp(session: Path) -> list[list[float]]:
    """The lights of a session's lights.lp, in its order."""
    rows = (session / "lights.lp").read_text(encoding="utf-8").splitlines()[1:]
    return [[float(v) for v in row.split()[1:]] for row in rows]


def move_a_light(session: Path) -> None:
    """Move the third light of the session's lights.lp a little (a recalibrated dome)."""
    head, *rows = (session / "lights.lp").read_text(encoding="utf-8").splitlines()
    name, x, y, _ = rows[2].split()
    x2, y2 = float(x) * 0.98, float(y) * 0.98
    z2 = (1.0 - x2 * x2 - y2 * y2) ** 0.5
    rows[2] = f"{name} {x2:.6f} {y2:.6f} {z2:.6f}"
    (session / "lights.lp").write_text("\n".join([head, *rows]) + "\n", encoding="utf-8")


def killed_in_the_swap(tmp_path: Path) -> tuple[Path, Path, Path]:
    """Sessions S and T fitted by a batch into FB, a light of S moved, then a batch SIGKILLed
    between the two renames of S's refit: (S, T, FB)."""
    cfg = write_config(tmp_path, SMALL_DOME)
    s, t, fb = tmp_path / "S", tmp_path / "T", tmp_path / "FB"
    for session in (s, t):
        r = runner.invoke(app, ["run", str(cfg), "--out", str(session), "--lights", "6"])
        assert r.exit_code == 0, r.output
    r = batch(s, t, out=fb)
    assert r.exit_code == 0 and said(r).count(": done") == 2, r.output
    move_a_light(s)
    args = ["fit", str(s), str(t), "--out", str(fb), "--model", "ps", "--no-qa"]
    proc = popen_argv("refit_swap", 0, args)
    _, err = proc.communicate(timeout=600)
    assert proc.returncode == -signal.SIGKILL, err.decode()
    assert not (fb / "S").exists()  # the moment the kill hook chose: neither fit in place
    return s, t, fb


def lights_of(fit: Path) -> list[list[float]]:
    """The lights a fit folder's fit.json records it was fitted with."""
    return json.loads((fit / "fit.json").read_text(encoding="utf-8"))["inputs"]["lights"]


@pytest.mark.e2e
@pytest.mark.slow
def test_a_swap_killed_midway_is_finished_by_the_next_batch(tmp_path: Path) -> None:
    s, t, fb = killed_in_the_swap(tmp_path)
    r = batch(s, t, out=fb)
    text = said(r)
    assert r.exit_code == 0, r.output
    assert "the new fit, complete, was put in place" in text, r.output
    assert f"{s}: skipped (finished earlier)" in text, r.output  # the new fit is current
    np.testing.assert_allclose(lights_of(fb / "S"), lights_of_lp(s), atol=1e-6)
    assert sorted(p.name for p in fb.iterdir()) == ["S", "T"], list(fb.iterdir())


@pytest.mark.e2e
@pytest.mark.slow
def test_a_session_whose_refit_fails_after_the_kill_keeps_a_fit(tmp_path: Path) -> None:
    s, t, fb = killed_in_the_swap(tmp_path)
    moved = lights_of_lp(s)
    (s / "linear" / "image_004.tif").unlink()  # the session can no longer be fitted
    (s / "image_004.jpg").unlink()
    r = batch(s, t, out=fb)
    text = said(r)
    assert r.exit_code == 2, r.output
    assert "the new fit, complete, was put in place" in text, r.output
    assert f"(the earlier fit in {fb / 'S'} is kept)" in text, r.output
    np.testing.assert_allclose(lights_of(fb / "S"), moved, atol=1e-6)


@pytest.mark.e2e
@pytest.mark.slow
def test_an_incomplete_new_fit_is_undone_and_the_earlier_fit_put_back(tmp_path: Path) -> None:
    s, t, fb = killed_in_the_swap(tmp_path)
    (new,) = [p for p in fb.iterdir() if p.name.endswith(".partial")]
    (new / "fit.json").unlink()  # as if the new fit had not been finished
    r = batch(s, t, out=fb)
    text = said(r)
    assert r.exit_code == 0, r.output
    assert "the earlier fit was put back" in text, r.output
    assert f"{s}: refitted (its session changed since the earlier fit: 1 of 6 lights" in text
    assert sorted(p.name for p in fb.iterdir()) == ["S", "T"], list(fb.iterdir())


@pytest.mark.e2e
@pytest.mark.slow
def test_an_outgrown_fit_is_not_put_back_for_a_new_fit_the_user_removed(
    tmp_path: Path,
) -> None:
    """Killed after the swap's second rename (the new fit in place, the earlier not yet
    removed), then the new fit deleted by the user: the outgrown fit had been put back,
    "interrupted before its new fit was complete"."""
    import shutil

    s, t, fb = killed_in_the_swap(tmp_path)
    (new,) = [p for p in fb.iterdir() if p.name.endswith(".partial")]
    new.rename(fb / "S")  # the rename the kill came before
    shutil.rmtree(fb / "S")  # the user deletes the new fit
    r = batch(s, t, out=fb)
    text = said(r)
    assert r.exit_code == 0, r.output
    assert "put back" not in text and "put in place" not in text, r.output
    assert f"{s}: done" in text, r.output  # fitted afresh, from the session as it is
    np.testing.assert_allclose(lights_of(fb / "S"), lights_of_lp(s), atol=1e-6)
    assert sorted(p.name for p in fb.iterdir()) == ["S", "T"], list(fb.iterdir())
