"""A tethered DSLR session whose disk fills while a RAW is downloaded, through `rti-rig run`
on the shipped DSLR example (its dome firmware emulated on a pty, python-gphoto2 replaced at
its API boundary by tests/fake_gphoto2.py), then `--resume` once there is room.

libgphoto2's ``gp_file_save`` answers a short write by unlinking the file and returning
GP_ERROR (-1), which python-gphoto2 raises. Uncaught, the run stopped with "unexpected
GPhoto2Error: [-1] libgphoto2 error (… please report it …)": not a word of the full disk, of
the shot lost with the camera's RAM, or that a resume shoots it again.
"""

from __future__ import annotations

import json
import shutil
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from conftest import CONFIGS, shipped_dome_on_pty
from dng_spec_writer import dng, mosaic_from_rgb
from fake_gphoto2 import Body, make_module
from typer.testing import CliRunner

from rti_rig.cli import app

pytestmark = [
    pytest.mark.skipif(sys.platform != "linux", reason="pty semantics tested on Linux"),
    pytest.mark.pty,
]


def _config(tmp_path: Path, target: str) -> Path:
    """The shipped DSLR example beside its .lp, small frames, shooting into ``target``."""
    shutil.copy(CONFIGS / "example_dome_48.lp", tmp_path / "example_dome_48.lp")
    text = (CONFIGS / "example_dome_48.toml").read_text()
    old = 'capture_target = "Internal RAM"'
    assert old in text
    text = text.replace(old, f'capture_target = "{target}"')
    text = text.replace("width = 6000", "width = 48").replace("height = 4000", "height = 32")
    cfg = tmp_path / "dslr.toml"
    cfg.write_text(text)
    return cfg


def _raw(body: Body) -> bytes:
    rgb = np.broadcast_to(np.array([0.2, 0.5, 0.8]), (32, 48, 3))
    return dng(mosaic_from_rgb(np.array(rgb), "RGGB", (0,) * 4, 4095), "RGGB", (0,) * 4, 4095)


def _shot_with(
    monkeypatch: pytest.MonkeyPatch, cfg: Path, body: Body, argv: list[str]
) -> tuple[Any, str, Any]:
    """``rti-rig ARGV`` on the shipped dome, the camera the gphoto2 ``body``: the CLI's
    result, its output on one line, and the LEDs lit once it ended (None: all off)."""
    monkeypatch.setitem(sys.modules, "gphoto2", make_module(body))
    with shipped_dome_on_pty(monkeypatch, cfg) as firmware:
        r = CliRunner().invoke(app, argv)
        lit_at_end = firmware.lit
    return r, " ".join(r.output.split()), lit_at_end


@pytest.mark.parametrize("target", ["Internal RAM", "Memory card"])
def test_a_disk_full_at_a_download_is_said_and_the_resume_shoots_the_light_again(
    tmp_path, monkeypatch, target
):
    cfg = _config(tmp_path, target)
    body = Body(render=_raw, disk_free_saves=2)  # the third RAW finds the disk full
    out = tmp_path / "s"
    r, said, lit_at_end = _shot_with(
        monkeypatch, cfg, body, ["run", str(cfg), "--out", str(out), "--lights", "4"]
    )
    assert r.exit_code == 2, said
    assert "unexpected" not in said and "please report" not in said, said
    assert "Traceback" not in said and lit_at_end is None, said
    assert "IMG_0003.CR2 came from the camera but could not be written" in said, said
    assert "full, read-only or failing" in said and "MB free there now" in said, said
    assert "rti-rig run --resume" in said, said
    if target == "Internal RAM":
        assert "so it is lost" in said, said
    else:  # the card's copy is the only one: never deleted
        assert "stays on the camera's card at /store_00020001/DCIM/100CANON/IMG_0003" in said
        assert "IMG_0003.CR2" in body.card and not any("IMG_0003" in d for d in body.deleted)
    assert not list((out / "raw" / ".incoming").glob("*IMG_0003*")), "a partial download"
    lp = (out / "lights.lp").read_text().split()
    assert lp[0] == "2", lp

    body.disk_free_saves = None  # room again
    with shipped_dome_on_pty(monkeypatch, cfg):
        r = CliRunner().invoke(app, ["run", "--resume", str(out), "--no-verdict"])
    said = " ".join(r.output.split())
    assert r.exit_code == 0, said
    lines = (out / "lights.lp").read_text().splitlines()
    assert lines[0].strip() == "4", lines
    for k in range(1, 5):
        assert (out / f"raw/image_{k:03d}.cr2").is_file()
        record = json.loads((out / f"records/image_{k:03d}.json").read_text())
        assert record["image"] == f"image_{k:03d}.jpg"


