"""A run killed between a step's record file and its journal line: the step is committed (its
record file proves it, a resume keeps it), but the run had not yet rewritten ``lights.lp``.

Before, ``export-lp`` listed one light more than ``lights.lp``, ``fit`` fitted one image fewer
than the session holds, and relight and RTIBuilder (which read ``lights.lp``) left it out. Now
the session's own ``lights.lp`` is completed when the session is next opened by ``fit``,
``export-lp`` or ``--resume``, so the images, the ``.lp`` and the fit agree.
"""

from __future__ import annotations

import hashlib
import json
import signal
from pathlib import Path

import pytest
from conftest import CONFIGS
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.core.lp_format import read_lp
from rti_rig.testing.kill_hooks import popen_session

runner = CliRunner()
LIGHTS = 8


def said(result) -> str:  # type: ignore[no-untyped-def]
    return " ".join(result.output.split())


def _killed_after_fourth_record(tmp_path: Path) -> Path:
    """A shipped-config dry run SIGKILLed right after image_004's record file was written."""
    out = tmp_path / "s"
    proc = popen_session("after_record", 3, CONFIGS / "simulated_dome.toml", out, LIGHTS)
    _, stderr = proc.communicate(timeout=300)
    assert proc.returncode == -signal.SIGKILL, stderr.decode()
    assert len((out / "journal.jsonl").read_bytes().splitlines()) == 3
    assert [e.name for e in read_lp(out / "lights.lp")] == [f"image_00{i}.jpg" for i in (1, 2, 3)]
    return out


def _listed(lp: Path) -> list[str]:
    return [e.name for e in read_lp(lp)]


FOUR = [f"image_00{i}.jpg" for i in (1, 2, 3, 4)]


@pytest.mark.slow
@pytest.mark.e2e
def test_export_lp_fit_and_resume_agree_with_lights_lp(tmp_path: Path) -> None:
    out = _killed_after_fourth_record(tmp_path)
    kept = hashlib.sha256((out / "image_004.jpg").read_bytes()).hexdigest()

    exported = tmp_path / "x.lp"
    r = runner.invoke(app, ["export-lp", str(out), "--out", str(exported)])
    assert r.exit_code == 0, r.output
    assert "4 lights" in said(r), said(r)
    assert "lights.lp now lists image_004 too" in said(r), said(r)
    # the export and the session's own lights.lp list the same images, with the same lights
    assert exported.read_bytes() == (out / "lights.lp").read_bytes()
    assert _listed(out / "lights.lp") == FOUR
    # nothing captured moved, and the journal is left to the resume
    assert hashlib.sha256((out / "image_004.jpg").read_bytes()).hexdigest() == kept
    assert len((out / "journal.jsonl").read_bytes().splitlines()) == 3

    r = runner.invoke(app, ["fit", str(out), "--out", str(tmp_path / "fit"), "--model", "ps"])
    assert r.exit_code == 0, r.output
    qa = json.loads((tmp_path / "fit" / "qa.json").read_text())
    assert [c["name"] for c in qa["images"]] == [Path(n).stem for n in FOUR], qa["images"]
    verdict = " ".join(qa["verdict"].split())
    assert "not yet in lights.lp" not in verdict and "does not list" not in verdict, verdict
    assert "the run stopped after image_004's record file, before its journal line" in verdict

    r = runner.invoke(app, ["run", "--resume", str(out), "--no-verdict"])
    assert r.exit_code == 0, r.output
    assert "4 of 8 images verified" in said(r), said(r)
    assert _listed(out / "lights.lp") == [f"image_{i:03d}.jpg" for i in range(1, LIGHTS + 1)]


@pytest.mark.slow
@pytest.mark.e2e
def test_fit_first_completes_lights_lp_and_fits_every_image_the_session_holds(
    tmp_path: Path,
) -> None:
    out = _killed_after_fourth_record(tmp_path)
    r = runner.invoke(app, ["fit", str(out), "--out", str(tmp_path / "fit"), "--model", "ps"])
    assert r.exit_code == 0, r.output
    assert "lights.lp now lists image_004 too" in said(r), said(r)
    assert _listed(out / "lights.lp") == FOUR
    qa = json.loads((tmp_path / "fit" / "qa.json").read_text())
    assert [c["name"] for c in qa["images"]] == [Path(n).stem for n in FOUR], qa["images"]
    exported = tmp_path / "x.lp"
    r = runner.invoke(app, ["export-lp", str(out), "--out", str(exported)])
    assert r.exit_code == 0, r.output
    assert "now lists" not in said(r), said(r)  # already whole: nothing rewritten again
    assert exported.read_bytes() == (out / "lights.lp").read_bytes()


@pytest.mark.slow
@pytest.mark.e2e
def test_a_lights_lp_edited_by_hand_is_left_as_it_is(tmp_path: Path) -> None:
    out = _killed_after_fourth_record(tmp_path)
    lp = out / "lights.lp"
    edited = lp.read_bytes().replace(b"image_002.jpg", b"image_002.jpg ", 1)
    lp.write_bytes(edited)
    r = runner.invoke(app, ["export-lp", str(out), "--out", str(tmp_path / "x.lp")])
    assert r.exit_code == 0, r.output
    assert "now lists" not in said(r), said(r)
    assert lp.read_bytes() == edited


@pytest.mark.slow
@pytest.mark.e2e
def test_a_resume_that_journals_the_step_before_the_lock_is_not_overwritten(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The decision to complete lights.lp is taken again under the lock from the journal as it
    is then: a resume that ran between the first look and the lock (here: journaled image_004
    and wrote its own lights.lp) keeps what it wrote. Before, the journal scan taken before
    the lock was reused and lights.lp was rewritten from it."""
    import rti_rig.runtime.session as session_mod

    out = _killed_after_fourth_record(tmp_path)
    lp = out / "lights.lp"
    resumed = lp.read_bytes()  # the listing the resume wrote, not yet naming image_004
    record = (out / "records" / "image_004.json").read_text().strip()
    real_lock = session_mod.lock_session

    def resume_then_lock(root: Path) -> None:
        # what a resume run in between leaves: image_004's journal line, and its lights.lp
        with (out / "journal.jsonl").open("a") as f:
            f.write(json.dumps(json.loads(record)) + "\n")
        lp.write_bytes(resumed)
        real_lock(root)

    monkeypatch.setattr(session_mod, "lock_session", resume_then_lock)
    r = runner.invoke(app, ["export-lp", str(out), "--out", str(tmp_path / "x.lp")])
    assert r.exit_code == 0, r.output
    assert "now lists" not in said(r), said(r)
    assert lp.read_bytes() == resumed
    # the line appended is a journal line as the run writes it: read whole, nothing mended
    scan = session_mod.scan_journal(out, session_mod.image_names(LIGHTS))
    assert len(scan.records) == 4 and not scan.mended and not scan.rejected, scan
