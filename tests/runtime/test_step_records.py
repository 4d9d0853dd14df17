"""A committed step stays proven when its journal line is damaged later: each commit also
writes the step's record to ``records/BASE.json``, which a resume takes back into the journal.

Before, a run killed after committing a step whose journal line was then cut (the tail of
``journal.jsonl`` torn) left nothing proving the step (the manifest lists a run's steps only
when it ends): the resume set the image aside and shot it again.
"""

from __future__ import annotations

import hashlib
import json
import shutil
import signal
from pathlib import Path

import pytest
from conftest import SMALL_DOME, cut_new_session, write_config
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.testing.kill_hooks import popen_session

runner = CliRunner()
LIGHTS = 8


def said(result) -> str:  # type: ignore[no-untyped-def]
    return " ".join(result.output.split())


def _sha(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def _killed_after_three(tmp_path: Path) -> Path:
    cfg = write_config(tmp_path, SMALL_DOME)
    out = tmp_path / "s"
    proc = popen_session("before_light", 3, cfg, out, LIGHTS)
    _, stderr = proc.communicate(timeout=120)
    assert proc.returncode == -signal.SIGKILL, stderr.decode()
    return out


@pytest.mark.slow
@pytest.mark.e2e
@pytest.mark.parametrize("flags", [[], ["--rebuild-journal"]])
def test_a_committed_step_whose_journal_line_was_cut_is_kept_not_shot_again(
    tmp_path: Path, flags: list[str]
) -> None:
    out = _killed_after_three(tmp_path)
    assert sorted(p.name for p in (out / "records").iterdir()) == [
        "image_001.json",
        "image_002.json",
        "image_003.json",
    ]
    third = {p: _sha(out / p) for p in ("image_003.jpg", "linear/image_003.tif")}
    journal = out / "journal.jsonl"
    lines = journal.read_bytes().splitlines(keepends=True)
    assert len(lines) == 3
    journal.write_bytes(b"".join(lines[:2]) + lines[2][:-25])  # image_003's line torn

    r = runner.invoke(app, ["run", "--resume", str(out), *flags])
    assert r.exit_code == 0, r.output
    text = said(r)
    assert "3 of 8 images verified" in text, text
    assert "written back from records/image_003.json" in text, text
    # the image is the one captured, never set aside
    assert {p: _sha(out / p) for p in third} == third
    moved = [p.name for p in (out / "recovered").rglob("*") if p.is_file()]
    assert moved == ["journal-rejected.txt"], moved
    # the journal is mended: image_003's record, once, then the steps shot after it
    records = [json.loads(x) for x in journal.read_text().splitlines()]
    assert [r["index"] for r in records] == list(range(LIGHTS))
    assert records[2]["sha256"]["image_003.jpg"] == third["image_003.jpg"]
    # the resume shot only the steps never committed
    m = json.loads((out / "manifest.json").read_text())
    assert m["runs"][-1]["resumed_with_steps_done"] == 3
    assert len(list((out / "records").glob("image_*.json"))) == LIGHTS


@pytest.mark.slow
@pytest.mark.e2e
def test_a_record_file_whose_image_was_changed_proves_nothing(tmp_path: Path) -> None:
    """The record file is proof only with its files as captured: an image changed since
    (and its journal line cut) is set aside and shot again, as before."""
    out = _killed_after_three(tmp_path)
    (out / "image_003.jpg").write_bytes(b"edited")
    journal = out / "journal.jsonl"
    lines = journal.read_bytes().splitlines(keepends=True)
    journal.write_bytes(b"".join(lines[:2]) + lines[2][:-25])

    r = runner.invoke(app, ["run", "--resume", str(out)])
    assert r.exit_code == 0, r.output
    assert "2 of 8 images verified" in said(r), said(r)
    kept = {p.relative_to(out / "recovered").parts[1:] for p in (out / "recovered").rglob("*.*")}
    assert ("image_003.jpg",) in kept, kept
    assert next((out / "recovered").rglob("image_003.jpg")).read_bytes() == b"edited"
    # the journal and the record file now hold the new capture's record
    new = json.loads((out / "records" / "image_003.json").read_text())
    assert new["sha256"]["image_003.jpg"] == _sha(out / "image_003.jpg")


@pytest.mark.slow
@pytest.mark.e2e
@pytest.mark.parametrize("flags", [[], ["--rebuild-journal"]])
def test_a_deleted_journal_is_rebuilt_from_the_step_record_files(
    tmp_path: Path, flags: list[str]
) -> None:
    """A journal deleted outright, records/ holding every committed step's record: the resume
    rebuilds it from them, each verified against its files (it had been refused, saying
    ``--rebuild-journal`` cannot help, though every step was proven)."""
    out = _killed_after_three(tmp_path)
    kept = {p: _sha(out / p) for p in ("image_002.jpg", "image_003.jpg")}
    (out / "journal.jsonl").unlink()

    r = runner.invoke(app, ["run", "--resume", str(out), *flags])
    assert r.exit_code == 0, r.output
    text = said(r)
    assert "3 of 8 images verified" in text, text
    if flags:  # the rebuild asked for says where each image's proof came from
        assert "3 from their step record files in records/ (journal.jsonl was missing)" in text
    else:
        assert "journal.jsonl was missing: rebuilt from 3 step record file(s) in records/" in text
        assert not (out / "recovered").exists()
    assert "nothing rebuilt" not in text and "set aside in recovered/" not in text, text
    assert {p: _sha(out / p) for p in kept} == kept
    records = [json.loads(x) for x in (out / "journal.jsonl").read_text().splitlines()]
    assert [r["index"] for r in records] == list(range(LIGHTS))
    assert (
        json.loads((out / "manifest.json").read_text())["runs"][-1]["resumed_with_steps_done"] == 3
    )


@pytest.mark.slow
@pytest.mark.e2e
def test_a_deleted_journal_whose_record_file_no_longer_matches_is_still_refused(
    tmp_path: Path,
) -> None:
    """A record file is proof only with its files as captured: image_002 changed, the journal
    deleted, nothing vouches for image_002 while image_003 was committed after it: refused,
    the folder unchanged, the fit's verdict saying the journal is missing."""
    out = _killed_after_three(tmp_path)
    (out / "journal.jsonl").unlink()
    (out / "image_002.jpg").write_bytes(b"edited")
    before = sorted(p.relative_to(out).as_posix() for p in out.rglob("*"))

    r = runner.invoke(app, ["run", "--resume", str(out)])
    assert r.exit_code != 0
    text = said(r)
    assert "journal.jsonl is missing" in text and "image_002" in text, text
    assert "records/" in text, text
    assert sorted(p.relative_to(out).as_posix() for p in out.rglob("*")) == before


def test_the_decoded_raw_is_named_where_it_is_kept_not_where_it_was_staged(
    tmp_path: Path,
) -> None:
    """decode.source_file in the journal, the record file and the manifest had named the
    staged download (raw/.incoming/cap0001_IMG_0001.CR2), gone once the commit moved it to
    raw/image_001.cr2: it now names the kept file, the camera's own name kept beside it."""
    import numpy as np

    from rti_rig.core.devices import Frame
    from rti_rig.runtime.session import RAW_INCOMING, SessionFolder

    folder = SessionFolder.create(tmp_path / "s", 1)
    folder.begin({"rig": {}, "schedule": {"steps": [{}]}})
    staged = folder.root / RAW_INCOMING / "cap0001_IMG_0001.CR2"
    staged.parent.mkdir(parents=True)
    staged.write_bytes(b"raw bytes")
    frame = Frame(
        pixels=np.full((4, 4, 3), 1000, np.uint16),
        exposure_s=0.1,
        gain=100.0,
        white_level=65535,
        timestamp_s=0.0,
        metadata={
            "originals": [{"path": str(staged), "name": "/IMG_0001.CR2"}],
            "decode": {"mode": "half", "source_file": str(staged)},
        },
    )
    fields = {
        "planned_direction": (0.0, 0.0, 1.0),
        "actual_direction": (0.0, 0.0, 1.0),
        "led": 0,
        "rig_start_s": 0.0,
        "light_s": 0.0,
        "settle_s": 0.0,
        "capture_s": 0.0,
    }
    rec = folder.write_step(0, frame, fields)
    folder.finish([rec], {"finish_reason": "completed"}, {})
    manifest = json.loads((folder.root / "manifest.json").read_text())
    for decode in (
        rec.decode,
        json.loads((folder.root / "journal.jsonl").read_text())["decode"],
        json.loads((folder.root / "records" / "image_001.json").read_text())["decode"],
        manifest["steps"][0]["decode"],
    ):
        assert decode["source_file"] == decode["raw_file"] == "raw/image_001.cr2", decode
        assert (folder.root / decode["source_file"]).read_bytes() == b"raw bytes"
        assert decode["camera_file"] == "/IMG_0001.CR2"


@pytest.mark.slow
@pytest.mark.e2e
def test_the_verdicts_mend_for_an_unfinished_session_says_it_also_captures(
    tmp_path: Path,
) -> None:
    """The verdict of a session killed after 5 of 8 images, its fifth journal line cut, named
    `rti-rig run --resume S` as what writes the record back into the journal, and nothing
    more: that resume also lights the dome for the 3 images still to take. Said now."""
    cfg = write_config(tmp_path, SMALL_DOME)
    out = tmp_path / "s"
    proc = popen_session("before_light", 5, cfg, out, LIGHTS)
    _, stderr = proc.communicate(timeout=120)
    assert proc.returncode == -signal.SIGKILL, stderr.decode()
    journal = out / "journal.jsonl"
    lines = journal.read_bytes().splitlines(keepends=True)
    assert len(lines) == 5
    journal.write_bytes(b"".join(lines[:4]) + lines[4][:-25])
    r = runner.invoke(
        app,
        ["fit", str(out), "--out", str(tmp_path / "f"), "--no-ptm", "--no-hsh", "--no-normals"],
    )
    text = said(r)
    assert "writes it back into journal.jsonl, and goes on to capture the 3 images" in text, text


@pytest.mark.slow
@pytest.mark.e2e
def test_a_disk_that_cannot_fsync_a_folder_still_runs(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Some network and FUSE file systems answer EINVAL to an fsync of a folder. The step
    record's folder fsync turned that into a write failure after the step's journal line was
    written: every run on such a disk stopped at image 1, its summary and manifest
    disagreeing on the images kept. The folder's entries are let be as durable as the file
    system makes them."""
    import errno
    import os
    import stat

    real_fsync = os.fsync

    def fsync(fd: int) -> None:
        if stat.S_ISDIR(os.fstat(fd).st_mode):
            raise OSError(errno.EINVAL, os.strerror(errno.EINVAL))
        real_fsync(fd)

    monkeypatch.setattr(os, "fsync", fsync)
    cfg = write_config(tmp_path, SMALL_DOME)
    out = tmp_path / "s"
    r = runner.invoke(app, ["run", str(cfg), "--out", str(out), "--lights", "4"])
    assert r.exit_code == 0, said(r)
    assert sorted(p.name for p in (out / "records").iterdir()) == [
        f"image_00{i}.json" for i in range(1, 5)
    ]


@pytest.mark.slow
def test_a_step_shot_again_whose_new_journal_line_was_cut_is_proven_by_its_record_file(
    tmp_path: Path,
) -> None:
    """A step shot again (a resume that set its image aside, or `--reshoot-lost`) has two
    journal records, the earlier first; a run killed after that commit, its new line then
    cut, leaves the earlier record as the journal's latest. That record had decided alone:
    its checksums no longer match the image on disk, so the step was unproven and shot once
    more, although records/image_003.json holds the new record whole and the files match it.
    The record file is taken over a journal record its files do not match (and only then:
    one the files match still decides)."""
    from rti_rig.runtime.session import image_names, scan_journal, verified_steps

    cfg = write_config(tmp_path, SMALL_DOME)
    out = tmp_path / "s"
    r = runner.invoke(app, ["run", str(cfg), "--out", str(out), "--lights", "4"])
    assert r.exit_code == 0, said(r)
    journal = out / "journal.jsonl"
    lines = journal.read_bytes().splitlines(keepends=True)
    earlier = json.loads(lines[2])
    earlier["sha256"] = {k: "0" * 64 for k in earlier["sha256"]}  # a capture since replaced
    journal.write_bytes(
        lines[0] + lines[1] + (json.dumps(earlier) + "\n").encode() + lines[3] + lines[2][:-30]
    )
    scan = scan_journal(out, image_names(4))
    assert scan.mended == ["records/image_003.json"]
    assert sorted(verified_steps(out, scan.records)) == [0, 1, 2, 3]

    # the journal's own latest record, matching the files, decides: no record file taken
    journal.write_bytes(b"".join(lines))
    (out / "records" / "image_003.json").write_text(json.dumps(earlier) + "\n")
    scan = scan_journal(out, image_names(4))
    assert scan.mended == [] and sorted(verified_steps(out, scan.records)) == [0, 1, 2, 3]


def _killed(tmp_path: Path, stage: str, k: int) -> Path:
    cfg = write_config(tmp_path, SMALL_DOME)
    out = tmp_path / "s"
    proc = popen_session(stage, k, cfg, out, LIGHTS)
    _, stderr = proc.communicate(timeout=120)
    assert proc.returncode == -signal.SIGKILL, stderr.decode()
    return out


@pytest.mark.slow
@pytest.mark.e2e
def test_a_kill_right_after_a_journal_line_leaves_its_record_file_to_prove_it(
    tmp_path: Path,
) -> None:
    """The record file had been written after the journal line: a kill between the two left
    image_004 committed with no record file, and once its line was cut the resume called the
    line "never committed", set the image aside and shot it again. The record file is now
    written first, so a committed line always has one."""
    out = _killed(tmp_path, "after_journal", 3)
    assert (out / "records" / "image_004.json").is_file()
    fourth = {p: _sha(out / p) for p in ("image_004.jpg", "linear/image_004.tif")}
    journal = out / "journal.jsonl"
    journal.write_bytes(journal.read_bytes()[:-30])  # image_004's line cut

    r = runner.invoke(app, ["run", "--resume", str(out), "--no-verdict"])
    assert r.exit_code == 0, r.output
    text = said(r)
    assert "4 of 8 images verified" in text, text
    assert "written back from records/image_004.json" in text, text
    assert "never committed" not in text, text
    assert {p: _sha(out / p) for p in fourth} == fourth


@pytest.mark.slow
@pytest.mark.e2e
def test_a_record_file_with_no_journal_line_keeps_its_image_only_as_captured(
    tmp_path: Path,
) -> None:
    """A kill between the record file and the journal line: the image is whole and its
    record says so, so the resume takes it back into the journal (not shot again); the same
    kill with the image changed since is set aside and shot again, as any unproven image.
    (The second case is a copy of the killed folder: a second killed run of the same
    deterministic session, a subprocess and its imports, left the same files.)"""
    out = _killed(tmp_path, "after_record", 3)
    changed = tmp_path / "b" / "s"
    shutil.copytree(out, changed, symlinks=True)
    journal = out / "journal.jsonl"
    assert len(journal.read_bytes().splitlines()) == 3
    r = runner.invoke(app, ["run", "--resume", str(out), "--no-verdict"])
    assert r.exit_code == 0, r.output
    assert "4 of 8 images verified" in said(r), said(r)
    records = [json.loads(x) for x in journal.read_text().splitlines()]
    assert [r["index"] for r in records] == list(range(LIGHTS))

    (changed / "image_004.jpg").write_bytes(b"edited")
    r = runner.invoke(app, ["run", "--resume", str(changed), "--no-verdict"])
    assert r.exit_code == 0, r.output
    assert "3 of 8 images verified" in said(r), said(r)
    assert next((changed / "recovered").rglob("image_004.jpg")).read_bytes() == b"edited"
    new = json.loads((changed / "records" / "image_004.json").read_text())
    assert new["sha256"]["image_004.jpg"] == _sha(changed / "image_004.jpg")


@pytest.mark.slow
@pytest.mark.e2e
def test_a_rejected_line_is_said_set_aside_whatever_its_own_text_says(tmp_path: Path) -> None:
    """The resume had told a record written back from a rejected line by the note's words
    ("written back from" in it), and a rejected line's reason quotes the line's own image
    name: a damaged line naming "written back from.jpg" was set aside without a word of it.
    Each note now carries whether it set something aside; the manifest keeps the words."""
    out = _killed_after_three(tmp_path)
    journal = out / "journal.jsonl"
    lines = journal.read_text().splitlines()
    damaged = json.loads(lines[2])
    damaged["image"] = "written back from.jpg"
    lines[2] = json.dumps(damaged)
    journal.write_text("\n".join(lines) + "\n")

    r = runner.invoke(app, ["run", "--resume", str(out), "--no-verdict"])
    assert r.exit_code == 0, r.output
    text = said(r)
    assert "3 of 8 images verified" in text, text
    assert (
        "journal line 3: image 'written back from.jpg' does not fit step 3 of the schedule: "
        "set aside in recovered/, not appended onto" in text
    ), text
    # the record written back says so, with nothing set aside
    assert "not shot again): set aside" not in text, text
    run = json.loads((out / "manifest.json").read_text())["runs"][-1]
    assert all(isinstance(n, str) for n in run["journal_repair"]), run["journal_repair"]
    assert run["journal_repair"][0].startswith("journal line 3: image 'written back from.jpg'")


def _stopped_before_line(tmp_path: Path, n: int) -> Path:
    """A session as a kill between image ``n``'s record file and its journal line leaves it:
    that image's files and record file on disk, no journal line or lights.lp line of it, a
    manifest as begun. Made from a run cancelled after ``n`` images (no child to kill: fast)."""
    from rti_rig.app.usecases.session import NewSessionRequest
    from rti_rig.core.lp_format import read_lp
    from rti_rig.runtime.session import write_lp_atomic

    cfg = write_config(tmp_path, SMALL_DOME)
    out = tmp_path / "s"
    cut_new_session(NewSessionRequest(cfg, out, lights=LIGHTS), after_step=n - 1)
    journal = out / "journal.jsonl"
    lines = journal.read_bytes().splitlines(keepends=True)
    assert len(lines) == n and (out / "records" / f"image_{n:03d}.json").is_file()
    lp = out / "lights.lp"
    if n == 1:
        journal.unlink()
        lp.unlink()
    else:
        journal.write_bytes(b"".join(lines[:-1]))
        write_lp_atomic(lp, read_lp(lp)[:-1])
    manifest = json.loads((out / "manifest.json").read_text())
    manifest["runner"] = {"state": "running", "finish_reason": None}
    manifest["steps"] = []
    manifest.pop("finished_at", None)
    (out / "manifest.json").write_text(json.dumps(manifest))
    return out


def test_fit_of_a_run_stopped_between_a_record_file_and_its_line_says_so(tmp_path: Path) -> None:
    """The verdict had said "lights.lp does not list image_004 … (the .lp edited since
    capture?)" and "journal.jsonl is damaged (records missing)" of a run stopped between
    image_004's record file and its journal line, and counted 4 images of a fit of 3. The fit
    now completes lights.lp first (the step is committed), and fits the 4 images."""
    out = _stopped_before_line(tmp_path, 4)
    r = runner.invoke(app, ["fit", str(out), "--out", str(tmp_path / "fit"), "--model", "ps"])
    assert r.exit_code == 0, r.output
    qa = json.loads((tmp_path / "fit" / "qa.json").read_text())
    verdict = " ".join(qa["verdict"].split())
    assert "does not list" not in verdict and "damaged" not in verdict, verdict
    assert (
        "the run stopped after image_004's record file, before its journal line; rti-rig run "
        f"--resume {out} writes it back"
    ) in verdict, verdict
    assert len(qa["images"]) == 4, qa["images"]


def test_a_run_stopped_before_its_first_journal_line_tells_one_story(tmp_path: Path) -> None:
    """Image_001's record file on disk, no journal yet: fit said "stopped before its first
    image was recorded", export-lp exported it, and the resume said "journal.jsonl was
    missing" of a journal never written."""
    out = _stopped_before_line(tmp_path, 1)
    r = runner.invoke(app, ["fit", str(out), "--out", str(tmp_path / "fit")])
    assert r.exit_code != 0
    assert (
        f"{out} is a session that stopped before its first journal line: image_001 is kept "
        "(its record file proves it)" in said(r)
    ), r.output
    r = runner.invoke(app, ["export-lp", str(out), "--out", str(tmp_path / "x.lp")])
    assert r.exit_code == 0 and "1 light" in said(r) and "1 lights" not in said(r), r.output
    r = runner.invoke(app, ["run", "--resume", str(out), "--no-verdict"])
    assert r.exit_code == 0, r.output
    assert "the run stopped before its first journal line: journal.jsonl begun from " in said(r)
    assert "was missing" not in said(r) and "1 of 8 images verified" in said(r), r.output
