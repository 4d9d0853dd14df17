"""A run stopped once every image is in (a SIGTERM held while the last image was committed,
or during an arm's final park) says every image is in, that fit works on them, and that the
resume records the session's end without shooting anything again.

Why: it said "Continue with: rti-rig run --resume S" as if images were missing; then "the
session is complete, nothing is left to resume", while its manifest recorded an emergency stop
(and, of an adaptive session, no outcome): `rti-rig fit` called it "not finished … continue it
with rti-rig run --resume". A stop with images missing still says the resume.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest
from conftest import CONFIGS, REPO, shipped_variant
from sigterm_support import signal_at_commit

#: ``rti-rig run`` in a process of its own that sends itself SIGTERM as image ``AT`` (0-based)
#: is committed: the commit holds the signal, which stops the run right after it
SCRIPT = signal_at_commit("SIGTERM")
SMALL = (("width = 512", "width = 96"), ("height = 512", "height = 96"))


def _python(*argv: str) -> tuple[int, str]:
    """``python argv…`` in a process of its own (a signal it sends itself stops it alone), on
    this checkout, 300 columns wide: its exit code and its output unwrapped (one line)."""
    proc = subprocess.run(
        [sys.executable, *argv],
        capture_output=True,
        text=True,
        timeout=300,
        env={**os.environ, "PYTHONPATH": str(REPO), "COLUMNS": "300"},
    )
    return proc.returncode, " ".join((proc.stdout + proc.stderr).split())


def _run_sigterm_at(tmp_path: Path, at: int, *extra: str) -> tuple[int, str, Path]:
    """``run --lights 6`` (and ``extra``) on the shipped simulated dome at 96 px, SIGTERM as
    image ``at`` is committed: what is in, what is said and what the resume records are the
    images' count and the session's record, not their size."""
    out = tmp_path / "s"
    config = shipped_variant(tmp_path, "simulated_dome.toml", SMALL)
    args = ["run", str(config), "--out", str(out), "--lights", "6"]
    return (*_python("-c", SCRIPT, str(at), *args, *extra, "--no-verdict"), out)


@pytest.mark.skipif(sys.platform == "win32", reason="signals tested on POSIX")
def test_a_sigterm_as_the_last_image_is_committed_says_all_in_fit_and_resume(
    tmp_path: Path,
) -> None:
    code, said, out = _run_sigterm_at(tmp_path, 5)
    assert code == 143, said
    assert "Emergency stop (SIGTERM)" in said and "Traceback" not in said, said
    assert f"6 image(s) kept in {out}, listed in lights.lp: every image is in" in said, said
    assert "before the run recorded its end," in said, said
    assert "nothing is left to resume" not in said, said
    assert f"rti-rig run --resume {out}` records it complete without shooting" in said, said
    assert f"rti-rig fit {out} --out {out}-fit" in said, said
    assert len((out / "lights.lp").read_text().splitlines()) == 7  # its count and 6 lights


def _cli(*args: str) -> tuple[int, str]:
    return _python("-m", "rti_rig", *args)


@pytest.mark.skipif(sys.platform == "win32", reason="signals tested on POSIX")
def test_an_adaptive_session_stopped_with_every_image_in_is_completed_by_its_resume(
    tmp_path: Path,
) -> None:
    """Its outcome (why it stopped, its estimate) is not recorded until the resume the stop
    names, which shoots nothing and records it."""
    code, said, out = _run_sigterm_at(tmp_path, 5, "--adaptive")
    assert code == 143 and "Traceback" not in said, said
    manifest = json.loads((out / "manifest.json").read_text())
    assert manifest["runner"]["finish_reason"] != "completed", said
    assert "result" not in manifest["adaptive"], said
    assert "before the run recorded its end and its adaptive outcome" in said, said
    assert f"rti-rig run --resume {out}` records it complete" in said, said
    lp = (out / "lights.lp").read_text()
    images = {p.name: p.read_bytes() for p in out.glob("image_*.jpg")}
    assert len(images) == 6, said
    code, said = _cli("run", "--resume", str(out), "--no-verdict")
    assert code == 0 and "Traceback" not in said, said
    assert "0 of 6 lights left" in said, said
    manifest = json.loads((out / "manifest.json").read_text())
    assert manifest["runner"]["finish_reason"] == "completed", said
    assert manifest["adaptive"]["result"]["lights_used"] == 6, said
    # nothing shot again, nothing lost or overwritten
    assert {p.name: p.read_bytes() for p in out.glob("image_*.jpg")} == images
    assert (out / "lights.lp").read_text() == lp


@pytest.mark.skipif(sys.platform == "win32", reason="signals tested on POSIX")
def test_a_sigterm_with_images_missing_still_says_the_resume(tmp_path: Path) -> None:
    code, said, out = _run_sigterm_at(tmp_path, 2)
    assert code == 143, said
    kept = f"3 image(s) kept in {out}, listed in lights.lp. Continue with: rti-rig run --resume"
    assert kept in said, said
    assert "session is complete" not in said, said


#: as SCRIPT, but the SIGTERM comes as the session records its end (in the teardown, where
#: it is held until the teardown is done): after an adaptive stopping rule ended it
FINISH_SCRIPT = """
import os, signal, sys
from rti_rig.runtime.session import SessionFolder
real = SessionFolder.finish
def finish(self, *a, **k):
    real(self, *a, **k)
    os.kill(os.getpid(), signal.SIGTERM)