def test_a_disk_full_at_a_metering_download_advises_running_again_not_a_resume(
    tmp_path, monkeypatch
):
    """`run --auto-exposure`'s metering downloads into a private temporary folder before any
    session exists: its refusal advised "'rti-rig run --resume SESSION' shoots it again" beside
    the run's "nothing was captured or written"."""
    cfg = _config(tmp_path, "Internal RAM")
    body = Body(render=_raw, disk_free_saves=0)  # the first metering shot finds it full
    out = tmp_path / "s"
    r, said, lit_at_end = _shot_with(
        monkeypatch,
        cfg,
        body,
        ["run", str(cfg), "--out", str(out), "--lights", "4", "--auto-exposure"],
    )
    assert r.exit_code == 2 and "Traceback" not in said and lit_at_end is None, said
    assert "IMG_0001.CR2 came from the camera but could not be written" in said, said
    assert "nothing was captured or written" in said, said
    assert "--resume" not in said and "run the command again" in said, said
    assert not out.exists() or not any(out.iterdir()), said


@pytest.mark.parametrize("target", ["Internal RAM", "Memory card"])
def test_a_disk_full_at_a_strays_download_is_said_as_the_stray_not_the_shot(
    tmp_path, monkeypatch, target
):
    """The body answers busy once after the first shot yet takes the picture (IMG_0002, a
    stray); the retry takes light 2's own IMG_0003, downloaded whole; the disk fills at the
    stray's download. The stop had called the stray "the shot" ("the shot was taken into the
    camera's RAM … so it is lost") and said nothing of light 2's own file, downloaded whole."""
    cfg = _config(tmp_path, target)
    body = Body(render=_raw, disk_free_saves=2, busy_after_shot=1, busy_yet_shot=1)
    out = tmp_path / "s"
    r, said, lit_at_end = _shot_with(
        monkeypatch, cfg, body, ["run", str(cfg), "--out", str(out), "--lights", "3"]
    )
    assert r.exit_code == 2, said
    assert "Traceback" not in said and lit_at_end is None, said
    assert body.stray_files == ["IMG_0002.CR2"], body.stray_files
    assert "IMG_0002.CR2, a stray (a picture the camera took while answering busy" in said
    assert "the shot was taken into" not in said and "the shot's copy" not in said, said
    if target == "Internal RAM":
        assert "The stray was in the camera's RAM, so it is lost" in said, said
    else:
        assert "The stray's copy stays on the camera's card at /store_00020001/" in said, said
        assert "IMG_0002.CR2" in body.card and "IMG_0003.CR2" in body.card
    # light 2's own shot: downloaded whole, and said so with where a resume puts it
    (own,) = (out / "raw" / ".incoming").glob("*IMG_0003.CR2")
    assert own.read_bytes() == _raw(body)
    assert f"This light's own shot (IMG_0003.CR2) was downloaded whole to {own}" in said, said
    assert "resume moves to the session's recovered/ folder" in said, said
    assert (out / "lights.lp").read_text().split()[0] == "1"

    body.disk_free_saves = None  # room again: the resume moves it aside as said
    with shipped_dome_on_pty(monkeypatch, cfg):
        r = CliRunner().invoke(app, ["run", "--resume", str(out), "--no-verdict"])
    assert r.exit_code == 0, " ".join(r.output.split())
    assert [p.name for p in (out / "recovered").rglob("*IMG_0003.CR2")], "not moved aside"
    assert (out / "lights.lp").read_text().split()[0] == "3"


def _big_raw(body: Body) -> bytes:
    """A RAW of some 12 kB: more than one stdio block (4096 bytes), so that where the disk
    fills decides between a short ``fwrite`` and a failed final flush."""
    rgb = np.broadcast_to(np.array([0.2, 0.5, 0.8]), (64, 96, 3))
    return dng(mosaic_from_rgb(np.array(rgb), "RGGB", (0,) * 4, 4095), "RGGB", (0,) * 4, 4095)


