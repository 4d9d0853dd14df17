"""Sessions that cannot be mixed, torn or stranded (issue #30, findings 1-7).

Each test plays what a user did to break a session — resume on another rig, a torn journal and
a chain of interrupted resumes, a full disk at every write point, junk journal lines, a killed
session opened in relight, a rig that does not answer — through the command line, and checks the
folder against an uninterrupted run of the same plan, file by file.
"""

from __future__ import annotations

import errno
import hashlib
import io
import json
import os
import shutil
import signal
import subprocess
import sys
from pathlib import Path

import pytest
from conftest import CONFIGS, SMALL_DOME, cut_new_session, write_config
from typer.testing import CliRunner

from rti_rig.app.usecases.session import NewSessionRequest
from rti_rig.cli import app
from rti_rig.core.lp_format import read_lp
from rti_rig.runtime.controller import FinishReason
from rti_rig.testing.disk_faults import WRITE_POINTS, failing_writes

runner = CliRunner()
LIGHTS = 8
REPO = Path(__file__).resolve().parents[2]


def said(result) -> str:  # type: ignore[no-untyped-def]
    return " ".join(result.output.split())


def digests(folder: Path) -> dict[str, str]:
    files = [*folder.glob("image_*.jpg"), *(folder / "linear").glob("*.tif"), folder / "lights.lp"]
    return {
        p.relative_to(folder).as_posix(): hashlib.sha256(p.read_bytes()).hexdigest() for p in files
    }


def manifest(folder: Path) -> dict:
    return json.loads((folder / "manifest.json").read_text())


def leftovers(folder: Path) -> list[Path]:
    return [*folder.rglob(".*.partial"), *folder.rglob(".*.tmp")]


def copied(ref: Path, tmp_path: Path) -> Path:
    """A copy of the finished reference session, to be damaged by a test."""
    import shutil

    done = tmp_path / "done"
    shutil.copytree(ref, done)
    return done


