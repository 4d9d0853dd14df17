"""A Ctrl-C once every image is in (during the teardown, as the records are finished) says the
truth of what the session holds: complete, fit next; never the resume.

Found by a review: the first Ctrl-C there said "Stopping after this image (Ctrl-C again to stop
at once)" as if an image were still to come, and an adaptive session that had stopped itself
short of its maximum (its estimate met --until-error), stopped by a second Ctrl-C in its
teardown, was told "Continue with: rti-rig run --resume" (its images were counted against the
maximum, not the manifest's "completed"; two Ctrl-C in that teardown stop no image: the run
stops after its summary, the session said complete as the manifest records it). A stop with
images missing still says the resume.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest
from conftest import CONFIGS, REPO

#: ``rti-rig run`` in a process of its own that sends itself SIGINT ``TIMES`` times when the
#: session's records are finished (the teardown: after the capture's end, or its stop) when
#: ``AT`` is -1, as the run is about to write its first file when -2, or once image ``AT``
#: (0-based) is committed when ``AT`` >= 0: a condition, never a delay
SCRIPT = """
import os, signal, sys
from rti_rig.runtime.session import SessionFolder
AT, TIMES = int(sys.argv.pop(1)), int(sys.argv.pop(1))
def interrupt():
    for _ in range(TIMES):
        os.kill(os.getpid(), signal.SIGINT)
if AT == -2:
    real_begin = SessionFolder.begin
    def begin(self, *a, **k):
        interrupt()
        return real_begin(self, *a, **k)
    SessionFolder.begin = begin
elif AT < 0:
    real_finish = SessionFolder.finish
    def finish(self, *a, **k):
        interrupt()
        return real_finish(self, *a, **k)
    SessionFolder.finish = finish
else:
    real_write = SessionFolder.write_step
    def write_step(self, i, *a, **k):
        record = real_write(self, i, *a, **k)
        if i == AT:
            interrupt()
        return record
    SessionFolder.write_step = write_step
from rti_rig.cli import app
app(sys.argv[1:], prog_name="rti-rig")
"""

pytestmark = pytest.mark.skipif(sys.platform == "win32", reason="signals tested on POSIX")


def _run(tmp_path: Path, at: int, times: int, *options: str) -> tuple[int, str, Path]:
    out = tmp_path / "s"
    new = [] if "--resume" in options else [str(CONFIGS / "simulated_dome.toml"), "--out", str(out)]
    args = ["run", *new, *options]
    proc = subprocess.run(
        [sys.executable, "-c", SCRIPT, str(at), str(times), *args, "--no-verdict"],
        capture_output=True,
        text=True,
        timeout=600,
        env={**os.environ, "PYTHONPATH": str(REPO), "COLUMNS": "300"},
    )
    return proc.returncode, " ".join((proc.stdout + proc.stderr).split()), out


def test_a_ctrl_c_after_the_last_image_says_it_is_in_and_completes(tmp_path: Path) -> None:
    code, said, out = _run(tmp_path, 5, 1, "--lights", "6")
    assert code == 0, said
    assert "Every image is in: finishing the session" in said, said
    assert "Stopping after this image" not in said and "--resume" not in said, said
    assert "6 image(s) in the session; lights.lp lists the lights that fired." in said, said
    assert len((out / "lights.lp").read_text().splitlines()) == 7  # its count and 6 lights


def test_two_ctrl_c_in_a_completed_adaptive_sessions_teardown_say_complete(
    tmp_path: Path,
) -> None:
    code, said, out = _run(tmp_path, -1, 2, "--until-error", "30", "--lights", "20")
    manifest = json.loads((out / "manifest.json").read_text())
    kept = manifest["runner"]["steps_done"]
    # the session stopped itself short of its maximum, and its manifest says it completed
    assert manifest["runs"][-1]["finish_reason"] == "completed" and 0 < kept < 20, manifest
    # both came once the capture had ended: they stopped no image, and the run stops after
    # its summary (it had said "Emergency stop (second Ctrl-C)" of this completed manifest,
    # an emergency teardown that never ran)
    assert code == 130, said
    assert "Emergency stop" not in said and "Traceback" not in said, said
    assert said.count("Ctrl-C after the capture had ended: there was nothing left to stop") == 1
    assert "--resume" not in said, said
    assert f"{kept} image(s) in the session; lights.lp lists the lights that fired." in said
    assert "Stopped (Ctrl-C) once the session had ended: it is complete" in said, said
    assert f"rti-rig fit {out} --out {out}-fit gives it" in said, said


def test_two_ctrl_c_with_images_missing_still_say_the_resume(tmp_path: Path) -> None:
    code, said, out = _run(tmp_path, 2, 2, "--lights", "6")
    assert code == 130, said
    assert "Stopping after this image" in said, said
    kept = f"3 image(s) kept in {out}, listed in lights.lp. Continue with: rti-rig run --resume"
    assert kept in said, said
    assert "session is complete" not in said, said


def test_a_reshoot_stopped_before_it_wrote_anything_is_not_said_complete(tmp_path: Path) -> None:
    """A completed session reopened with --reshoot-lost, stopped (two Ctrl-C) before its first
    write: the manifest's last run is still the earlier, completed one, and was read as this
    run's ("the session is complete, nothing is left to resume", an image still missing)."""
    code, said, out = _run(tmp_path, 99, 0, "--lights", "6")
    assert code == 0, said
    (out / "image_003.jpg").unlink()
    (out / "linear" / "image_003.tif").unlink()
    code, said, _ = _run(tmp_path, -2, 2, "--resume", str(out), "--reshoot-lost")
    assert code == 130, said
    assert "session is complete" not in said and "Traceback" not in said, said
    assert f"5 image(s) kept in {out}" in said, said
    assert f"Continue with: rti-rig run --resume {out} --reshoot-lost" in said, said


