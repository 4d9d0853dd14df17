"""A `--reshoot` whose rig does not open leaves the session as it was, not with a hole.

The images named were moved to ``recovered/`` before the rig opened. With the arm's servo
overloaded as the port opened (or a dome's port held by another program), the run stopped
there: the session stayed "completed" with those images missing, and the next plain resume
said "1 of its images is missing or changed since capture (image_003): put the originals back
from a copy", of files rti-rig itself had moved.
"""

from __future__ import annotations

import hashlib
from pathlib import Path

import pytest
from conftest import inprocess_arm_config, said, servo_fault
from typer.testing import CliRunner

from rti_rig.cli import app

runner = CliRunner()


def _tree(folder: Path) -> dict[str, str]:
    return {
        p.relative_to(folder).as_posix(): hashlib.sha256(p.read_bytes()).hexdigest()
        for p in sorted(folder.rglob("*"))
        if p.is_file() and p.name != "manifest.json"
    }


def test_a_reshoot_whose_arm_does_not_connect_puts_the_images_back(tmp_path: Path) -> None:
    first = tmp_path / "first"
    first.mkdir()
    out = tmp_path / "s"
    cfg = inprocess_arm_config(first)
    r = runner.invoke(
        app, ["run", str(cfg), "--out", str(out), "--lights", "6", "--no-verdict"],
        terminal_width=400,
    )  # fmt: skip
    assert r.exit_code == 0, r.output
    before = _tree(out)
    assert not (out / "recovered").exists()

    # the reshoot: servo 1 reports an overload at the first packet, the arm never connects
    again = tmp_path / "again"
    again.mkdir()
    broken = inprocess_arm_config(again, servo_fault(1, 1))
    argv = ["run", str(broken), "--resume", str(out), "--reshoot", "image_003,image_005"]
    r = runner.invoke(app, argv, terminal_width=400)
    text = said(r)
    assert r.exit_code == 2, text
    assert "Traceback" not in text
    assert "Nothing was commanded: the arm could not be connected" in text, text
    # no bar of the images captured before stands above it, as if this run had taken them:
    # "capturing 4/6" had been shown before "Nothing was commanded"
    assert "capturing" not in text, text
    assert (
        "Nothing was reshot: image_003, image_005 put back as captured, and lights.lp lists "
        "every image again: the session's images are as they were before this resume." in text
    ), text
    assert f"once what stopped it is put right, the same command: rti-rig run {broken} " in text
    assert f"--resume {out} --reshoot image_003,image_005" in text, text
    # every file as it was: the images, their TIFFs, lights.lp listing all six, no recovered/
    assert _tree(out) == before
    assert not (out / "recovered").exists()

    # the plain resume after it finds the session complete and intact, not images "lost"
    r = runner.invoke(app, ["run", "--resume", str(out)], terminal_width=400)
    text = said(r)
    assert "this session is complete: all 6 steps were captured" in text, text
    assert "missing or changed since capture" not in text, text

    # the same command, the arm mended, reshoots them
    r = runner.invoke(app, ["run", str(cfg), *argv[2:]], terminal_width=400)
    text = said(r)
    assert r.exit_code == 0, text
    assert "4 of 6 images verified on disk" in text, text


def test_a_reshoot_refused_as_the_rig_opens_puts_the_images_back(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The same when the opening itself fails (a schedule the rig refuses, a Ctrl-C), after
    the reopen set the images aside and before the run took the folder over."""
    from rti_rig.app.usecases import session as usecase
    from rti_rig.core.errors import RtiRigError

    out = tmp_path / "s"
    cfg = inprocess_arm_config(tmp_path)
    r = runner.invoke(app, ["run", str(cfg), "--out", str(out), "--lights", "6", "--no-verdict"])
    assert r.exit_code == 0, r.output
    before = _tree(out)

    def refused(*args: object, **kwargs: object) -> None:
        raise RtiRigError("the dome's port is held by another program")

    monkeypatch.setattr(usecase, "_opened_resume", refused)
    notes: list[str] = []
    with pytest.raises(RtiRigError, match="held by another program"):
        usecase.open_resumed_session(
            usecase.ResumeRequest(out, reshoot=("image_002",)), lambda n: notes.append(n.text)
        )
    assert _tree(out) == before and not (out / "recovered").exists()
    assert notes[-1].startswith("Nothing was reshot: image_002 put back as captured"), notes
    # the folder is not left locked: the next command opens it
    monkeypatch.undo()
    r = runner.invoke(app, ["run", "--resume", str(out)], terminal_width=400)
    assert "this session is complete: all 6 steps were captured" in said(r), said(r)


def test_a_reshoot_lost_whose_arm_does_not_connect_puts_back_what_it_found(tmp_path: Path) -> None:
    """--reshoot-lost sets aside what is lost or changed: put back, it is said as found, not
    "as captured", and lights.lp lists every image as the completed session had."""
    first = tmp_path / "first"
    first.mkdir()
    out = tmp_path / "s"
    cfg = inprocess_arm_config(first)
    argv = ["run", str(cfg), "--out", str(out), "--lights", "6", "--no-verdict"]
    assert runner.invoke(app, argv).exit_code == 0
    (out / "image_004.jpg").unlink()  # lost since capture: its TIFF is set aside to reshoot
    before = _tree(out)
    again = tmp_path / "again"
    again.mkdir()
    broken = inprocess_arm_config(again, servo_fault(1, 1))
    argv = ["run", str(broken), "--resume", str(out), "--reshoot-lost", "--reshoot", "image_002"]
    r = runner.invoke(app, argv, terminal_width=400)
    text = said(r)
    assert r.exit_code == 2, text
    assert (
        "Nothing was reshot: image_002 put back as captured; image_004 put back as found (still "
        "missing or changed since capture), and lights.lp lists every image again"
    ) in text, text
    assert _tree(out) == before and not (out / "recovered").exists()


def test_a_reshoot_stopped_before_its_capture_began_puts_the_images_back(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A Ctrl-C once the rig had opened, before the capture began (metering, the handover),
    had left the images set aside and the session "completed" with a hole."""
    from rti_rig.app.usecases import session as usecase

    out = tmp_path / "s"
    cfg = inprocess_arm_config(tmp_path)
    argv = ["run", str(cfg), "--out", str(out), "--lights", "6", "--no-verdict"]
    assert runner.invoke(app, argv).exit_code == 0
    before = _tree(out)

    def stopped(*args: object, **kwargs: object) -> None:
        raise KeyboardInterrupt

    monkeypatch.setattr(usecase, "run_opened_session", stopped)
    r = runner.invoke(app, ["run", "--resume", str(out), "--reshoot", "image_003"])
    text = said(r)
    assert r.exit_code == 130, text
    assert "Nothing was reshot: image_003 put back as captured" in text, text
    assert f"To reshoot, the same command: rti-rig run --resume {out} --reshoot image_003" in text
    assert _tree(out) == before and not (out / "recovered").exists()