@pytest.fixture
def reference(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    base = tmp_path_factory.mktemp("ref")
    cfg = write_config(base, SMALL_DOME)
    out = base / "uninterrupted"
    r = runner.invoke(app, ["run", str(cfg), "--out", str(out), "--lights", str(LIGHTS)])
    assert r.exit_code == 0, r.output
    return cfg, out


def cancelled_after(cfg: Path, out: Path, n: int) -> None:
    """A session stopped after ``n`` images, through the use-case API (no typer)."""
    result = cut_new_session(NewSessionRequest(cfg, out, lights=LIGHTS), after_step=n - 1)
    assert result.finish_reason is FinishReason.CANCELLED


def killed_resume(out: Path, at_light: int) -> None:
    """``rti-rig run --resume OUT`` SIGKILLed before its ``at_light``-th light (0-based)."""
    env = {**os.environ, "PYTHONPATH": str(REPO)}
    argv = [sys.executable, "-m", "rti_rig.testing.kill_hooks", "before_light", str(at_light)]
    proc = subprocess.run(
        [*argv, "run", "--resume", str(out)], env=env, capture_output=True, timeout=120
    )
    assert proc.returncode == -signal.SIGKILL, proc.stderr.decode()


# 1. A session knows its rig ------------------------------------------------------------------


def test_resume_on_another_rig_is_refused_with_what_differs(
    tmp_path: Path, reference: tuple[Path, Path]
) -> None:
    cfg, _ = reference
    out = tmp_path / "s"
    cancelled_after(cfg, out, 3)
    before = sorted(p.relative_to(out).as_posix() for p in out.rglob("*"))

    r = runner.invoke(app, ["run", str(CONFIGS / "virtual_arm.toml"), "--resume", str(out)])
    assert r.exit_code == 2, r.output
    assert "cannot change kind of rig" in said(r) and f"run --resume {out}" in said(r)
    r = runner.invoke(
        app,
        ["run", str(CONFIGS / "virtual_arm.toml"), "--resume", str(out), "--accept-rig-change"],
    )
    assert r.exit_code == 2 and "cannot change kind of rig" in said(r), r.output
    smaller = write_config(tmp_path, SMALL_DOME.replace("width = 64", "width = 32"), "small.toml")
    for flag in ([], ["--accept-rig-change"]):
        r = runner.invoke(app, ["run", str(smaller), "--resume", str(out), *flag])
        assert r.exit_code == 2 and "camera size: 64×64 → 32×64" in said(r), r.output
        assert "cannot be accepted into this session, even with --accept-rig-change" in said(r)
    # the session's own config, edited since: --resume alone uses it, and sees the edit; a new
    # exposure is no change a session can take (accepted, it went into the fit as a brighter
    # light: normals 5.5° off with a "good" verdict)
    cfg.write_text(SMALL_DOME.replace("exposure_s = 0.05", "exposure_s = 0.04"))
    for flag in ([], ["--accept-rig-change"]):
        r = runner.invoke(app, ["run", "--resume", str(out), *flag])
        assert r.exit_code == 2 and "exposure (s): 0.05 → 0.04" in said(r), r.output
        assert "set it back to continue" in said(r)
    assert sorted(p.relative_to(out).as_posix() for p in out.rglob("*")) == before  # untouched

    # nor another dry-run scene: another object (it had been accepted with the flag)
    cfg.write_text(SMALL_DOME.replace("seed = 3", "seed = 4"))
    for flag in ([], ["--accept-rig-change"]):
        r = runner.invoke(app, ["run", "--resume", str(out), *flag])
        assert r.exit_code == 2 and "simulated scene: changed" in said(r), r.output
        assert "cannot be accepted into this session, even with --accept-rig-change" in said(r)
    assert sorted(p.relative_to(out).as_posix() for p in out.rglob("*")) == before  # untouched

    # a deliberate change to the rest of the rig (here an upper ring re-measured a degree
    # round) goes through with the flag, and is recorded
    cfg.write_text(SMALL_DOME.replace("azimuth_offset_deg = 45.0", "azimuth_offset_deg = 46.0"))
    r = runner.invoke(app, ["run", "--resume", str(out)])
    assert r.exit_code == 2 and "add --accept-rig-change to record it" in said(r), r.output
    r = runner.invoke(app, ["run", "--resume", str(out), "--accept-rig-change"])
    assert r.exit_code == 0, r.output
    run = manifest(out)["runs"][-1]
    assert [d.split(":")[0] for d in run["rig_change"]] == ["light positions"], run


def test_resume_with_the_same_rig_needs_no_flag(
    tmp_path: Path, reference: tuple[Path, Path]
) -> None:
    cfg, ref = reference
    out = tmp_path / "s"
    cancelled_after(cfg, out, 3)
    cfg.write_text(SMALL_DOME + "\n# a comment changes nothing the images depend on\n")
    r = runner.invoke(app, ["run", "--resume", str(out)])
    assert r.exit_code == 0, r.output
    assert digests(out) == digests(ref)


# 2. The journal is repaired before it is appended to ------------------------------------------


def test_torn_journal_and_a_chain_of_killed_resumes_stay_resumable(
    tmp_path: Path, reference: tuple[Path, Path]
) -> None:
    """A kill while a journal line is appended leaves it torn: the line of a step no manifest
    lists (only a run's end writes the steps there), never committed. A journal cut into a
    committed line is damage, not a kill: refused and rebuilt (test_journal_rebuild.py)."""
    cfg, ref = reference
    out = tmp_path / "s"
    cancelled_after(cfg, out, 4)
    journal = out / "journal.jsonl"
    for at_light in (1, 0, 2):  # a line torn by a kill, resume, kill the resume; again and again
        last = journal.read_bytes().splitlines()[-1]
        with open(journal, "ab") as fh:
            fh.write(last.replace(b'"index": 3', b'"index": 4')[:-40])
        killed_resume(out, at_light)
    r = runner.invoke(app, ["run", "--resume", str(out)])
    assert r.exit_code == 0, r.output
    assert digests(out) == digests(ref)
    for line in journal.read_text().splitlines():
        json.loads(line)  # never a record appended onto a torn one
    rejected = list((out / "recovered").rglob("journal-rejected.txt"))
    assert rejected and all("torn last line" in p.read_text() for p in rejected)
    assert manifest(out)["runner"]["finish_reason"] == "completed"


# 3. Every write failure stops the session by name ---------------------------------------------


@pytest.mark.parametrize(
    ("point", "code"),
    [(p, errno.ENOSPC) for p in WRITE_POINTS]
    + [("jpeg", errno.EROFS), ("journal", errno.EIO), ("lp", errno.EIO)],
)
def test_write_failure_stops_by_name_and_resumes(
    tmp_path: Path, reference: tuple[Path, Path], point: str, code: int
) -> None:
    cfg, ref = reference
    out = tmp_path / "s"
    after = 1 if point == "manifest" else 3  # the manifest: begin is written, the end is not
    with failing_writes(point, after=after, errno_code=code) as fault:
        r = runner.invoke(app, ["run", str(cfg), "--out", str(out), "--lights", str(LIGHTS)])
    assert fault.failed >= 1
    assert r.exit_code == 2, r.output
    assert r.exception is None or isinstance(r.exception, SystemExit)
    text = said(r)
    assert f"({errno.errorcode[code]})" in text and "cannot write" in text
    assert "Traceback" not in r.output
    assert f"rti-rig run --resume {out}" in text
    assert leftovers(out) == []
    listed = [e.name for e in read_lp(out / "lights.lp")]
    assert len(listed) >= 3 and all((out / name).is_file() for name in listed)
    if point != "manifest":
        assert manifest(out)["runner"]["finish_reason"] == "write-failed"
        assert errno.errorcode[code] in manifest(out)["runner"]["error"]

    r = runner.invoke(app, ["run", "--resume", str(out)])
    assert r.exit_code == 0, r.output
    assert digests(out) == digests(ref)


@pytest.mark.parametrize(("after", "state"), [(0, "is missing"), (3, "lists only 3 of them")])
def test_a_stop_does_not_say_listed_in_lights_lp_when_its_write_failed(
    tmp_path: Path, reference: tuple[Path, Path], after: int, state: str
) -> None:
    """The image is committed (its journal line), then lights.lp cannot be rewritten (a full
    disk): the stop had said "N image(s) kept …, listed in lights.lp" of a lights.lp that was
    missing, or listed one image fewer than the folder holds."""
    cfg, ref = reference
    out = tmp_path / "s"
    with failing_writes("lp", after=after, errno_code=errno.ENOSPC):
        r = runner.invoke(app, ["run", str(cfg), "--out", str(out), "--lights", str(LIGHTS)])
    assert r.exit_code == 2, r.output
    text = said(r)
    assert f"{after + 1} image(s) kept in {out}" in text
    assert "listed in lights.lp" not in text
    assert f"lights.lp could not be written and {state}" in text
    assert f"rti-rig run --resume {out}" in text
    r = runner.invoke(app, ["run", "--resume", str(out)])
    assert r.exit_code == 0, r.output
    assert digests(out) == digests(ref)


def test_free_space_is_checked_before_each_image(
    tmp_path: Path, reference: tuple[Path, Path], monkeypatch: pytest.MonkeyPatch
) -> None:
    import shutil

    cfg, ref = reference
    real = shutil.disk_usage
    out = tmp_path / "s"

    def usage(path):  # type: ignore[no-untyped-def]
        u = real(path)
        # the start-up checks and three images see room; then the disk is full
        full = out.is_dir() and len(list(out.glob("image_*.jpg"))) >= 3
        return u._replace(free=1_000_000) if full else u

    monkeypatch.setattr(shutil, "disk_usage", usage)
    r = runner.invoke(app, ["run", str(cfg), "--out", str(out), "--lights", str(LIGHTS)])
    assert r.exit_code == 2, r.output
    assert "not enough free disk space" in said(r) and "--resume" in said(r)
    assert manifest(out)["runner"]["finish_reason"] == "no-space"
    assert len(read_lp(out / "lights.lp")) == 3
    monkeypatch.setattr(shutil, "disk_usage", real)
    r = runner.invoke(app, ["run", "--resume", str(out)])
    assert r.exit_code == 0, r.output
    assert digests(out) == digests(ref)


# 4. Junk journal lines -------------------------------------------------------------------------


def test_a_resume_without_its_journal_is_refused_before_anything_moves(
    tmp_path: Path, reference: tuple[Path, Path]
) -> None:
    """An interrupted session whose journal.jsonl was moved away by hand: its resume had moved
    every image to recovered/ ("0 of 8 images verified") and shot them all again without
    saying why. Now it is refused, naming the journal and what to do, the folder unchanged;
    with the journal back the resume keeps every image. A kill before the first journal line
    (files of the first step only) is still resumed as ever."""
    cfg, ref = reference
    out = tmp_path / "s"
    cancelled_after(cfg, out, 3)
    (out / "journal.jsonl").rename(tmp_path / "journal.jsonl")
    # and its step record files (a session from before them; one with them is rebuilt from
    # them: tests/runtime/test_step_records.py)
    (out / "records").rename(tmp_path / "records")
    before = {p: p.read_bytes() for p in out.rglob("*") if p.is_file()}
    r = runner.invoke(app, ["run", "--resume", str(out)])
    assert r.exit_code == 2, r.output
    assert "journal.jsonl is missing" in said(r) and "restore journal.jsonl" in said(r)
    assert {p: p.read_bytes() for p in out.rglob("*") if p.is_file()} == before
    (tmp_path / "journal.jsonl").rename(out / "journal.jsonl")
    (tmp_path / "records").rename(out / "records")
    r = runner.invoke(app, ["run", "--resume", str(out)])
    assert r.exit_code == 0 and "3 of 8 images verified" in said(r), r.output
    assert digests(out) == digests(ref)
    # files of the first step only, and no journal: a kill before its line, resumed as ever
    first = tmp_path / "first"
    cancelled_after(cfg, first, 1)
    (first / "journal.jsonl").unlink()
    shutil.rmtree(first / "records")  # as a kill before the first commit leaves them: none
    killed = manifest(first)  # as a kill leaves it: the manifest begin wrote, with no step
    killed.update(steps=[], runner={"state": "running", "finish_reason": None})
    (first / "manifest.json").write_text(json.dumps(killed))
    r = runner.invoke(app, ["run", "--resume", str(first)])
    assert r.exit_code == 0 and "0 of 8 images verified" in said(r), r.output
    assert digests(first) == digests(ref)


@pytest.mark.parametrize(
    "junk",
    [
        "42",
        "[]",
        '"text"',
        "null",
        '{"index": 1}',
        "not json at all",
        "{}",
    ],
)
def test_junk_journal_lines_are_set_aside(
    tmp_path: Path, reference: tuple[Path, Path], junk: str
) -> None:
    cfg, ref = reference
    out = tmp_path / "s"
    cancelled_after(cfg, out, 4)
    journal = out / "journal.jsonl"
    lines = journal.read_text().splitlines(keepends=True)
    no_checksum = json.loads(lines[2])
    del no_checksum["sha256"]
    # a record without its checksum, beside the step's own (in place of it, the journal has
    # lost a record the manifest holds: refused, test_journal_rebuild.py)
    lines.insert(3, json.dumps(no_checksum) + "\n")
    lines.insert(1, junk + "\n")
    journal.write_text("".join(lines))
    r = runner.invoke(app, ["run", "--resume", str(out)])
    assert r.exit_code == 0, r.output
    assert "4 of 8 images verified" in said(r)
    assert digests(out) == digests(ref)
    (rejected,) = (out / "recovered").rglob("journal-rejected.txt")
    assert "without its checksums" in rejected.read_text() or "sha256" in rejected.read_text()
    assert junk in rejected.read_text()


# 5. lights.lp kept current; export-lp from the verified journal --------------------------------


def test_killed_session_has_its_lp_and_exports(
    tmp_path: Path, reference: tuple[Path, Path]
) -> None:
    from rti_rig.testing.kill_hooks import popen_session

    cfg, ref = reference
    out = tmp_path / "s"
    proc = popen_session("before_light", 3, cfg, out, LIGHTS)
    _, stderr = proc.communicate(timeout=120)
    assert proc.returncode == -signal.SIGKILL, stderr.decode()
    ref_lp = read_lp(ref / "lights.lp")
    assert read_lp(out / "lights.lp") == ref_lp[:3]  # relight can open it at once
    r = runner.invoke(app, ["export-lp", str(out), "--out", str(tmp_path / "k.lp")])
    assert r.exit_code == 0, r.output
    assert read_lp(tmp_path / "k.lp") == ref_lp[:3]


def test_an_image_killed_before_its_journal_line_is_said_to_be_no_part_of_the_session(
    tmp_path: Path, reference: tuple[Path, Path]
) -> None:
    """A kill after image_007's files were written and before its journal line: fit's verdict
    had named image_007 "not checked against its capture checksum" and advised restoring
    journal.jsonl from a backup, of a journal that had lost nothing. It now says what the
    file is (no part of the session, not fitted) and what a resume does with it; a line
    really lost from the journal is still said to be."""
    from rti_rig.testing.kill_hooks import popen_session

    cfg, _ = reference
    out = tmp_path / "s"
    proc = popen_session("before_journal", 6, cfg, out, LIGHTS)
    _, stderr = proc.communicate(timeout=120)
    assert proc.returncode == -signal.SIGKILL, stderr.decode()
    assert (out / "image_007.jpg").is_file()
    r = runner.invoke(app, ["fit", str(out), "--out", str(tmp_path / "fit"), "--model", "ps"])
    assert r.exit_code == 0, r.output
    verdict = json.loads((tmp_path / "fit" / "qa.json").read_text())["verdict"]
    assert "image_007 is on disk without a journal record" in verdict, verdict
    assert "restore journal.jsonl" not in verdict and "not checked" not in verdict, verdict
    lines = (out / "journal.jsonl").read_text().splitlines(keepends=True)
    (out / "journal.jsonl").write_text("".join(lines[:2] + lines[3:]))  # image_003's lost
    (out / "records" / "image_003.json").unlink()  # with its step record file
    r = runner.invoke(app, ["fit", str(out), "--out", str(tmp_path / "fit2"), "--model", "ps"])
    assert r.exit_code == 0, r.output
    verdict = json.loads((tmp_path / "fit2" / "qa.json").read_text())["verdict"]
    assert "image_003 not checked against its capture checksum" in verdict, verdict
    assert "image_007 is on disk without a journal record" in verdict, verdict


def test_a_session_killed_before_its_first_record_is_told_to_resume_not_restore(
    tmp_path: Path, reference: tuple[Path, Path]
) -> None:
    """Killed after image_001's TIFF was written, before any journal line: `fit` had called
    the folder "not a session folder" and `export-lp` advised restoring journal.jsonl from a
    backup, of a journal that never existed. Both now say it stopped before its first record
    and to resume. A session that lost both its lights.lp and its journal is not called "not
    a session folder" either."""
    from rti_rig.testing.kill_hooks import popen_session

    cfg, ref = reference
    out = tmp_path / "s"
    proc = popen_session("between_files", 0, cfg, out, LIGHTS)
    _, stderr = proc.communicate(timeout=120)
    assert proc.returncode == -signal.SIGKILL, stderr.decode()
    assert (out / "linear" / "image_001.tif").is_file() and not (out / "journal.jsonl").exists()
    r = runner.invoke(app, ["fit", str(out), "--out", str(tmp_path / "fit")])
    assert r.exit_code == 2 and "stopped before its first image was recorded" in said(r), r.output
    assert f"rti-rig run --resume {out}" in said(r)
    r = runner.invoke(app, ["export-lp", str(out), "--out", str(tmp_path / "x.lp")])
    assert r.exit_code == 2 and "stopped before its first image was recorded" in said(r), r.output
    assert "backup" not in said(r)
    done = copied(ref, tmp_path)
    (done / "journal.jsonl").unlink()
    (done / "lights.lp").unlink()
    r = runner.invoke(app, ["fit", str(done), "--out", str(tmp_path / "fit2")])
    assert r.exit_code == 2, r.output
    assert "a session folder without its lights.lp and journal.jsonl" in said(r), r.output


def test_a_resume_after_a_kill_says_its_time_is_a_lower_bound(
    tmp_path: Path, reference: tuple[Path, Path]
) -> None:
    """A run killed outright records no time; the resumed session's time line had summed the
    runs that did (12.9 s "over 2 runs" for a session of 56 s) as if that were all of it."""
    import re

    from rti_rig.testing.kill_hooks import popen_session

    cfg, ref = reference
    out = tmp_path / "s"
    proc = popen_session("before_light", 5, cfg, out, LIGHTS)
    _, stderr = proc.communicate(timeout=120)
    assert proc.returncode == -signal.SIGKILL, stderr.decode()
    r = runner.invoke(app, ["run", "--resume", str(out)])
    assert r.exit_code == 0, r.output
    line = re.search(r"Session time on the real rig: at least ([0-9.]+) s", said(r))
    assert line, said(r)
    assert (
        "1 run(s) killed, powered off or out of disk before recording their time, counted "
        "from their images" in said(r)
    ), said(r)
    # the killed run's images are counted from the journal: the whole session's time, not
    # the resumed run's alone (the same session uninterrupted is the yardstick)
    whole = manifest(ref)["timing"]["rig_time_s"]
    assert 0.85 * whole <= float(line.group(1)) <= whole + 0.05, (line.group(1), whole)


def test_export_leaves_out_an_image_deleted_since(
    tmp_path: Path, reference: tuple[Path, Path]
) -> None:
    _, ref = reference
    done = copied(ref, tmp_path)
    (done / "image_002.jpg").unlink()
    r = runner.invoke(app, ["export-lp", str(done), "--out", str(tmp_path / "x.lp")])
    assert r.exit_code == 0, r.output
    names = [e.name for e in read_lp(tmp_path / "x.lp")]
    assert "image_002.jpg" not in names and len(names) == LIGHTS - 1
    assert "image_002.jpg" in said(r)


def test_export_names_only_the_file_kind_it_lists(
    tmp_path: Path, reference: tuple[Path, Path]
) -> None:
    """An .lp of the TIFFs keeps an image whose JPEG is gone (its linear TIFF is intact), and
    an .lp of the JPEGs one whose TIFF is damaged: each is judged by the file it names (a
    lost JPEG had dropped its intact TIFF from the --linear listing)."""
    _, ref = reference
    done = copied(ref, tmp_path)
    (done / "image_002.jpg").unlink()
    (done / "linear" / "image_003.tif").write_bytes(b"damaged")
    r = runner.invoke(app, ["export-lp", str(done), "--out", str(done / "t.lp"), "--linear"])
    assert r.exit_code == 0, r.output
    names = [e.name for e in read_lp(done / "t.lp")]
    assert "linear/image_002.tif" in names and "linear/image_003.tif" not in names
    assert len(names) == LIGHTS - 1 and "linear/image_003.tif" in said(r)
    r = runner.invoke(app, ["export-lp", str(done), "--out", str(done / "j.lp")])
    assert r.exit_code == 0, r.output
    names = [e.name for e in read_lp(done / "j.lp")]
    assert "image_003.jpg" in names and "image_002.jpg" not in names
    assert len(names) == LIGHTS - 1 and "image_002.jpg" in said(r)


def test_an_image_lost_since_capture_is_named_by_qa_and_reshot_on_request(
    tmp_path: Path, reference: tuple[Path, Path]
) -> None:
    """A finished session whose JPEG was deleted, or truncated, since capture: QA had said
    "good" (fit reads the intact TIFFs) while lights.lp still listed the JPEG, so relight
    paired every later image with the wrong light, and `run --resume` could not repair it.
    Now the verdict names the images, a plain resume still refuses a completed session but
    names them and the command, and `--reshoot-lost` reshoots exactly those, setting aside
    their surviving files."""
    _, ref = reference
    done = copied(ref, tmp_path)
    (done / "image_003.jpg").unlink()
    jpg = done / "image_006.jpg"
    jpg.write_bytes(jpg.read_bytes()[:2000])
    r = runner.invoke(app, ["fit", str(done), "--out", str(tmp_path / "fit"), "--model", "ps"])
    assert r.exit_code == 0, r.output
    verdict = json.loads((tmp_path / "fit" / "qa.json").read_text())["verdict"]
    assert verdict.startswith("reshoot: image_003 (image_003.jpg missing since capture"), verdict
    assert "lights.lp still lists it, so relight" in verdict
    assert "image_006 (image_006.jpg changed since capture)" in verdict
    # the advice once for both (it had followed each image: 48 times for a lost linear/)
    assert "2 images missing or changed since capture (image_003, image_006): put the " in verdict
    assert verdict.count("put the originals back") == 1
    assert f"rti-rig run --resume {done} --reshoot-lost" in verdict
    before = {p: p.read_bytes() for p in done.rglob("*") if p.is_file()}
    r = runner.invoke(app, ["run", "--resume", str(done)])
    assert r.exit_code == 2, r.output
    assert "already completed" in said(r) and "image_003, image_006" in said(r)
    assert f"rti-rig run --resume {done} --reshoot-lost" in said(r)
    assert {p: p.read_bytes() for p in done.rglob("*") if p.is_file()} == before
    tif = (done / "linear" / "image_003.tif").read_bytes()
    r = runner.invoke(app, ["run", "--resume", str(done), "--reshoot-lost"])
    assert r.exit_code == 0, r.output
    assert "2 of 8 lights" in said(r) and "QA verdict: good" in said(r)
    assert digests(done) == digests(ref)  # a dry run reshoots the very same images
    # nothing captured is lost: the intact TIFF of the deleted JPEG and the truncated JPEG
    kept = {p.name: p.read_bytes() for p in (done / "recovered").rglob("image_*")}
    assert kept["image_003.tif"] == tif and len(kept["image_006.jpg"]) == 2000


def test_images_renamed_in_the_folder_are_named_as_renamed_not_lost(
    tmp_path: Path, reference: tuple[Path, Path]
) -> None:
    """A finished session whose JPEGs a user renamed to the collection's numbering
    (``coin17_001.jpg`` for ``image_001.jpg``): every image had been called missing — the
    verdict said reshoot them all, ``--reshoot-lost`` would have, ``export-lp`` found "none of
    the 8 journaled image(s) on disk". Each is named with its new name and the advice is to
    give it back its name; one really deleted is still lost, and said so."""
    _, ref = reference
    done = copied(ref, tmp_path)
    for jpg in sorted(done.glob("image_*.jpg")):
        jpg.rename(done / f"coin17_{jpg.name.removeprefix('image_')}")
    (done / "coin17_008.jpg").unlink()  # this one is really gone
    r = runner.invoke(app, ["export-lp", str(done), "--out", str(tmp_path / "x.lp")])
    assert r.exit_code == 2, r.output
    assert "image_001.jpg as coin17_001.jpg" in said(r) and "need no reshooting" in said(r)
    assert "image_008.jpg as" not in said(r)
    r = runner.invoke(app, ["fit", str(done), "--out", str(tmp_path / "fit"), "--model", "ps"])
    assert r.exit_code == 0, r.output
    verdict = json.loads((tmp_path / "fit" / "qa.json").read_text())["verdict"]
    assert verdict.startswith("reshoot: image_008 (image_008.jpg missing since capture"), verdict
    assert "image_001 (" not in verdict and "image_002.jpg as coin17_002.jpg" in verdict
    before = {p: p.read_bytes() for p in done.rglob("*") if p.is_file()}
    r = runner.invoke(app, ["run", "--resume", str(done)])
    assert r.exit_code == 2 and "image_008" in said(r) and "as coin17_003.jpg" in said(r)
    assert {p: p.read_bytes() for p in done.rglob("*") if p.is_file()} == before
    # put back under its name, one is listed again; the others are still named as renamed
    (done / "coin17_003.jpg").rename(done / "image_003.jpg")
    r = runner.invoke(app, ["export-lp", str(done), "--out", str(tmp_path / "y.lp")])
    assert r.exit_code == 0, r.output
    assert [e.name for e in read_lp(tmp_path / "y.lp")] == ["image_003.jpg"]
    assert "image_004.jpg as coin17_004.jpg" in said(r)


def test_tiffs_renamed_in_linear_are_named_as_renamed_not_lost(
    tmp_path: Path, reference: tuple[Path, Path]
) -> None:
    """The TIFFs renamed in linear/ to a collection's numbering, like their JPEGs: only the
    JPEGs were looked for under other names, so the TIFFs were called missing, the verdict
    said "reshoot" and --reshoot-lost reshot them, setting files that were there aside. Now
    they are named as renamed, nothing is reshot, and a fit says to give the names back."""
    _, ref = reference
    done = copied(ref, tmp_path)
    (done / "linear" / "image_005.tif").rename(done / "linear" / "coin17_005.tif")
    r = runner.invoke(app, ["fit", str(done), "--out", str(tmp_path / "fit"), "--model", "ps"])
    assert r.exit_code == 0, r.output
    verdict = json.loads((tmp_path / "fit" / "qa.json").read_text())["verdict"]
    assert verdict.startswith("good") and "reshoot" not in verdict.split(";")[0], verdict
    assert "linear/image_005.tif as linear/coin17_005.tif" in verdict
    (done / "image_003.jpg").rename(done / "coin17_003.jpg")
    (done / "linear" / "image_003.tif").rename(done / "linear" / "coin17_003.tif")
    r = runner.invoke(app, ["fit", str(done), "--out", str(tmp_path / "fit2"), "--model", "ps"])
    assert r.exit_code == 2, r.output
    assert "lists are not under their session names" in said(r), said(r)
    assert "linear/image_003.tif as linear/coin17_003.tif" in said(r)
    assert "--reshoot-lost" not in said(r)
    before = {p: p.read_bytes() for p in done.rglob("*") if p.is_file()}
    r = runner.invoke(app, ["run", "--resume", str(done), "--reshoot-lost"])
    assert r.exit_code == 2 and "nothing to reshoot" in said(r), r.output
    assert {p: p.read_bytes() for p in done.rglob("*") if p.is_file()} == before


def test_a_finished_session_is_not_reshot_for_a_rewritten_tiff(
    tmp_path: Path, reference: tuple[Path, Path]
) -> None:
    """A TIFF rewritten by another tool with the very pixels captured: the images stand, the
    verdict is good, and --reshoot-lost finds nothing to reshoot (a review found it made a
    completed session reshoot every image, its intact files moved aside)."""
    import tifffile

    _, ref = reference
    done = copied(ref, tmp_path)
    tif = done / "linear" / "image_004.tif"
    tifffile.imwrite(tif, tifffile.imread(tif), description="re-saved")
    r = runner.invoke(app, ["fit", str(done), "--out", str(tmp_path / "fit"), "--model", "ps"])
    assert r.exit_code == 0, r.output
    assert json.loads((tmp_path / "fit" / "qa.json").read_text())["verdict"] == "good"
    before = {p: p.read_bytes() for p in done.rglob("*") if p.is_file()}
    r = runner.invoke(app, ["run", "--resume", str(done), "--reshoot-lost"])
    assert r.exit_code == 2, r.output
    assert "nothing to reshoot" in said(r) and "missing or changed" not in said(r), said(r)
    assert {p: p.read_bytes() for p in done.rglob("*") if p.is_file()} == before


def _with_raw_originals(done: Path) -> dict[str, bytes]:
    """Session ``done`` made a DSLR session's: each step keeps the camera's file under raw/,
    its checksum and camera name in the journal and the manifest's records. Returns them."""
    records = [json.loads(line) for line in (done / "journal.jsonl").read_text().splitlines()]
    (done / "raw").mkdir()
    bodies = {}
    for rec in records:
        raw = f"raw/{Path(rec['image']).stem}.dng"
        body = f"camera file {rec['index']}".encode()
        (done / raw).write_bytes(body)
        bodies[raw] = body
        rec["sha256"][raw] = hashlib.sha256(body).hexdigest()
        rec.setdefault("originals", {})[raw] = f"IMG_{rec['index']:04d}.DNG"
    (done / "journal.jsonl").write_text("".join(json.dumps(r) + "\n" for r in records))
    for rec in records:  # each step's record file holds its journal line, as at capture
        step_file = done / "records" / f"{Path(rec['image']).stem}.json"
        if step_file.parent.is_dir():
            step_file.write_text(json.dumps(rec) + "\n")
    m = manifest(done)
    by_step = {r["index"]: r for r in records}
    m["steps"] = [by_step.get(s["index"], s) for s in m["steps"]]
    (done / "manifest.json").write_text(json.dumps(m))
    return bodies


def test_a_missing_raw_original_is_a_lost_image_said_alike_and_reshot_on_request(
    tmp_path: Path, reference: tuple[Path, Path]
) -> None:
    """The RAW is the original capture: raw/image_003.dng gone from a finished session. The
    verdict had said "good" and --reshoot-lost "nothing to reshoot", while a rebuild of its
    journal called the image unproven and advised --reshoot-lost, which then refused. Now the
    verdict names the RAW as lost (its developed images fitted), a plain resume names it,
    and --reshoot-lost shoots exactly that step again, its developed files set aside."""
    _, ref = reference
    done = copied(ref, tmp_path)
    _with_raw_originals(done)
    (done / "raw" / "image_003.dng").unlink()
    r = runner.invoke(app, ["fit", str(done), "--out", str(tmp_path / "fit"), "--model", "ps"])
    assert r.exit_code == 0, r.output
    verdict = json.loads((tmp_path / "fit" / "qa.json").read_text())["verdict"]
    assert verdict.startswith(
        "reshoot: image_003 (raw/image_003.dng missing since capture: the "
        "camera's original capture is lost, its developed JPEG and linear "
        "TIFF are as captured and were fitted"
    ), verdict
    assert f"rti-rig run --resume {done} --reshoot-lost" in verdict
    r = runner.invoke(app, ["run", "--resume", str(done)])
    assert r.exit_code == 2 and "missing or changed since capture (image_003)" in said(r), r.output
    jpeg = (done / "image_003.jpg").read_bytes()
    r = runner.invoke(app, ["run", "--resume", str(done), "--reshoot-lost"])
    assert r.exit_code == 0, r.output
    (aside,) = (done / "recovered").iterdir()
    assert (aside / "image_003.jpg").read_bytes() == jpeg  # set aside, not overwritten
    assert sorted(p.relative_to(aside).as_posix() for p in aside.rglob("*") if p.is_file()) == [
        "image_003.jpg",
        "linear/image_003.tif",
    ]
    journal = [json.loads(line) for line in (done / "journal.jsonl").read_text().splitlines()]
    assert [e["index"] for e in journal] == [*range(LIGHTS), 2]


def test_a_linear_tiff_edited_since_capture_is_named_and_reshot_on_request(
    tmp_path: Path, reference: tuple[Path, Path]
) -> None:
    """A colleague opened linear/image_005.tif in an editor, touched a few pixels and saved it:
    `fit` fitted the edited pixels and said "good" (only the JPEGs were checked against their
    checksums, the TIFFs for their presence). Now the verdict names the TIFF, --reshoot-lost
    reshoots exactly that step (the edited file set aside, never deleted), while a TIFF
    re-saved with the very pixels captured still counts as intact (its pixel checksum)."""
    import tifffile

    _, ref = reference
    done = copied(ref, tmp_path)
    edited = done / "linear" / "image_005.tif"
    pixels = tifffile.imread(edited)
    pixels[10:14, 10:14] = 0  # a retouch: small enough that the QA's pixel checks cannot see it
    tifffile.imwrite(edited, pixels, photometric="rgb")
    resaved = done / "linear" / "image_002.tif"
    tifffile.imwrite(resaved, tifffile.imread(resaved), photometric="rgb", description="DAM tag")
    r = runner.invoke(app, ["fit", str(done), "--out", str(tmp_path / "fit"), "--model", "ps"])
    assert r.exit_code == 0, r.output
    verdict = json.loads((tmp_path / "fit" / "qa.json").read_text())["verdict"]
    assert verdict.startswith("reshoot: image_005 (linear/image_005.tif changed since capture")
    assert "image_002" not in verdict, verdict
    # export-lp --linear judges them alike (it had left the re-saved TIFF out too)
    r = runner.invoke(app, ["export-lp", str(done), "--linear", "--out", str(tmp_path / "x.lp")])
    assert r.exit_code == 0, r.output
    names = [e.name for e in read_lp(tmp_path / "x.lp")]
    assert "linear/image_002.tif" in names and "linear/image_005.tif" not in names, names
    r = runner.invoke(app, ["run", "--resume", str(done), "--reshoot-lost"])
    assert r.exit_code == 0, r.output
    assert "7 of 8 images verified" in said(r) and "QA verdict: good" in said(r), said(r)
    kept = {p.name: p.read_bytes() for p in (done / "recovered").rglob("image_*")}
    assert set(kept) == {"image_005.tif", "image_005.jpg"}
    assert tifffile.imread(io.BytesIO(kept["image_005.tif"]))[10, 10].tolist() == [0, 0, 0]


def test_an_lp_of_the_users_own_in_a_session_is_checked_for_the_images_it_lists(
    tmp_path: Path, reference: tuple[Path, Path]
) -> None:
    """`rti-rig fit S/mine.lp` (an .lp the user exported or edited beside the session's
    images) had no integrity check at all: a TIFF edited since capture was fitted and judged
    "good". Its images are now checked as lights.lp's are, and only those: an image it leaves
    out (lost, and left out on purpose) is not held against it."""
    import tifffile

    _, ref = reference
    done = copied(ref, tmp_path)
    edited = done / "linear" / "image_005.tif"
    pixels = tifffile.imread(edited)
    pixels[10:14, 10:14] = 0
    tifffile.imwrite(edited, pixels, photometric="rgb")
    (done / "image_003.jpg").unlink()
    lines = (done / "lights.lp").read_text().splitlines()
    kept = [line for line in lines[1:] if not line.startswith("image_003")]
    (done / "mine.lp").write_text("\n".join([str(len(kept)), *kept]) + "\n")
    out = tmp_path / "fit"
    r = runner.invoke(app, ["fit", str(done / "mine.lp"), "--out", str(out), "--model", "ps"])
    assert r.exit_code == 0, r.output
    verdict = json.loads((out / "qa.json").read_text())["verdict"]
    assert verdict.startswith("reshoot: image_005 (linear/image_005.tif changed since capture")
    assert "image_003" not in verdict, verdict


def test_an_image_lost_and_left_out_of_the_lp_fitted_is_still_named(
    tmp_path: Path, reference: tuple[Path, Path]
) -> None:
    """image_003.jpg deleted, lights.lp written again from the journal (export-lp leaves the
    lost image out): `fit S` judged the 7 images listed and said "good", of a session that
    lost one. The lost image is now named, as not fitted; and a session folder without its
    lights.lp, fitted from another .lp in it, is said to be."""
    _, ref = reference
    done = copied(ref, tmp_path)
    (done / "image_003.jpg").unlink()
    (done / "linear" / "image_003.tif").unlink()
    r = runner.invoke(app, ["export-lp", str(done), "--out", str(tmp_path / "x.lp")])
    assert r.exit_code == 0, r.output
    (done / "lights.lp").unlink()
    (tmp_path / "x.lp").rename(done / "rest.lp")
    r = runner.invoke(app, ["fit", str(done), "--out", str(tmp_path / "fit"), "--model", "ps"])
    assert r.exit_code == 0, r.output
    assert f"{done} is a session folder without its lights.lp: fitted from its rest.lp" in said(r)
    verdict = json.loads((tmp_path / "fit" / "qa.json").read_text())["verdict"]
    assert "1 image missing or changed since capture (image_003; image_003 not in rest.lp, so" in (
        verdict
    ), verdict
    (done / "rest.lp").rename(done / "lights.lp")
    r = runner.invoke(app, ["fit", str(done), "--out", str(tmp_path / "fit2"), "--model", "ps"])
    assert r.exit_code == 0, r.output
    assert "without its lights.lp" not in said(r)
    verdict = json.loads((tmp_path / "fit2" / "qa.json").read_text())["verdict"]
    assert "image_003 not in lights.lp, so not fitted" in verdict, verdict


def test_a_session_journaled_before_pixel_checksums_is_checked_by_bytes_and_says_so(
    tmp_path: Path, reference: tuple[Path, Path]
) -> None:
    """A session written before the TIFFs' pixel checksums (its journal has only the files'):
    still fitted and checked, its edited TIFF named, with one note saying why a mere re-save
    would be named too (not once per image, and no refusal)."""
    import tifffile

    _, ref = reference
    done = copied(ref, tmp_path)
    records = [json.loads(line) for line in (done / "journal.jsonl").read_text().splitlines()]
    for rec in records:
        rec.pop("pixels_sha256", None)
    (done / "journal.jsonl").write_text("".join(json.dumps(r) + "\n" for r in records))
    r = runner.invoke(app, ["fit", str(done), "--out", str(tmp_path / "fit0"), "--model", "ps"])
    assert r.exit_code == 0, r.output
    qa = json.loads((tmp_path / "fit0" / "qa.json").read_text())
    assert qa["verdict"] == "good" and "predates" not in json.dumps(qa)
    for name in ("image_003.tif", "image_007.tif"):
        tif = done / "linear" / name
        tifffile.imwrite(tif, tifffile.imread(tif) // 2, photometric="rgb")
    r = runner.invoke(app, ["fit", str(done), "--out", str(tmp_path / "fit"), "--model", "ps"])
    assert r.exit_code == 0, r.output
    out = said(r)
    assert "linear/image_003.tif changed since capture" in out
    assert "linear/image_007.tif changed since capture" in out
    assert out.count("predates pixel checksums") == 1, out


def test_a_fit_of_a_session_whose_images_are_gone_names_them_all_and_the_way_out(
    tmp_path: Path, reference: tuple[Path, Path]
) -> None:
    """Both files of two steps deleted by hand: the fit stopped at the first with "image
    .../image_004.jpg listed in .../lights.lp is missing (an .lp's image names are read relative
    to its own folder)", neither naming the other nor what a session can do. Now it names both
    and the ways out, and the .lp it points to fits the images that remain."""
    _, ref = reference
    done = copied(ref, tmp_path)
    for stem in ("image_004", "image_006"):
        (done / f"{stem}.jpg").unlink()
        (done / "linear" / f"{stem}.tif").unlink()
    # a rest.lp an earlier export left, which export-lp refuses to overwrite: the .lp named is
    # one that is not there yet
    (done / "rest.lp").write_bytes(b"an earlier export")
    r = runner.invoke(app, ["fit", str(done), "--out", str(tmp_path / "fit"), "--model", "ps"])
    assert r.exit_code == 2, r.output
    out = said(r)
    assert "2 image(s) its lights.lp lists cannot be read as captured" in out
    assert "(image_004: neither its JPEG nor its linear TIFF on disk; image_006: neither" in out
    assert f"rti-rig run --resume {done} --reshoot-lost" in out
    rest = done / "rest-2.lp"
    assert f"rti-rig export-lp {done} --linear --out {rest}" in out
    # the fit's --out a folder beside the session that is not there yet (DIR had been said)
    fit_out = done.with_name(f"{done.name}-fit")
    assert f"then rti-rig fit {rest} --out {fit_out}" in out, out
    _fit_the_rest(done, fit_out, rest)
    assert (done / "rest.lp").read_bytes() == b"an earlier export"


def _fitted_from_its_jpeg(done: Path, out: Path, stem: str) -> str:
    """Fit session ``done`` whose ``linear/<stem>.tif`` is damaged: as for a TIFF missing, the
    fit reads the image's JPEG instead, says so, and the verdict names the TIFF changed since
    capture with the session's ways out. Returns what was said."""
    r = runner.invoke(app, ["fit", str(done), "--out", str(out), "--model", "ps"])
    assert r.exit_code == 0, r.output
    text = said(r)
    assert (
        f"1 of {LIGHTS} image(s) have no readable linear/ TIFF and were read from their 8-bit "
        f"file instead ({stem}.jpg)"
    ) in text, text
    assert f"reshoot: {stem} (linear/{stem}.tif changed since capture" in text, text
    assert f"rti-rig run --resume {done} --reshoot-lost" in text, text
    assert "leave it out of the .lp" not in text and "Traceback" not in text, text
    return text


def test_a_linear_tiff_overwritten_whole_is_named_with_the_sessions_ways_out(
    tmp_path: Path, reference: tuple[Path, Path]
) -> None:
    """A linear TIFF overwritten by other bytes of its own length: the decoder's refusal had
    said "cannot be read as a TIFF (TiffFileError …); … or leave it out of the .lp", an edit
    of the session's lights.lp, not its ways out; then the whole fit was refused for it, where
    a TIFF missing is read from its JPEG. Now it is read as a missing one is."""
    _, ref = reference
    done = copied(ref, tmp_path)
    tif = done / "linear" / "image_005.tif"
    tif.write_bytes(bytes(range(256)) * (tif.stat().st_size // 256 + 1))
    _fitted_from_its_jpeg(done, tmp_path / "fit", "image_005")


def test_a_camera_original_changed_since_capture_is_lost_said_alike_and_reshot_on_request(
    tmp_path: Path, reference: tuple[Path, Path]
) -> None:
    """A kept DNG into which a raw editor wrote its metadata: the captured original is no
    longer there. The verdict had called it "good" (restore it from a backup, no reshoot) and
    --reshoot-lost "nothing to reshoot", while a rebuilt journal recorded it as lost and a
    resume of a session not finished shot it again. Now every path calls it lost in the same
    words, with the same remedies, and --reshoot-lost shoots it again, its files kept."""
    _, ref = reference
    done = copied(ref, tmp_path)
    _with_raw_originals(done)
    edited = b"camera file 4 + XMP written by an editor"
    (done / "raw" / "image_005.dng").write_bytes(edited)
    words = (
        "image_005 (raw/image_005.dng changed since capture: the camera's original capture is "
        "lost, its developed JPEG and linear TIFF are as captured and were fitted; put the "
        "originals back from a copy, or reshoot exactly those, with the object where it was: "
        f"rti-rig run --resume {done} --reshoot-lost"
    )
    r = runner.invoke(app, ["fit", str(done), "--out", str(tmp_path / "fit"), "--model", "ps"])
    assert r.exit_code == 0, r.output
    verdict = json.loads((tmp_path / "fit" / "qa.json").read_text())["verdict"]
    assert verdict.startswith(f"reshoot: {words}"), verdict
    r = runner.invoke(app, ["export-lp", str(done), "--out", str(tmp_path / "x.lp")])
    assert r.exit_code == 0, r.output
    assert "raw/image_005.dng changed since capture: the camera's original capture" in said(r)
    r = runner.invoke(app, ["run", "--resume", str(done)])
    assert r.exit_code == 2 and "missing or changed since capture (image_005)" in said(r), r.output
    assert f"rti-rig run --resume {done} --reshoot-lost" in said(r)
    r = runner.invoke(app, ["run", "--resume", str(done), "--reshoot-lost", "--no-verdict"])
    assert r.exit_code == 0, r.output
    assert "1 of 8 light" in said(r)
    (aside,) = (done / "recovered").iterdir()
    assert (aside / "raw" / "image_005.dng").read_bytes() == edited  # set aside, never deleted


def test_a_camera_original_changed_in_a_session_not_finished_is_said_and_shot_again(
    tmp_path: Path, reference: tuple[Path, Path]
) -> None:
    """The resume of a session not finished shoots again what it cannot verify (the object is
    still in place): it had said only "N unverified file(s) moved" of a DNG a raw editor had
    written into. It now names it in the verdict's words, kept in recovered/."""
    _, ref = reference
    done = copied(ref, tmp_path)
    _with_raw_originals(done)
    m = manifest(done)
    m["runner"]["finish_reason"] = "cancelled"
    (done / "manifest.json").write_text(json.dumps(m))
    edited = b"camera file 2 + XMP written by an editor"
    (done / "raw" / "image_003.dng").write_bytes(edited)
    r = runner.invoke(app, ["fit", str(done), "--out", str(tmp_path / "fit"), "--model", "ps"])
    verdict = json.loads((tmp_path / "fit" / "qa.json").read_text())["verdict"]
    assert "image_003 (raw/image_003.dng changed since capture: the camera's original" in verdict
    assert "or let its resume set them aside and shoot them again, with the object" in verdict
    r = runner.invoke(app, ["run", "--resume", str(done), "--no-verdict"])
    assert r.exit_code == 0, r.output
    assert (
        "1 image(s) lost since capture (image_003: raw/image_003.dng changed): what was "
        "captured is no longer there; what is left of them set aside in recovered/"
    ) in said(r), said(r)
    (aside,) = (done / "recovered").iterdir()
    assert (aside / "raw" / "image_003.dng").read_bytes() == edited
    assert manifest(done)["runs"][-1]["lost_since_capture"] == [
        "image_003: raw/image_003.dng changed"
    ]


def test_a_fit_of_a_session_with_a_tiff_cut_short_names_it_before_fitting(
    tmp_path: Path, reference: tuple[Path, Path]
) -> None:
    """linear/image_007.tif cut short by an interrupted copy: the fit stopped part-way at a
    short read, told to "leave it out of the .lp" (of a session, whose lights.lp it rewrites);
    then it was refused whole, while a TIFF missing is read from its JPEG. Now the cut one is
    read as a missing one is, and the verdict names it with the session's ways out."""
    _, ref = reference
    done = copied(ref, tmp_path)
    tif = done / "linear" / "image_007.tif"
    tif.write_bytes(tif.read_bytes()[:5000])
    _fitted_from_its_jpeg(done, tmp_path / "fit", "image_007")


def test_a_session_copied_without_its_linear_folder_says_its_jpegs_stood_in(
    tmp_path: Path, reference: tuple[Path, Path]
) -> None:
    """A session copied without linear/ (left behind to save space): the fit read the 8-bit
    JPEGs for every image without a word (the stand-in note was for a session missing some
    TIFFs, not all), while a session journals a linear TIFF for each."""
    import shutil

    _, ref = reference
    done = copied(ref, tmp_path)
    shutil.rmtree(done / "linear")
    r = runner.invoke(app, ["fit", str(done), "--out", str(tmp_path / "fit"), "--model", "ps"])
    assert r.exit_code == 0, r.output
    assert f"{LIGHTS} of {LIGHTS} image(s) have no readable linear/ TIFF and were read" in said(r)
    notes = json.loads((tmp_path / "fit" / "fit.json").read_text())["input_notes"]
    assert any("read from their 8-bit file instead" in n for n in notes), notes


def test_a_session_without_its_lights_lp_is_told_how_to_rebuild_it(
    tmp_path: Path, reference: tuple[Path, Path]
) -> None:
    """fit on a session whose lights.lp was deleted had said "not a session folder"; it names
    the export-lp command that rebuilds it from the journal, and that command works."""
    _, ref = reference
    done = copied(ref, tmp_path)
    (done / "lights.lp").unlink()
    r = runner.invoke(app, ["fit", str(done), "--out", str(tmp_path / "fit")])
    assert r.exit_code == 2, r.output
    command = f"rti-rig export-lp {done} --out {done / 'lights.lp'}"
    assert command in said(r), said(r)
    r = runner.invoke(app, command.split()[1:])
    assert r.exit_code == 0, r.output
    assert read_lp(done / "lights.lp") == read_lp(ref / "lights.lp")


# 6. Nothing on disk before the rig works ------------------------------------------------------


def test_unreachable_rig_creates_nothing_and_promises_no_resume(
    tmp_path: Path, reference: tuple[Path, Path], monkeypatch: pytest.MonkeyPatch
) -> None:
    from rti_rig.core.errors import DeviceError
    from rti_rig.simulator.sim_lights import SimulatedDome

    cfg, _ = reference

    def unreachable(self) -> None:  # type: ignore[no-untyped-def]
        raise DeviceError("dome on /dev/ttyACM0", "no answer to the handshake")

    monkeypatch.setattr(SimulatedDome, "connect", unreachable)
    out = tmp_path / "s"
    r = runner.invoke(app, ["run", str(cfg), "--out", str(out), "--lights", str(LIGHTS)])
    assert r.exit_code == 2, r.output
    assert "no answer to the handshake" in said(r)
    assert not out.exists()
    assert "--resume" not in said(r) and "images kept" not in said(r).lower()


def test_no_space_at_start_creates_nothing(
    tmp_path: Path, reference: tuple[Path, Path], monkeypatch: pytest.MonkeyPatch
) -> None:
    import shutil

    cfg, _ = reference
    usage = shutil.disk_usage(tmp_path)
    monkeypatch.setattr(shutil, "disk_usage", lambda _p: usage._replace(free=1_000_000))
    out = tmp_path / "s"
    r = runner.invoke(app, ["run", str(cfg), "--out", str(out), "--lights", str(LIGHTS)])
    assert r.exit_code == 2 and "not enough free disk space" in said(r), r.output
    assert not out.exists()
    assert "--resume" not in said(r)


def test_a_folder_holding_no_image_may_be_reused(
    tmp_path: Path, reference: tuple[Path, Path]
) -> None:
    cfg, ref = reference
    out = tmp_path / "s"
    with failing_writes("tiff", after=0):  # the first image cannot be written
        r = runner.invoke(app, ["run", str(cfg), "--out", str(out), "--lights", str(LIGHTS)])
    assert r.exit_code == 2, r.output
    assert "--resume" not in said(r) and "may be used again" in said(r)
    assert out.is_dir()
    r = runner.invoke(app, ["run", str(cfg), "--out", str(out), "--lights", str(LIGHTS)])
    assert r.exit_code == 0, r.output
    assert digests(out) == digests(ref)


def test_a_new_folder_a_file_browser_opened_is_not_refused_as_not_empty(
    tmp_path: Path, reference: tuple[Path, Path]
) -> None:
    """A folder made for the session in Finder or Explorer holds .DS_Store or Thumbs.db before
    any image: `run --out` had refused it ("not empty: refusing to write a session over
    existing files"). They are left as they are; any other file still refuses the folder."""
    cfg, ref = reference
    out = tmp_path / "s"
    out.mkdir()
    (out / ".DS_Store").write_bytes(b"\0\0\0\1Bud1")
    (out / "Thumbs.db").write_bytes(b"thumbs")
    r = runner.invoke(app, ["run", str(cfg), "--out", str(out), "--lights", str(LIGHTS)])
    assert r.exit_code == 0, r.output
    assert digests(out) == digests(ref) and (out / ".DS_Store").is_file()
    other = tmp_path / "t"
    other.mkdir()
    (other / ".DS_Store").write_bytes(b"x")
    (other / "notes.txt").write_text("object 17")
    r = runner.invoke(app, ["run", str(cfg), "--out", str(other), "--lights", str(LIGHTS)])
    assert r.exit_code == 2 and "is not empty" in said(r), r.output


# 7. Counts and caps before any layout is built -------------------------------------------------


@pytest.mark.parametrize(
    "config", ["virtual_arm.toml", "simulated_arm.toml", "example_dome_48.toml"]
)
def test_light_cap_is_checked_before_any_layout(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, config: str
) -> None:
    import rti_rig.planner.uniform as uniform

    def no_layout(*_a, **_k):  # type: ignore[no-untyped-def]
        raise AssertionError("a layout was built before the light count was checked")

    monkeypatch.setattr(uniform, "plan_uniform", no_layout)
    out = tmp_path / "s"
    r = runner.invoke(app, ["run", str(CONFIGS / config), "--out", str(out), "--lights", "1000000"])
    assert r.exit_code == 2, r.output
    assert "at most 1000 lights" in said(r)
    assert not out.exists()


def test_plan_with_too_many_lights_is_refused_before_it_is_matched(tmp_path: Path) -> None:
    from rti_rig.core.geometry import direction_from_az_el

    plan = tmp_path / "big.lp"
    lines = [f"{1001}"]
    for i in range(1001):
        d = direction_from_az_el(i * 0.35, 20 + (i % 50))
        lines.append(f"l{i}.jpg {d[0]:.6f} {d[1]:.6f} {d[2]:.6f}")
    plan.write_text("\n".join(lines) + "\n")
    r = runner.invoke(
        app,
        [
            "run",
            str(CONFIGS / "virtual_arm.toml"),
            "--out",
            str(tmp_path / "s"),
            "--plan",
            str(plan),
        ],
    )
    assert r.exit_code == 2, r.output
    assert "1000" in said(r)


def test_the_journal_time_counts_a_killed_run_of_one_image() -> None:
    """Each run's first image starts at 0.0 on its clock: a killed run that journaled one image
    had been merged into the next and its time dropped."""
    from rti_rig.runtime.session import rig_time_of_records

    def rec(start: float) -> dict[str, float]:
        return {"rig_start_s": start, "light_s": 0.1, "settle_s": 0.2, "capture_s": 0.7}

    one_run = [rec(0.0), rec(1.0), rec(2.0)]
    assert rig_time_of_records(one_run) == pytest.approx(3.0)
    killed_after_one = [rec(0.0), rec(0.0), rec(1.0)]  # run 1: one image; run 2: two
    assert rig_time_of_records(killed_after_one) == pytest.approx(1.0 + 2.0)


def _fit_the_rest(done: Path, out: Path, rest: Path | None = None) -> None:
    """The way out a refused session is given: ``export-lp --linear`` of the images still
    intact into ``rest`` (``rest.lp`` in the session by default), then ``fit`` of that, which
    must succeed."""
    rest = rest or done / "rest.lp"
    r = runner.invoke(app, ["export-lp", str(done), "--linear", "--out", str(rest)])
    assert r.exit_code == 0, r.output
    r = runner.invoke(app, ["fit", str(rest), "--out", str(out), "--model", "ps"])
    assert r.exit_code == 0, r.output


def test_a_missing_raw_beside_a_lost_journal_is_rebuilt_as_lost_and_its_image_still_fitted(
    tmp_path: Path, reference: tuple[Path, Path]
) -> None:
    """Journal lost and raw/image_006.dng gone from a finished DSLR session: the rebuild had
    refused the whole journal for it. Now every image is taken back, image_006 recorded as
    lost with its JPEG and TIFF left in place (still listed and fitted), and the verdict and
    the rebuild name the reshoot that gets the original back."""
    _, ref = reference
    done = copied(ref, tmp_path)
    _with_raw_originals(done)
    journal = (done / "journal.jsonl").read_bytes()
    (done / "journal.jsonl").unlink()
    (done / "raw" / "image_006.dng").unlink()
    lp = (done / "lights.lp").read_bytes()
    r = runner.invoke(app, ["run", "--resume", str(done), "--rebuild-journal"])
    assert r.exit_code == 0, r.output
    reshoot = f"rti-rig run --resume {done} --reshoot-lost"
    assert "lost since capture (image_006: raw/image_006.dng missing)" in said(r), r.output
    assert reshoot in said(r)
    assert (done / "journal.jsonl").read_bytes() == journal
    assert (done / "lights.lp").read_bytes() == lp  # its developed image stays listed
    assert not list((done / "recovered").rglob("image_*"))  # nothing else was set aside
    r = runner.invoke(app, ["fit", str(done), "--out", str(tmp_path / "fit"), "--model", "ps"])
    assert r.exit_code == 0, r.output
    verdict = json.loads((tmp_path / "fit" / "qa.json").read_text())["verdict"]
    assert verdict.startswith("reshoot: image_006 (raw/image_006.dng missing since capture: the")
    assert reshoot in verdict


def test_export_lp_lists_an_image_whose_raw_is_lost_and_says_the_original_is_lost(
    tmp_path: Path, reference: tuple[Path, Path]
) -> None:
    """export-lp of a finished DSLR session without raw/image_002.dng said nothing of it, while
    the verdict names the image lost: its JPEG is listed (as captured), and the lost original
    named with the reshoot that gets it back."""
    _, ref = reference
    done = copied(ref, tmp_path)
    _with_raw_originals(done)
    (done / "raw" / "image_002.dng").unlink()
    r = runner.invoke(app, ["export-lp", str(done), "--out", str(done / "x.lp")])
    assert r.exit_code == 0, r.output
    assert [e.name for e in read_lp(done / "x.lp")] == [e.name for e in read_lp(ref / "lights.lp")]
    assert (
        "raw/image_002.dng missing since capture: the camera's original capture of image_002 "
        "is lost (the developed image is as captured, and listed)" in said(r)
    ), r.output
    assert f"rti-rig run --resume {done} --reshoot-lost" in said(r)


def test_a_rebuild_names_the_missing_raw_that_leaves_an_image_unproven(
    tmp_path: Path, reference: tuple[Path, Path]
) -> None:
    """A stopped DSLR session without its journal and without raw/image_002.dng: the rebuild
    set image_002's JPEG and TIFF aside saying "not all its files (or its light) are as
    recorded there". Now it names the lost original; the resume shoots the step again."""
    cfg, ref = reference
    out = tmp_path / "s"
    cancelled_after(cfg, out, 4)
    _with_raw_originals(out)
    (out / "raw" / "image_002.dng").unlink()
    (out / "journal.jsonl").unlink()
    r = runner.invoke(app, ["run", "--resume", str(out), "--rebuild-journal", "--no-verdict"])
    assert r.exit_code == 0, r.output
    assert "image_002.jpg set aside as recovered/" in said(
        r
    ) and "but raw/image_002.dng missing since capture" in said(r), r.output
    assert "not all its files" not in said(r)
    assert digests(out) == digests(ref)


def test_export_lp_names_the_reshoot_of_the_images_it_leaves_out(
    tmp_path: Path, reference: tuple[Path, Path]
) -> None:
    """export-lp of a finished session with image_003.jpg deleted left it out and named it,
    but not what gets it back (the verdict names the reshoot)."""
    _, ref = reference
    done = copied(ref, tmp_path)
    (done / "image_003.jpg").unlink()
    r = runner.invoke(app, ["export-lp", str(done), "--out", str(done / "x.lp")])
    assert r.exit_code == 0, r.output
    assert (
        "left out, missing or changed since they were captured: image_003.jpg; put the "
        f"originals back from a copy, or reshoot exactly those, with the object where it was: "
        f"rti-rig run --resume {done} --reshoot-lost" in said(r)
    ), r.output


def test_a_full_disk_during_reshoot_lost_points_the_verdict_at_what_it_set_aside(
    tmp_path: Path, reference: tuple[Path, Path]
) -> None:
    """image_003.jpg deleted, then --reshoot-lost stopped by a full disk after it set the
    intact TIFF aside: the verdict said only "put the originals back from a copy". Now it
    names the file set aside, as captured, in recovered/."""
    _, ref = reference
    done = copied(ref, tmp_path)
    (done / "image_003.jpg").unlink()
    with failing_writes("tiff", after=0, errno_code=errno.ENOSPC):
        r = runner.invoke(app, ["run", "--resume", str(done), "--reshoot-lost"])
    assert "cannot write" in said(r), r.output
    aside = [p.relative_to(done).as_posix() for p in (done / "recovered").rglob("*.tif")]
    assert len(aside) == 1 and aside[0].endswith("/linear/image_003.tif"), aside
    r = runner.invoke(app, ["fit", str(done), "--out", str(tmp_path / "fit"), "--model", "ps"])
    assert r.exit_code == 0, r.output
    verdict = json.loads((tmp_path / "fit" / "qa.json").read_text())["verdict"]
    assert f"put the originals back ({aside[0]} is as captured, set aside by a resume" in (
        " ".join(verdict.split())
    ), verdict


def test_a_full_disk_on_a_step_record_file_ends_with_what_happened_and_the_resume(
    tmp_path: Path, reference: tuple[Path, Path], monkeypatch: pytest.MonkeyPatch
) -> None:
    """The run's last line had been a bare "error: cannot write …/records/image_002.json": it
    now says the image is kept (its journal line, which commits it in place of that file, is
    written) and the command that continues, and that command completes the session."""
    cfg, ref = reference
    out = tmp_path / "s"
    # a step's record file (records/.image_NNN.json.tmp), the manifest's (.manifest.json.tmp)
    # too: its begin and image_001's record file are written, image_002's is not
    monkeypatch.setitem(WRITE_POINTS, "record", (".json.tmp",))
    with failing_writes("record", after=2, errno_code=errno.ENOSPC):
        r = runner.invoke(app, ["run", str(cfg), "--out", str(out), "--lights", str(LIGHTS)])
    assert r.exit_code == 2, r.output
    last = " ".join(r.output.strip().splitlines()[-1].split())
    assert last.startswith(f"error: cannot write {out}/records/image_002.json"), r.output
    assert "image_002 is kept all the same" in said(r), r.output
    assert said(r).endswith(f"then continue with rti-rig run --resume {out}"), r.output
    r = runner.invoke(app, ["run", "--resume", str(out)])
    assert r.exit_code == 0 and "2 of 8 images verified" in said(r), r.output
    assert digests(out) == digests(ref)


@pytest.mark.parametrize("point", ["journal", "lp"])
def test_a_write_failing_after_the_record_file_counts_the_step_it_kept(
    tmp_path: Path, reference: tuple[Path, Path], point: str
) -> None:
    """A step is committed once its record file is on disk: a full disk on its journal line
    (or lights.lp) after it had left the step uncounted by the run (progress 2/8, the
    manifest's steps_done_this_run 2) though lights.lp, steps_done and the stop said 3."""
    cfg, _ = reference
    out = tmp_path / "s"
    with failing_writes(point, after=2, errno_code=errno.ENOSPC):
        r = runner.invoke(app, ["run", str(cfg), "--out", str(out), "--lights", str(LIGHTS)])
    assert r.exit_code == 2, r.output
    assert "3/8" in r.output and "2/8" not in r.output, r.output
    assert "3 image(s) kept" in said(r), r.output
    run = manifest(out)["runner"]
    assert run["steps_done_this_run"] == run["steps_done"] == 3, run
    assert len(manifest(out)["steps"]) == 3