def test_a_reshoot_stopped_as_the_capture_takes_over_is_told_to_reshoot(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The same stop, held by the hand-over from the opening to the capture (a SIGTERM raised
    as the hand-over starts holding): it had been told "continue it with rti-rig run --resume
    S", which refuses a completed session, --reshoot-lost dropped."""
    import signal

    from typer.testing import CliRunner

    import rti_rig.cli.session as cli_session
    from rti_rig.cli import app

    code, said, out = _run(tmp_path, 99, 0, "--lights", "6")
    assert code == 0, said
    (out / "image_003.jpg").unlink()
    (out / "linear" / "image_003.tif").unlink()
    real_hold, held = cli_session.HandOver.hold, []

    def hold(self):  # type: ignore[no-untyped-def]
        real_hold(self)
        held.append(signal.SIGTERM)
        signal.raise_signal(signal.SIGTERM)  # recorded by the hand-over, answered by the capture

    monkeypatch.setattr(cli_session.HandOver, "hold", hold)
    argv = ["run", "--resume", str(out), "--reshoot-lost", "--no-verdict"]
    r = CliRunner().invoke(app, argv, terminal_width=400)
    said = " ".join(r.output.split())
    assert held and r.exit_code == 143 and "Traceback" not in said, said
    assert "Stopped (SIGTERM) before the session went on" in said, said
    assert f"continue it with rti-rig run --resume {out} --reshoot-lost" in said, said


def test_a_reshoot_stopped_before_it_wrote_anything_is_told_the_flags_it_was_given(
    tmp_path: Path,
) -> None:
    """The same stop of a reshoot given its rig config and --accept-rig-change: it had been
    told ``--resume S --reshoot-lost``, the config and the acceptance dropped (a resume
    without them takes the manifest's config, or refuses the rig change again)."""
    code, said, out = _run(tmp_path, 99, 0, "--lights", "6")
    assert code == 0, said
    (out / "image_003.jpg").unlink()
    (out / "linear" / "image_003.tif").unlink()
    cfg = str(CONFIGS / "simulated_dome.toml")
    flags = ("--resume", str(out), "--accept-rig-change", "--reshoot-lost")
    code, said, _ = _run(tmp_path, -2, 2, cfg, *flags)
    assert code == 130 and "Traceback" not in said, said
    given = f"rti-rig run {cfg} --resume {out} --accept-rig-change --reshoot-lost"
    assert f"Continue with: {given}" in said, said


def test_a_ctrl_c_on_the_image_that_meets_the_target_completes_the_session(
    tmp_path: Path,
) -> None:
    """An --until-error session stopped by one Ctrl-C as the image that meets its target is
    committed: whether it ended "cancelled" (exit 130, resume advised) or complete (exit 0)
    had hung on whether the Ctrl-C landed before or during the next decision. The decision
    is made either way, and a session it says is done is complete."""
    whole = tmp_path / "whole"
    whole.mkdir()
    code, said, out = _run(whole, 99, 0, "--until-error", "30", "--lights", "20")
    assert code == 0, said
    kept = json.loads((out / "manifest.json").read_text())["runner"]["steps_done"]
    assert 4 <= kept < 20, kept  # it stopped itself (judged from its 4th image on) short of 20
    code, said, out = _run(tmp_path, kept - 1, 1, "--until-error", "30", "--lights", "20")
    manifest = json.loads((out / "manifest.json").read_text())
    assert code == 0, said
    assert manifest["runner"]["finish_reason"] == "completed", manifest["runner"]
    assert manifest["runner"]["steps_done"] == kept and "--resume" not in said, said
    # a Ctrl-C one image earlier still stops it there, cancelled, the resume said
    code, said, out = _run(tmp_path / "x", kept - 2, 1, "--until-error", "30", "--lights", "20")
    assert code == 130 and f"{kept - 1} image(s) in the session" in said and "--resume" in said, (
        said
    )