SessionFolder.finish = finish
from rti_rig.cli import app
app(sys.argv[1:], prog_name="rti-rig")
"""


@pytest.mark.skipif(sys.platform == "win32", reason="signals tested on POSIX")
def test_a_sigterm_after_an_until_error_stop_says_complete_not_resume(tmp_path: Path) -> None:
    """Its stopping rule ended it short of its maximum and the run recorded it complete: the
    stop had said "Continue with: rti-rig run --resume S", which the resume refused as
    "already completed"."""
    out = tmp_path / "s"
    args = ["run", str(CONFIGS / "simulated_dome.toml"), "--out", str(out)]
    code, said = _python("-c", FINISH_SCRIPT, *args, "--until-error", "3", "--no-verdict")
    assert code == 143 and "Emergency stop (SIGTERM)" in said, said
    manifest = json.loads((out / "manifest.json").read_text())
    assert manifest["runner"]["finish_reason"] == "completed", said
    kept = len(list(out.glob("image_*.jpg")))
    total = manifest["runner"]["steps_planned"]
    assert kept < total, said  # stopped by its rule, short of its maximum
    assert "Continue with" not in said, said
    assert f"the session is complete (its stopping rule ended it at {kept} of at most {total}" in (
        said
    )
    assert f"Next: rti-rig fit {out} --out {out}-fit" in said, said
    code, again = _cli("run", "--resume", str(out))
    # what the advice would have met: complete, said so, with the same next step
    assert code == 0 and "this adaptive session is complete: it stopped after" in again, again
    assert f"Next: rti-rig fit {out} --out {out}-fit" in again, again


@pytest.mark.skipif(sys.platform == "win32", reason="signals tested on POSIX")
def test_a_camera_triggered_run_stopped_before_its_proof_is_not_said_complete(
    tmp_path: Path,
) -> None:
    """Every image of the shipped cceh/rti dome is in, but the SIGTERM stops the run before its
    end-of-run proof frame, which alone verifies the labels: it had said "the session is
    complete, nothing is left to resume. Next: rti-rig fit", and fit refused the session."""
    out = tmp_path / "s"
    args = ["run", str(CONFIGS / "emulated_cceh_rti.toml"), "--out", str(out), "--no-verdict"]
    code, said = _python("-c", SCRIPT, "59", *args)
    assert code == 143 and "Emergency stop (SIGTERM)" in said, said
    assert len(list(out.glob("image_*.jpg"))) == 60, said  # every image is in
    assert "session is complete" not in said and "Next: rti-rig fit" not in said, said
    marker = out / "LABELS_NOT_VERIFIED.txt"
    assert f"listed in lights.lp, their labels NOT verified: {marker} says why" in said, said
    assert "A camera-triggered dome cannot resume a session" in said, said
    # with the run that shoots it again, into a free folder beside it ("start a new session"
    # had left the config and a folder to find)
    config = CONFIGS / "emulated_cceh_rti.toml"
    assert f"then start a new session: rti-rig run {config} --out {tmp_path / 's-again'}" in said
    code, fitted = _cli("fit", str(out), "--out", str(tmp_path / "fit"))  # what fit says of it
    assert code != 0 and "it is not used" in fitted, fitted


@pytest.mark.skipif(sys.platform == "win32", reason="signals tested on POSIX")
def test_a_resume_with_one_image_left_says_it_of_all_the_lights(tmp_path: Path) -> None:
    """Stopped with 5 of 6 images in, the resume says "1 of 6 lights left": the noun had
    followed the images left, "1 of 6 light left"."""
    code, said, out = _run_sigterm_at(tmp_path, 4)
    assert code == 143 and "Traceback" not in said, said
    code, said = _cli("run", "--resume", str(out), "--no-verdict")
    assert code == 0 and "Traceback" not in said, said
    assert "1 of 6 lights left" in said, said