@pytest.mark.parametrize("where", ["fwrite", "fclose"])
def test_a_disk_full_within_a_save_is_said_whether_gphoto2_failed_it_or_not(
    tmp_path, monkeypatch, where
):
    """libgphoto2's ``gp_file_save`` fails a short ``fwrite`` (-1, the file removed) but
    ignores a failed ``fclose``: a disk that fills within the last buffered block leaves a
    truncated file and GP_OK. That file had been kept as the shot ("would not decode … is it
    a complete RAW/DNG download?") and the card's copy, the only whole one, deleted."""
    cfg = _config(tmp_path, "Memory card")
    size = len(_big_raw(Body(render=_big_raw)))
    whole_blocks = size - ((size - 1) % 4096 + 1)  # what fwrite writes through; the rest buffered
    room = whole_blocks - 1000 if where == "fwrite" else whole_blocks + 10
    body = Body(render=_big_raw, disk_free_saves=2, disk_free_bytes=room)
    out = tmp_path / "s"
    r, said, lit_at_end = _shot_with(
        monkeypatch, cfg, body, ["run", str(cfg), "--out", str(out), "--lights", "4"]
    )
    assert r.exit_code == 2 and "Traceback" not in said and lit_at_end is None, said
    assert "IMG_0003.CR2 came from the camera but could not be written" in said, said
    assert "full, read-only or failing" in said and "rti-rig run --resume" in said, said
    if where == "fclose":  # gphoto2 said nothing: the size did
        assert f"only {room} of its {size} bytes reached the disk" in said, said
    assert "would not decode" not in said, said
    assert "stays on the camera's card at /store_00020001/DCIM/100CANON/IMG_0003" in said, said
    assert "IMG_0003.CR2" in body.card and not any("IMG_0003" in d for d in body.deleted)
    assert not list((out / "raw" / ".incoming").glob("*IMG_0003*")), "a truncated file kept"
    assert (out / "lights.lp").read_text().split()[0] == "2"


class _FolderGoneAtDownload:
    """A download clock whose third download finds the session's staging folder gone (a
    disk unmounted, a folder removed), so that libgphoto2's ``fopen`` fails: -1, no file."""

    def __init__(self, folder: Path) -> None:
        self.folder, self.downloads = folder, 0

    def sleep(self, s: float) -> None:
        self.downloads += 1
        if self.downloads == 3:
            shutil.rmtree(self.folder)


def test_a_save_whose_file_cannot_be_created_is_not_called_a_full_disk(tmp_path, monkeypatch):
    """``gp_file_save`` answers a refused ``fopen`` with the same -1 as a short write: the
    stop said "that disk refused it (full, …)" and to free space, which fixes nothing."""
    cfg = _config(tmp_path, "Memory card")
    out = tmp_path / "s"
    clock = _FolderGoneAtDownload(out / "raw" / ".incoming")
    body = Body(render=_raw, download_s=0.001, download_clock=clock)
    r, said, lit_at_end = _shot_with(
        monkeypatch, cfg, body, ["run", str(cfg), "--out", str(out), "--lights", "4"]
    )
    assert r.exit_code == 2 and "Traceback" not in said and lit_at_end is None, said
    assert "IMG_0003.CR2 came from the camera but could not be written" in said, said
    assert "no file can be created there (No such file or directory): not a full disk" in said
    assert "full, read-only or failing" not in said and "free space" not in said, said
    # the command itself, not a template to fill in
    assert (
        f"make that folder writable, then shoot it again with: rti-rig run --resume {out}" in said
    )
    assert "SESSION" not in said, said
    assert "IMG_0003.CR2" in body.card and not any("IMG_0003" in d for d in body.deleted)


