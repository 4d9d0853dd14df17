"""A disk that fills while a watched folder's shot is copied into the session, through
`rti-rig run` on the shipped folder-watch example (its dome firmware emulated on a pty, its
camera a thread that saves a DNG into the folder for each shutter pulse the board saw), then
the resume the stop gives.

The folder belongs to the tethering program, so the shot is copied into the session's
``raw/.incoming`` before it is decoded. When the disk refuses that copy, the shot is still in
the watched folder under the camera's name; the stop said only "it could not be copied into …
([Errno 28] …)": not where the shot is, nor what a resume does with it. A resume takes every
file already in the folder as seen (an older file is never a light's image), so that shot is
not used: the resume shoots the light again.
"""

from __future__ import annotations

import errno
import os
import shutil
import sys
from pathlib import Path
from typing import Any

import pytest
from conftest import Tether, folder_watch_config, shipped_dome_on_pty, tethered_run
from dng_spec_writer import flat_dng
from typer.testing import CliRunner

from rti_rig.cli import app

pytestmark = [
    pytest.mark.skipif(sys.platform != "linux", reason="pty semantics tested on Linux"),
    pytest.mark.pty,
]


def _disk_full_after(monkeypatch: pytest.MonkeyPatch, copies: int) -> None:
    """The session's disk fills after ``copies`` files copied into it: a later copy fails as
    the system's does, with ENOSPC and part of the file written."""
    real = shutil.copyfile
    done = 0

    def copyfile(src: Any, dst: Any, *args: Any, **kwargs: Any) -> Any:
        nonlocal done
        if ".incoming" not in str(dst):
            return real(src, dst, *args, **kwargs)
        done += 1
        if done > copies:
            Path(dst).write_bytes(Path(src).read_bytes()[:100])
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC), str(dst))
        return real(src, dst, *args, **kwargs)

    monkeypatch.setattr(shutil, "copyfile", copyfile)


def _resumed(
    monkeypatch: pytest.MonkeyPatch, cfg: Path, tether: Path, out: Path, shots: int = 2
) -> tuple[Any, list[tuple[str, bytes]]]:
    """``run --resume out`` on the dome, the camera saving ``shots`` new shots (IMG_0004 on)
    into ``tether`` at the board's shutter pulses: the CLI's result and the shots given."""
    again = [(f"IMG_{k:04d}.DNG", flat_dng(0.1 * k)) for k in range(4, 4 + shots)]
    with shipped_dome_on_pty(monkeypatch, cfg) as firmware:
        camera = Tether(firmware, tether, again)
        camera.start()
        try:
            r = CliRunner().invoke(
                app, ["run", "--resume", str(out), "--no-verdict"], terminal_width=400
            )
        finally:
            camera.stop.set()
            camera.join(5.0)
    return r, again


