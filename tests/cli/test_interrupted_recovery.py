"""Recovery commands interrupted part-way: ``run --resume --reshoot-lost`` and
``--rebuild-journal`` killed, then fit, export-lp and a resume; every image survives, and
every message names the session, what happened and a next command that is not refused."""

from __future__ import annotations

import hashlib
import shutil
from pathlib import Path

import pytest
from conftest import SMALL_DOME, said, write_config
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.testing.kill_hooks import popen_argv

runner = CliRunner()
LIGHTS = 6


def _images(folder: Path) -> dict[str, str]:
    files = [*folder.glob("image_*.jpg"), *(folder / "linear").glob("*.tif"), folder / "lights.lp"]
    return {
        p.relative_to(folder).as_posix(): hashlib.sha256(p.read_bytes()).hexdigest() for p in files
    }


@pytest.fixture(scope="module")
def ref(tmp_path_factory: pytest.TempPathFactory) -> Path:
    base = tmp_path_factory.mktemp("ref")
    cfg = write_config(base, SMALL_DOME)
    out = base / "done"
    r = runner.invoke(app, ["run", str(cfg), "--out", str(out), "--lights", str(LIGHTS)])
    assert r.exit_code == 0, r.output
    return out


def test_a_reshoot_killed_while_saving_is_fitted_exported_and_resumed(
    ref: Path, tmp_path: Path
) -> None:
    """--reshoot-lost of image_003 SIGKILLed between its TIFF and its JPEG: fit and export-lp
    of the folder died on an IndexError (every step recorded, the session no longer
    completed), and the verdict advised --reshoot-lost, which is refused for a session not
    finished. Now both work, the advice is the plain resume, and it makes the session whole."""
    out = tmp_path / "s"
    shutil.copytree(ref, out)
    damaged = (out / "image_003.jpg").read_bytes() + b"x"
    (out / "image_003.jpg").write_bytes(damaged)
    proc = popen_argv("between_files", 0, ["run", "--resume", str(out), "--reshoot-lost"])
    proc.communicate(timeout=300)
    assert proc.returncode == -9
    r = runner.invoke(app, ["fit", str(out), "--out", str(tmp_path / "fit"), "--model", "ps"])
    assert r.exit_code == 0, r.output
    assert "image_003" in said(r) and f"rti-rig run --resume {out}" in said(r), r.output
    assert "--reshoot-lost" not in said(r)  # refused for a session not finished
    r = runner.invoke(app, ["export-lp", str(out), "--out", str(tmp_path / "x.lp")])
    assert r.exit_code == 0 and "image_003.jpg" in said(r), r.output
    r = runner.invoke(app, ["run", "--resume", str(out), "--no-verdict"])
    assert r.exit_code == 0, r.output
    assert _images(out) == _images(ref)
    kept = [p.read_bytes() for p in (out / "recovered").rglob("image_003.jpg")]
    assert kept == [damaged]  # set aside, never deleted nor overwritten


def test_the_reshoot_says_where_it_set_the_files_aside_without_calling_them_unverified(
    ref: Path, tmp_path: Path
) -> None:
    """--reshoot-lost of image_002 (its JPEG changed, its TIFF as captured): "2 unverified
    file(s) moved to recovered/" had been said of a TIFF whose checksum matched, in a folder
    whose recovered/ may hold earlier resumes' files too."""
    out = tmp_path / "s"
    shutil.copytree(ref, out)
    (out / "image_002.jpg").write_bytes((out / "image_002.jpg").read_bytes() + b"x")
    with (out / "journal.jsonl").open("a") as journal:  # a torn line, set aside there too
        journal.write('{"index": 3, "imag')
    r = runner.invoke(app, ["run", "--resume", str(out), "--reshoot-lost", "--no-verdict"])
    assert r.exit_code == 0, r.output
    (stamp,) = (out / "recovered").iterdir()
    assert (stamp / "journal-rejected.txt").is_file()
    assert (
        f"2 file(s) of the images to reshoot set aside in recovered/{stamp.name}/ (never "
        "deleted)" in said(r)
    ), r.output
    assert "unverified" not in said(r)
    # the count is of the images' files set aside, whatever else the resume put there
    aside = [p for p in stamp.rglob("*") if p.is_file() and p.name.startswith("image_")]
    assert len(aside) == 2, sorted(p.name for p in stamp.rglob("*"))


def test_the_reshoot_again_after_it_was_killed_names_the_resume_that_continues(
    ref: Path, tmp_path: Path
) -> None:
    """The same --reshoot-lost again after it was SIGKILLed before its light: refused with
    "drop --reshoot-lost", the command left to guess. Now it says how the last run ended and
    names the resume; nothing in the folder changes, and that resume makes it whole."""
    out = tmp_path / "s"
    shutil.copytree(ref, out)
    (out / "image_005.jpg").write_bytes((out / "image_005.jpg").read_bytes() + b"x")
    proc = popen_argv("before_light", 0, ["run", "--resume", str(out), "--reshoot-lost"])
    proc.communicate(timeout=300)
    assert proc.returncode == -9
    before = {p: p.read_bytes() for p in out.rglob("*") if p.is_file()}
    r = runner.invoke(app, ["run", "--resume", str(out), "--reshoot-lost"])
    assert r.exit_code == 2, r.output
    assert "its last run: it stopped without recording why (killed, a power cut," in said(r)
    assert said(r).endswith(f"continue it with rti-rig run --resume {out}"), r.output
    assert {p: p.read_bytes() for p in out.rglob("*") if p.is_file()} == before
    r = runner.invoke(app, ["run", "--resume", str(out), "--no-verdict"])
    assert r.exit_code == 0, r.output
    assert _images(out) == _images(ref)


def test_the_verdict_of_a_reshoot_stopped_part_way_counts_the_image_lost(
    ref: Path, tmp_path: Path
) -> None:
    """A --reshoot-lost SIGKILLed before its light: the verdict said "the session is not
    finished (6 of 6 images; …)", which read as a contradiction; now it says one is lost."""
    out = tmp_path / "s"
    shutil.copytree(ref, out)
    (out / "image_004.jpg").write_bytes((out / "image_004.jpg").read_bytes() + b"x")
    proc = popen_argv("before_light", 0, ["run", "--resume", str(out), "--reshoot-lost"])
    proc.communicate(timeout=300)
    assert proc.returncode == -9
    r = runner.invoke(app, ["fit", str(out), "--out", str(tmp_path / "fit"), "--model", "ps"])
    assert r.exit_code == 0, r.output
    assert (
        f"the session is not finished ({LIGHTS} of {LIGHTS} images, 1 of them lost since; it "
        "stopped without recording why" in said(r)
    ), r.output