def test_a_disk_full_at_a_preview_download_advises_the_preview_again_not_a_resume(
    tmp_path, monkeypatch
):
    """`rti-rig preview` is a one-image session no `run --resume` continues: its refusal
    advised "'rti-rig run --resume SESSION' shoots it again"."""
    cfg = _config(tmp_path, "Internal RAM")
    body = Body(render=_raw, disk_free_saves=0)  # the preview's one shot finds it full
    out = tmp_path / "p"
    r, said, lit_at_end = _shot_with(
        monkeypatch, cfg, body, ["preview", str(cfg), "--out", str(out)]
    )
    assert r.exit_code == 2 and "Traceback" not in said and lit_at_end is None, said
    assert "IMG_0001.CR2 came from the camera but could not be written" in said, said
    assert "'rti-rig run --resume SESSION' shoots it again" not in said, said
    assert "free space on that disk (or fix it), then run the same 'rti-rig preview' again" in said
    assert "holds no image and may be used again" in said, said  # the same --out will do


class _OutOfInodesAtDownload:
    """A download clock whose third download finds the session's disk out of inodes (or over
    quota): from then on, creating a file in ``folder`` fails with ENOSPC, as ``creat`` does
    on a filesystem with no free inode, so libgphoto2's ``fopen`` fails (-1, no file)."""

    def __init__(self, folder: Path, monkeypatch: pytest.MonkeyPatch) -> None:
        import builtins
        import errno

        self.downloads = 0
        real_open = builtins.open

        def creating(file: Any, mode: str = "r", *args: Any, **kwargs: Any) -> Any:
            if (
                self.downloads >= 3
                and any(c in mode for c in "wxa")
                and isinstance(file, str | Path)
                and Path(file).parent == folder
            ):
                raise OSError(errno.ENOSPC, "No space left on device", str(file))
            return real_open(file, mode, *args, **kwargs)

        monkeypatch.setattr(builtins, "open", creating)

    def sleep(self, s: float) -> None:
        self.downloads += 1


def test_a_folder_that_refuses_a_new_file_for_want_of_inodes_is_said_as_a_full_disk(
    tmp_path, monkeypatch
):
    """A disk out of inodes (or a quota) refuses the new file itself with ENOSPC: the same -1
    from ``fopen`` as a folder that cannot be written into. The probe that tells them apart
    had called it "not a full disk, but the folder's permissions …" and advised making the
    folder writable, which it is."""
    cfg = _config(tmp_path, "Memory card")
    out = tmp_path / "s"
    clock = _OutOfInodesAtDownload(out / "raw" / ".incoming", monkeypatch)
    body = Body(render=_raw, download_s=0.001, download_clock=clock)
    r, said, lit_at_end = _shot_with(
        monkeypatch, cfg, body, ["run", str(cfg), "--out", str(out), "--lights", "4"]
    )
    assert r.exit_code == 2 and "Traceback" not in said and lit_at_end is None, said
    assert "IMG_0003.CR2 came from the camera but could not be written" in said, said
    assert "not a full disk" not in said and "make that folder writable" not in said, said
    assert "full, read-only or failing" in said, said
    assert (
        f"free space on that disk (or fix it), then shoot it again with: rti-rig run --resume {out}"
        in said
    ), said
    assert "SESSION" not in said, said
    assert "IMG_0003.CR2" in body.card and not any("IMG_0003" in d for d in body.deleted)


def test_a_preview_whose_download_the_disk_refused_is_not_told_no_resume_continues_it(
    tmp_path, monkeypatch
):
    """The preview's refusal said "(a preview is one image: no 'rti-rig run --resume'
    continues it)": a preview is a one-image session, and `run --resume` on its folder, once
    there is room, shoots its image. Its advice says to run the preview again, and nothing
    false of the resume."""
    cfg = _config(tmp_path, "Internal RAM")
    body = Body(render=_raw, disk_free_saves=0)
    out = tmp_path / "p"
    r, said, lit_at_end = _shot_with(
        monkeypatch, cfg, body, ["preview", str(cfg), "--out", str(out)]
    )
    assert r.exit_code == 2 and "Traceback" not in said and lit_at_end is None, said
    assert "then run the same 'rti-rig preview' again" in said, said
    assert "no 'rti-rig run --resume' continues it" not in said, said

    body.disk_free_saves = None  # room again: the resume the advice had denied
    with shipped_dome_on_pty(monkeypatch, cfg):
        r = CliRunner().invoke(app, ["run", "--resume", str(out), "--no-verdict"])
    assert r.exit_code == 0, " ".join(r.output.split())
    assert (out / "lights.lp").read_text().split()[0] == "1"
    assert (out / "raw" / "image_001.cr2").is_file()