def test_a_disk_full_copy_says_where_the_shot_is_and_what_the_resume_does(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    tether = tmp_path / "tether"
    tether.mkdir()
    cfg = folder_watch_config(tmp_path, tether, timeout_s=10.0)
    out = tmp_path / "s"
    files = [(f"IMG_{k:04d}.DNG", flat_dng(0.1 * k)) for k in range(1, 4)]
    with monkeypatch.context() as m:
        _disk_full_after(m, 1)  # the 2nd shot's copy
        run = tethered_run(monkeypatch, cfg, tether, files, out, lights=3)
    said = run.said
    assert run.result.exit_code != 0, said
    assert "Traceback" not in said and not run.lit_at_end, said
    assert (tether / "IMG_0002.DNG").is_file()  # where the camera saved it
    assert not list((out / "raw" / ".incoming").glob(".*.partial"))  # no half copy left
    assert "the disk refused the copy (full" in said, said
    assert f"IMG_0002.DNG is still in {tether}, but a resume will not use it" in said, said
    assert "shoots this light again" in said, said
    assert f"rti-rig run --resume {out}" in said, said

    # the resume, as said: the light is shot again and its new file taken, not IMG_0002.DNG
    r, again = _resumed(monkeypatch, cfg, tether, out)
    assert r.exit_code == 0, r.output
    assert (out / "raw" / "image_002.dng").read_bytes() == again[0][1]
    assert (out / "lights.lp").read_text().split()[0] == "3"


def test_a_disk_full_at_the_steps_images_says_which_shot_and_what_the_resume_does(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The copy came in, but the disk fills at the step's linear TIFF: the stop said "1
    image(s) are kept" and to resume, not which shot was not recorded nor what becomes of it."""
    from rti_rig.testing.disk_faults import failing_writes

    tether = tmp_path / "tether"
    tether.mkdir()
    cfg = folder_watch_config(tmp_path, tether, timeout_s=10.0)
    out = tmp_path / "s"
    files = [(f"IMG_{k:04d}.DNG", flat_dng(0.1 * k)) for k in range(1, 4)]
    with failing_writes("tiff", after=1, errno_code=errno.ENOSPC):  # the 2nd shot's
        run = tethered_run(monkeypatch, cfg, tether, files, out, lights=3)
    said = run.said
    assert run.result.exit_code != 0, said
    assert "Traceback" not in said and not run.lit_at_end, said
    assert "this light's shot (IMG_0002.DNG) is not recorded: the resume moves whatever" in said
    assert "recovered/ folder and shoots this light again" in said, said
    # the resume command once, at the end of the error (the teardown's line had said it too)
    assert said.lower().count("rti-rig run --resume") == 1, said
    assert said.rstrip().endswith(f"continue with rti-rig run --resume {out}"), said
    assert f"1 image(s) kept in {out}, listed in lights.lp." in said, said

    r, again = _resumed(monkeypatch, cfg, tether, out)
    assert r.exit_code == 0, r.output
    assert (out / "raw" / "image_002.dng").read_bytes() == again[0][1]
    moved = list((out / "recovered").rglob("*.dng"))
    assert [p.read_bytes() for p in moved] == [files[1][1]], moved


def test_a_disk_full_at_the_first_image_says_the_disk_the_shot_and_what_the_resume_does(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The disk fills at the first image's linear TIFF: nothing is kept yet, and the stop was a
    bare "cannot write …/linear/image_001.tif: No space left on device", without the disk,
    its free space, where the shot is or what the resume does with it."""
    from rti_rig.testing.disk_faults import failing_writes

    tether = tmp_path / "tether"
    tether.mkdir()
    cfg = folder_watch_config(tmp_path, tether, timeout_s=10.0)
    out = tmp_path / "s"
    files = [(f"IMG_{k:04d}.DNG", flat_dng(0.1 * k)) for k in range(1, 4)]
    with failing_writes("tiff", after=0, errno_code=errno.ENOSPC):  # the 1st shot's
        run = tethered_run(monkeypatch, cfg, tether, files, out, lights=3)
    said = run.said
    assert run.result.exit_code != 0, said
    assert "Traceback" not in said and not run.lit_at_end, said
    assert f"cannot write {out}/linear/image_001.tif: No space left on device" in said, said
    assert f"stopped before any image was kept, on the disk of {out} (mounted at /" in said
    assert " free now); this light's shot (IMG_0001.DNG) is not recorded;" in said, said
    assert f"IMG_0001.DNG is still in the watched folder {tether}, but the resume" in said
    assert "recovered/ folder and shoots this light again" in said, said
    assert (
        f"free space on that disk (or lift the file-size limit or quota), then continue "
        f"with rti-rig run --resume {out}" in said
    ), said
    # said once, after the fix it needs (the teardown's line had said "Continue with:" too)
    assert said.lower().count("rti-rig run --resume") == 1, said
    assert f"No image was completed, but {out} holds files of the camera." in said, said

    # the resume, as said: the copy that reached the session is set aside, the light reshot
    r, again = _resumed(monkeypatch, cfg, tether, out, shots=3)
    assert r.exit_code == 0, r.output
    assert (out / "raw" / "image_001.dng").read_bytes() == again[0][1]
    moved = list((out / "recovered").rglob("*.dng"))
    assert [p.read_bytes() for p in moved] == [files[0][1]], moved


class _ShareDropsAtSecondShot(Tether):
    """The tethering program's folder on a network share that disconnects at the second
    shutter pulse: the first shot arrives, then the folder is gone."""

    def save(self, name: str, data: bytes) -> None:
        if name == "IMG_0002.DNG":
            shutil.rmtree(self.folder)
            return
        super().save(name, data)


def test_a_watched_folder_gone_mid_run_gives_the_resume_command_itself(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The stop said "reconnect it, then continue with 'rti-rig run --resume SESSION'": a
    template to fill in, where the session's folder is known. It names the folder now, quoted
    for the shell (a space in it)."""
    from rti_rig.core.shell_words import shell_word

    tether = tmp_path / "tether"
    tether.mkdir()
    cfg = folder_watch_config(tmp_path, tether, timeout_s=2.0)
    out = tmp_path / "my session"
    files = [(f"IMG_{k:04d}.DNG", flat_dng(0.1 * k)) for k in range(1, 3)]
    run = tethered_run(
        monkeypatch,
        cfg,
        tether,
        files,
        out,
        lights=2,
        camera=lambda fw: _ShareDropsAtSecondShot(fw, tether, files),
    )
    said = run.said
    assert run.result.exit_code != 0 and "Traceback" not in said, said
    assert "no longer there or cannot be reached" in said, said
    assert f"then continue with: rti-rig run --resume {shell_word(str(out))}" in said, said
    assert "SESSION" not in said, said
