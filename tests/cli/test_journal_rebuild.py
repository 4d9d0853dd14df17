"""``run --resume --rebuild-journal``: a session whose journal was lost or damaged.

A stopped session's manifest holds every committed image's record (checksums, light). Its
resume had refused a missing journal with no way on but a backup, and had read a journal cut
short or overwritten as torn or junk lines: every image they had lost was moved to recovered/
and shot again. The resume now refuses, naming ``--rebuild-journal``; with it the journal is
rebuilt from the images whose files and lights the manifest proves, anything else set aside
(never deleted) under a name that says why, and the session continues as an uninterrupted
one would have gone.
"""

from __future__ import annotations

import hashlib
import json
import shutil
from pathlib import Path

import pytest
from conftest import SMALL_DOME, cut_new_session, interrupted, said, write_config
from typer.testing import CliRunner

from rti_rig.app.usecases.session import NewSessionRequest
from rti_rig.cli import app
from rti_rig.runtime.controller import FinishReason
from rti_rig.testing.kill_hooks import popen_argv

runner = CliRunner()
LIGHTS = 8


def _files(folder: Path) -> dict[str, bytes]:
    return {
        p.relative_to(folder).as_posix(): p.read_bytes() for p in folder.rglob("*") if p.is_file()
    }


def _images(folder: Path) -> dict[str, str]:
    files = [*folder.glob("image_*.jpg"), *(folder / "linear").glob("*.tif"), folder / "lights.lp"]
    return {
        p.relative_to(folder).as_posix(): hashlib.sha256(p.read_bytes()).hexdigest() for p in files
    }


@pytest.fixture(scope="module")
def made(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path, Path]:
    """(the rig config, an uninterrupted session, the same session stopped after 4 images).

    Both sessions' step record files (``records/``) are removed, as in a session
    written before them: with them, a plain resume writes a lost line back from its step's
    file (tests/runtime/test_step_records.py), and what these tests exercise is the proof
    that is left without them, the manifest."""
    base = tmp_path_factory.mktemp("rebuild")
    cfg = write_config(base, SMALL_DOME)
    ref = base / "uninterrupted"
    r = runner.invoke(app, ["run", str(cfg), "--out", str(ref), "--lights", str(LIGHTS)])
    assert r.exit_code == 0, r.output
    stopped = base / "stopped"
    run = cut_new_session(NewSessionRequest(cfg, stopped, lights=LIGHTS), after_step=3)
    assert run.finish_reason is FinishReason.CANCELLED
    for session in (ref, stopped):
        shutil.rmtree(session / "records")
    return cfg, ref, stopped


def _damaged(made: tuple[Path, Path, Path], tmp_path: Path, how: str) -> Path:
    out = tmp_path / "s"
    shutil.copytree(made[2], out)
    journal = out / "journal.jsonl"
    data = journal.read_bytes()
    if how == "deleted":
        journal.unlink()
    elif how == "truncated":
        journal.write_bytes(data[: len(data) // 2])  # mid-line: records 3 and 4 gone
    elif how == "garbage":
        journal.write_bytes(bytes(range(256)) * 8 + b"\x00\n{not json\n")
    return out


@pytest.mark.parametrize("how", ["deleted", "truncated", "garbage"])
def test_a_lost_or_damaged_journal_is_refused_then_rebuilt(
    made: tuple[Path, Path, Path], tmp_path: Path, how: str
) -> None:
    _, ref, _ = made
    out = _damaged(made, tmp_path, how)
    old_journal = (out / "journal.jsonl").read_bytes() if how != "deleted" else None
    before = _files(out)
    r = runner.invoke(app, ["run", "--resume", str(out)])
    assert r.exit_code == 2, r.output
    assert "lists as captured" in said(r) and f"--resume {out} --rebuild-journal" in said(r)
    assert _files(out) == before  # refused: nothing moved, nothing reshot

    r = runner.invoke(app, ["run", "--resume", str(out), "--rebuild-journal"])
    assert r.exit_code == 0, r.output
    assert "4 of 8 images verified" in said(r), r.output
    assert "journal.jsonl rebuilt from manifest.json: 4 image(s) taken back" in said(r)
    assert _images(out) == _images(ref)  # as if never interrupted
    for name, data in before.items():  # every captured file kept, unchanged
        if name.startswith("image_") or name.startswith("linear/"):
            assert (out / name).read_bytes() == data, name
    kept = list((out / "recovered").rglob("journal-damaged.jsonl"))
    if old_journal is None:
        assert not kept
    else:  # the broken journal kept aside, byte for byte, and said
        assert [p.read_bytes() for p in kept] == [old_journal]
        assert "journal-damaged.jsonl" in said(r)
    rebuild = json.loads((out / "manifest.json").read_text())["runs"][-1]["journal_rebuild"]
    assert rebuild and "rebuilt" in rebuild[0]
    # and on disk beside what was set aside, whatever stops the run before the manifest
    (report,) = (out / "recovered").rglob("journal-rebuild.txt")
    assert report.read_text().startswith("journal.jsonl rebuilt from manifest.json: 4 image(s)")
    r = runner.invoke(app, ["fit", str(out), "--out", str(tmp_path / "fit")])
    assert r.exit_code == 0, r.output
    assert "not checked" not in said(r) and "QA verdict: good" in said(r)


def test_an_image_edited_after_the_manifest_is_not_taken_back(
    made: tuple[Path, Path, Path], tmp_path: Path
) -> None:
    _, ref, _ = made
    out = _damaged(made, tmp_path, "deleted")
    edited = bytearray((out / "image_002.jpg").read_bytes())
    edited[-10] ^= 1
    (out / "image_002.jpg").write_bytes(bytes(edited))
    tif = (out / "linear" / "image_002.tif").read_bytes()
    r = runner.invoke(app, ["run", "--resume", str(out), "--rebuild-journal"])
    assert r.exit_code == 0, r.output
    assert "3 image(s) taken back (image_001, image_003, image_004)" in said(r)
    (aside,) = (out / "recovered").glob("*/unproven/image_002.jpg")
    assert aside.read_bytes() == bytes(edited)  # set aside as it was, never deleted
    assert aside.parent.joinpath("linear", "image_002.tif").read_bytes() == tif
    assert "image_002.jpg set aside as" in said(r)
    assert _images(out) == _images(ref)  # reshot, under the manifest's light


def test_an_image_the_manifest_does_not_list_is_set_aside(
    made: tuple[Path, Path, Path], tmp_path: Path
) -> None:
    _, ref, _ = made
    out = _damaged(made, tmp_path, "garbage")
    extra = (out / "image_004.jpg").read_bytes()
    (out / "image_005.jpg").write_bytes(extra)  # a copy dropped in: which light? none proves it
    r = runner.invoke(app, ["run", "--resume", str(out), "--rebuild-journal"])
    assert r.exit_code == 0, r.output
    (aside,) = (out / "recovered").glob("*/not-in-manifest/image_005.jpg")
    assert aside.read_bytes() == extra
    assert "does not list its step" in said(r)
    assert _images(out) == _images(ref)


def test_a_record_given_another_light_is_not_taken_back(
    made: tuple[Path, Path, Path], tmp_path: Path
) -> None:
    """A manifest record whose light is not its step's (edited by hand) proves nothing."""
    _, ref, _ = made
    out = _damaged(made, tmp_path, "deleted")
    manifest = json.loads((out / "manifest.json").read_text())
    manifest["steps"][2]["led"] = manifest["schedule"]["steps"][3]["led"]
    (out / "manifest.json").write_text(json.dumps(manifest))
    r = runner.invoke(app, ["run", "--resume", str(out), "--rebuild-journal"])
    assert r.exit_code == 0, r.output
    assert "3 image(s) taken back (image_001, image_002, image_004)" in said(r)
    assert list((out / "recovered").glob("*/unproven/image_003.jpg"))
    assert _images(out) == _images(ref)


def test_the_flag_goes_with_an_unfinished_session_only(
    made: tuple[Path, Path, Path], tmp_path: Path
) -> None:
    cfg, ref, _ = made
    r = runner.invoke(app, ["run", str(cfg), "--out", str(tmp_path / "n"), "--rebuild-journal"])
    assert r.exit_code == 2 and "goes with --resume" in said(r), r.output
    done = tmp_path / "done"
    shutil.copytree(ref, done)
    r = runner.invoke(app, ["run", "--resume", str(done), "--rebuild-journal"])
    assert r.exit_code == 2 and "completed" in said(r) and "drop --rebuild-journal" in said(r)
    # a whole journal: nothing to rebuild, and said; the resume goes on as ever
    out = tmp_path / "whole"
    shutil.copytree(made[2], out)
    r = runner.invoke(app, ["run", "--resume", str(out), "--rebuild-journal"])
    assert r.exit_code == 0 and "nothing rebuilt" in said(r), r.output
    assert _images(out) == _images(ref)


def test_an_adaptive_session_continues_as_it_would_have(tmp_path: Path) -> None:
    """Its records in the manifest hold each decision: the rebuilt journal replays them, and
    the resume decides each again (a step decided otherwise would be refused)."""
    cfg = write_config(tmp_path, SMALL_DOME)
    plain, lost = tmp_path / "plain", tmp_path / "lost"
    interrupted(cfg, plain, 3)
    shutil.copytree(plain, lost)
    (lost / "journal.jsonl").unlink()
    shutil.rmtree(lost / "records")  # and its step record files: the manifest alone
    r = runner.invoke(app, ["run", "--resume", str(lost)])
    assert r.exit_code == 2 and "--rebuild-journal" in said(r), r.output
    r = runner.invoke(app, ["run", "--resume", str(lost), "--rebuild-journal"])
    assert r.exit_code == 0, r.output
    r = runner.invoke(app, ["run", "--resume", str(plain)])
    assert r.exit_code == 0, r.output
    assert _images(lost) == _images(plain)


def test_the_verdict_of_a_session_without_its_journal_names_the_rebuild(
    made: tuple[Path, Path, Path], tmp_path: Path
) -> None:
    """fit's verdict had advised a backup alone, of a session its manifest can vouch for."""
    out = _damaged(made, tmp_path, "truncated")
    r = runner.invoke(app, ["fit", str(out), "--out", str(tmp_path / "fit")])
    assert r.exit_code == 0, r.output
    assert "not checked against their capture checksums" in said(r)
    assert f"rti-rig run --resume {out} --rebuild-journal" in said(r)


def test_a_committed_line_cut_short_is_not_called_a_stop_while_saving(
    made: tuple[Path, Path, Path], tmp_path: Path
) -> None:
    """The journal's last line cut short, of an image the manifest records: the verdict had
    said the session "stopped while saving it ... neither its files nor its light were ever
    recorded as captured", and pointed to a resume (now refused) to shoot it again."""
    out = tmp_path / "s"
    shutil.copytree(made[2], out)
    journal = out / "journal.jsonl"
    journal.write_bytes(journal.read_bytes()[:-30])
    r = runner.invoke(app, ["fit", str(out), "--out", str(tmp_path / "fit")])
    assert r.exit_code == 0, r.output
    assert "stopped while saving" not in said(r)
    assert "image_004 not checked against its capture checksum" in said(r)
    assert f"rti-rig run --resume {out} --rebuild-journal" in said(r)


def test_the_verdict_counts_the_images_the_manifest_records(
    made: tuple[Path, Path, Path], tmp_path: Path
) -> None:
    """A stopped session without its journal: "not finished (0 of 8 images …)" had been said
    of 4 images on disk, fitted and judged, that the manifest records."""
    out = _damaged(made, tmp_path, "deleted")
    r = runner.invoke(app, ["fit", str(out), "--out", str(tmp_path / "fit")])
    assert r.exit_code == 0, r.output
    assert "the session is not finished (4 of 8 images" in said(r), r.output
    # the continuation it names is one that is not refused
    assert f"continue it with rti-rig run --resume {out} --rebuild-journal" in said(r)


def test_an_adaptive_record_without_its_decision_is_refused(tmp_path: Path) -> None:
    """What cannot be proven is not guessed: a record with no decision cannot be decided again."""
    cfg = write_config(tmp_path, SMALL_DOME)
    out = tmp_path / "s"
    interrupted(cfg, out, 3)
    (out / "journal.jsonl").unlink()
    shutil.rmtree(out / "records")  # and its step record files: the manifest alone
    manifest = json.loads((out / "manifest.json").read_text())
    manifest["steps"][1]["decision"] = None
    (out / "manifest.json").write_text(json.dumps(manifest))
    before = _files(out)
    r = runner.invoke(app, ["run", "--resume", str(out), "--rebuild-journal"])
    assert r.exit_code == 2, r.output
    assert "image_002 without the adaptive decision" in said(r)
    assert _files(out) == before


@pytest.mark.parametrize("how", ["deleted", "truncated"])
def test_export_lp_names_the_rebuild(
    made: tuple[Path, Path, Path], tmp_path: Path, how: str
) -> None:
    """export-lp had advised a backup alone, of a session its manifest can vouch for."""
    out = _damaged(made, tmp_path, how)
    r = runner.invoke(app, ["export-lp", str(out), "--out", str(tmp_path / "x.lp")])
    assert f"rti-rig run --resume {out} --rebuild-journal" in said(r), r.output
    # a finished session's journal is rebuilt too (no rig opened): offered
    done = tmp_path / "done"
    shutil.copytree(made[1], done)
    (done / "journal.jsonl").unlink()
    r = runner.invoke(app, ["export-lp", str(done), "--out", str(tmp_path / "y.lp")])
    assert r.exit_code == 2 and f"rti-rig run --resume {done} --rebuild-journal" in said(r)
    # with an image lost too: the reshoot that makes it whole, and the rebuild that records
    # it as lost without the rig
    (done / "image_002.jpg").unlink()
    r = runner.invoke(app, ["export-lp", str(done), "--out", str(tmp_path / "y.lp")])
    assert r.exit_code == 2 and f"rti-rig run --resume {done} --reshoot-lost" in said(r)
    assert f"{done} --rebuild-journal rebuilds the journal and records it as lost" in said(r)


def test_a_rebuild_that_takes_nothing_back_keeps_no_old_line(
    made: tuple[Path, Path, Path], tmp_path: Path
) -> None:
    """Every record the manifest holds given another light: nothing is taken back, and the
    rebuilt journal stays empty (the damaged one's surviving lines had been written back over
    it, records of images just set aside)."""
    _, ref, _ = made
    out = _damaged(made, tmp_path, "truncated")
    manifest = json.loads((out / "manifest.json").read_text())
    for step in manifest["steps"]:
        step["led"] = -1
    (out / "manifest.json").write_text(json.dumps(manifest))
    # the journal's surviving lines too: they prove nothing either, and must not come back
    journal = out / "journal.jsonl"
    *whole, torn = journal.read_bytes().split(b"\n")
    edited = [json.loads(line) | {"led": -1} for line in whole]
    assert edited  # the surviving lines are there, to be left out
    journal.write_bytes(b"".join(json.dumps(e).encode() + b"\n" for e in edited) + torn)
    r = runner.invoke(app, ["run", "--resume", str(out), "--rebuild-journal"])
    assert r.exit_code == 0, r.output
    assert "0 image(s) taken back" in said(r)
    lines = (out / "journal.jsonl").read_text().splitlines()
    assert [json.loads(line)["index"] for line in lines] == list(range(8))
    assert _images(out) == _images(ref)


def _killed_after_its_manifest(made: tuple[Path, Path, Path], tmp_path: Path) -> Path:
    """The stopped session resumed and killed (SIGKILL) once it had committed three more
    images, which only the journal records; then image_004's line, which the manifest records
    too, overwritten (a sync tool)."""
    out = tmp_path / "s"
    shutil.copytree(made[2], out)
    kill = popen_argv("before_journal", 3, ["run", "--resume", str(out)])
    assert kill.wait(timeout=300) == -9, kill.communicate()
    journal = out / "journal.jsonl"
    lines = journal.read_bytes().split(b"\n")
    assert [json.loads(line)["index"] for line in lines if line] == list(range(7))
    assert len(json.loads((out / "manifest.json").read_text())["steps"]) == 4
    lines[3] = b"\x00" * len(lines[3])
    journal.write_bytes(b"\n".join(lines))
    return out


def test_images_journaled_after_the_manifest_are_taken_back(
    made: tuple[Path, Path, Path], tmp_path: Path
) -> None:
    """A resume killed (SIGKILL) after committing three images: their journal lines hold their
    checksums and lights, the manifest (written only when a run ends) does not. A line of the
    journal is then overwritten (a sync tool), so the resume is refused and the rebuild named.
    The rebuild had taken back only the manifest's images and set the three aside, then shot
    them again; the journal's intact lines prove them as a plain resume would."""
    _, ref, _ = made
    out = _killed_after_its_manifest(made, tmp_path)
    kept = {n: (out / n).stat().st_ino for n in ("image_005.jpg", "linear/image_007.tif")}
    r = runner.invoke(app, ["run", "--resume", str(out)])
    assert r.exit_code == 2 and "--rebuild-journal" in said(r), r.output

    r = runner.invoke(app, ["run", "--resume", str(out), "--rebuild-journal"])
    assert r.exit_code == 0, r.output
    assert "7 of 8 images verified" in said(r), r.output
    assert "and 3 from the old journal.jsonl's intact lines (image_005, image_006, image_007)" in (
        said(r)
    )
    # only the image the kill left uncommitted was set aside; the three were never moved
    aside = sorted(p.relative_to(out) for p in (out / "recovered").rglob("image_*"))
    assert [p.parts[2:] for p in aside] == [
        ("not-in-manifest", "image_008.jpg"),
        ("not-in-manifest", "linear", "image_008.tif"),
    ]
    assert {n: (out / n).stat().st_ino for n in kept} == kept
    assert _images(out) == _images(ref)


def _no_rig(monkeypatch: pytest.MonkeyPatch) -> None:
    """Fail the test if a rig config is loaded (a completed session's rebuild shoots nothing)."""

    def refused(*args, **kwargs):  # type: ignore[no-untyped-def]
        raise AssertionError("a rig config was loaded")

    monkeypatch.setattr("rti_rig.app.config.load_rig_config", refused)


def test_a_completed_session_whose_journal_is_lost_is_made_whole(
    made: tuple[Path, Path, Path], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A finished session copied to a NAS without its journal: the rebuild had been refused
    ("for a session that did not finish"), export-lp refused the folder and fit could check no
    image. Its manifest holds every record the journal did: the journal comes back as it was,
    with no rig opened."""
    _, ref, _ = made
    out = tmp_path / "done"
    shutil.copytree(ref, out)
    (out / "journal.jsonl").unlink()
    _no_rig(monkeypatch)
    r = runner.invoke(app, ["run", "--resume", str(out), "--rebuild-journal"])
    assert r.exit_code == 0, r.output
    assert "journal.jsonl rebuilt from manifest.json: 8 image(s) taken back" in said(r)
    assert "whole again" in said(r) and f"rti-rig fit {out} --out {out}-fit" in said(r)
    assert (out / "journal.jsonl").read_bytes() == (ref / "journal.jsonl").read_bytes()
    assert _images(out) == _images(ref)
    (report,) = (out / "recovered").rglob("journal-rebuild.txt")
    assert "8 image(s) taken back" in report.read_text()
    r = runner.invoke(app, ["export-lp", str(out), "--out", str(tmp_path / "x.lp")])
    assert r.exit_code == 0, r.output
    assert (tmp_path / "x.lp").read_bytes() == (ref / "lights.lp").read_bytes()
    r = runner.invoke(app, ["run", "--resume", str(out), "--rebuild-journal"])
    assert r.exit_code == 2 and "nothing to rebuild" in said(r), r.output
    # the fit it names pastes as it stands: a free folder beside the session (it said DIR)
    assert f"the QA verdict of rti-rig fit {out} --out {out}-fit names any image" in said(r)


@pytest.mark.parametrize("how", ["deleted", "truncated"])
def test_a_plain_resume_of_a_completed_session_without_its_journal_names_the_mend(
    made: tuple[Path, Path, Path], tmp_path: Path, monkeypatch: pytest.MonkeyPatch, how: str
) -> None:
    """The same session resumed without --rebuild-journal: it had been told only "this session
    already completed all 8 steps", exit 2, no image named and no mend (a stopped session in
    the same state names both). It names the images it cannot check, why, and the rebuild,
    and changes nothing."""
    _, ref, _ = made
    out = tmp_path / "done"
    shutil.copytree(ref, out)
    journal = out / "journal.jsonl"
    if how == "deleted":
        journal.unlink()
        unchecked, why = "image_001, image_002, image_003", "journal.jsonl is missing"
    else:
        journal.write_bytes(b"".join(journal.read_bytes().splitlines(keepends=True)[:5]))
        unchecked, why = "image_006, image_007, image_008", "no record of them in journal.jsonl"
    before = _files(out)
    r = runner.invoke(app, ["run", "--resume", str(out)])
    assert r.exit_code == 2, r.output
    text = said(r)
    assert "already completed all 8 steps; but " + unchecked in text, text
    assert f"cannot be checked against the checksums taken at capture ({why})" in text, text
    assert f"rti-rig run --resume {out} --rebuild-journal" in text, text
    assert "Traceback" not in r.output
    assert _files(out) == before
    _no_rig(monkeypatch)
    r = runner.invoke(app, ["run", "--resume", str(out), "--rebuild-journal"])  # the mend named
    assert r.exit_code == 0, r.output
    assert _images(out) == _images(ref)


def test_a_completed_session_with_a_record_given_another_light_is_refused_untouched(
    made: tuple[Path, Path, Path], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A record whose light is not its step's proves nothing, not even which image was lost:
    the rebuild is refused, nothing moved."""
    _, ref, _ = made
    out = tmp_path / "done"
    shutil.copytree(ref, out)
    (out / "journal.jsonl").unlink()
    manifest = json.loads((out / "manifest.json").read_text())
    manifest["steps"][2]["led"] = manifest["schedule"]["steps"][3]["led"]
    (out / "manifest.json").write_text(json.dumps(manifest))
    before = _files(out)
    _no_rig(monkeypatch)
    r = runner.invoke(app, ["run", "--resume", str(out), "--rebuild-journal"])
    assert r.exit_code == 2, r.output
    assert "image_003 (its recorded light is not the one its step was given)" in said(r)
    assert "restore journal.jsonl (or those files) from a backup copy" in said(r)
    assert _files(out) == before


def test_a_completed_session_with_an_image_it_cannot_prove_is_rebuilt_then_made_whole(
    made: tuple[Path, Path, Path], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Journal lost and image_003.jpg corrupted: the rebuild had been refused whole for that
    one image, every provable image left unproven. Now the journal is rebuilt from every proven
    image, image_003 recorded as lost (its changed JPEG set aside, never deleted) with the one
    command that reshoots it; fit says what is lost, and --reshoot-lost makes it whole."""
    _, ref, _ = made
    out = tmp_path / "done"
    shutil.copytree(ref, out)
    (out / "journal.jsonl").unlink()
    corrupted = (out / "image_003.jpg").read_bytes()[:-100] + b"\0" * 100
    (out / "image_003.jpg").write_bytes(corrupted)
    with monkeypatch.context() as m:
        _no_rig(m)
        r = runner.invoke(app, ["run", "--resume", str(out), "--rebuild-journal"])
    assert r.exit_code == 0, r.output
    reshoot = f"rti-rig run --resume {out} --reshoot-lost"
    assert "7 image(s) taken back" in said(r), r.output
    assert (
        "1 image(s) recorded as captured and lost (image_003: image_003.jpg changed since"
        in said(r)
    )
    assert "but the session is not whole: 1 image(s) lost since capture (image_003" in said(r)
    assert reshoot in said(r) and "whole again" not in said(r)
    (aside,) = (out / "recovered").rglob("unproven/image_003.jpg")
    assert aside.read_bytes() == corrupted
    # the journal holds all 8 records, as captured
    assert (out / "journal.jsonl").read_bytes() == (ref / "journal.jsonl").read_bytes()
    r = runner.invoke(app, ["fit", str(out), "--out", str(tmp_path / "fit"), "--model", "ps"])
    assert r.exit_code == 0, r.output
    assert "image_003" in said(r) and reshoot in said(r) and "not checked" not in said(r)
    # a lost image lights.lp no longer lists is still a session not whole: never "good"
    # (the verdict had read "good; 1 image missing or changed since capture …")
    assert "QA verdict: reshoot: image_003 (lost since capture, not fitted)" in said(r)
    qa = json.loads((tmp_path / "fit" / "qa.json").read_text())
    assert qa["good"] is False and qa["reshoot"] == ["image_003"], qa["verdict"]
    r = runner.invoke(app, ["run", "--resume", str(out), "--reshoot-lost", "--no-verdict"])
    assert r.exit_code == 0, r.output
    assert aside.read_bytes() == corrupted  # never overwritten
    r = runner.invoke(app, ["fit", str(out), "--out", str(tmp_path / "fit2"), "--model", "ps"])
    assert r.exit_code == 0 and "QA verdict: good" in said(r), r.output
    assert "missing or changed" not in said(r)
    assert _images(out) == _images(ref)


def _ctrl_c_once_relisted(monkeypatch: pytest.MonkeyPatch, real_relist) -> None:  # type: ignore[no-untyped-def]
    """A Ctrl-C arriving while the rebuilt journal is written: held by the block, acted on
    at its end (once ``_relist_verified`` has run)."""
    import rti_rig.runtime.session as session

    def relisted_then_stopped(*args, **kwargs):  # type: ignore[no-untyped-def]
        real_relist(*args, **kwargs)
        raise KeyboardInterrupt

    monkeypatch.setattr(session, "_relist_verified", relisted_then_stopped)


def test_a_stop_while_a_completed_session_is_rebuilt_says_what_it_left(
    made: tuple[Path, Path, Path], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Ctrl-C while the images are checked: nothing changed, and the same command again; one
    held while the journal is written acts once it is: the session is whole, and fit next."""
    import rti_rig.runtime.session as session

    _, ref, _ = made
    out = tmp_path / "done"
    shutil.copytree(ref, out)
    (out / "journal.jsonl").unlink()
    before = _files(out)
    real_provable, real_relist = session._provable_steps, session._relist_verified

    def stopped(*args, **kwargs):  # type: ignore[no-untyped-def]
        raise KeyboardInterrupt

    monkeypatch.setattr(session, "_provable_steps", stopped)
    r = runner.invoke(app, ["run", "--resume", str(out), "--rebuild-journal"])
    assert r.exit_code == 130, r.output
    assert "before journal.jsonl was rebuilt: nothing in" in said(r)
    assert f"rti-rig run --resume {out} --rebuild-journal again" in said(r)
    assert _files(out) == before

    monkeypatch.setattr(session, "_provable_steps", real_provable)

    _ctrl_c_once_relisted(monkeypatch, real_relist)
    r = runner.invoke(app, ["run", "--resume", str(out), "--rebuild-journal"])
    assert r.exit_code == 130, r.output
    assert "once journal.jsonl was rebuilt: the session is whole again" in said(r)
    assert (out / "journal.jsonl").read_bytes() == (ref / "journal.jsonl").read_bytes()


def test_a_completed_adaptive_session_is_rebuilt_to_where_it_stopped(tmp_path: Path) -> None:
    """An adaptive session completes below its maximum: the steps it took are all proven."""
    cfg = write_config(tmp_path, SMALL_DOME)
    out = tmp_path / "a"
    r = runner.invoke(
        app, ["run", str(cfg), "--out", str(out), "--lights", "8", "--until-error", "60"]
    )
    assert r.exit_code == 0, r.output
    journal = (out / "journal.jsonl").read_bytes()
    taken = len(journal.splitlines())
    assert taken < 8  # stopped by its rule, below its maximum
    (out / "journal.jsonl").unlink()
    r = runner.invoke(app, ["run", "--resume", str(out), "--rebuild-journal", "--no-verdict"])
    assert r.exit_code == 0, r.output
    assert f"{taken} image(s) taken back" in said(r)
    assert (out / "journal.jsonl").read_bytes() == journal


def test_a_rebuild_killed_before_its_journal_is_written_keeps_the_old_one(
    made: tuple[Path, Path, Path], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The old journal had been moved aside first: a kill before the new one was written left
    no journal, and the next rebuild, reading none, set aside and shot again the three images
    only its intact lines proved. The process dies here as the new journal is written (no
    code of the rebuild runs after it, as with SIGKILL)."""
    import rti_rig.runtime.session as session

    _, ref, _ = made
    out = _killed_after_its_manifest(made, tmp_path)
    damaged = (out / "journal.jsonl").read_bytes()
    real_write = session._write_bytes_atomic

    def killed(path: Path, data: bytes) -> None:
        if path.name == "journal.jsonl":
            raise KeyboardInterrupt  # stands for the kill: nothing after it runs
        real_write(path, data)

    monkeypatch.setattr(session, "_write_bytes_atomic", killed)
    r = runner.invoke(app, ["run", "--resume", str(out), "--rebuild-journal"])
    assert r.exit_code == 130, r.output
    assert (out / "journal.jsonl").read_bytes() == damaged
    monkeypatch.setattr(session, "_write_bytes_atomic", real_write)
    r = runner.invoke(app, ["run", "--resume", str(out), "--rebuild-journal"])
    assert r.exit_code == 0, r.output
    assert "and 3 from the old journal.jsonl's intact lines" in said(r), r.output
    assert _images(out) == _images(ref)


@pytest.mark.parametrize("flag", ["--rebuild-journal", "--reshoot-lost"])
def test_a_resume_stopped_before_it_went_on_names_the_command_that_continues_it(
    made: tuple[Path, Path, Path], tmp_path: Path, monkeypatch: pytest.MonkeyPatch, flag: str
) -> None:
    """A Ctrl-C while the rig opened had been told "continue it with rti-rig run --resume
    DIR": refused for a journal that needs the rebuild, and for a completed session's
    reshoot. The command named is the one given, which goes on."""
    import rti_rig.app.usecases.session as usecase

    _, ref, _ = made
    if flag == "--rebuild-journal":
        out = _damaged(made, tmp_path, "deleted")
    else:
        out = tmp_path / "s"
        shutil.copytree(ref, out)
        (out / "image_003.jpg").unlink()
    real = usecase.checked_rig

    def stopped(*args, **kwargs):  # type: ignore[no-untyped-def]
        raise KeyboardInterrupt

    monkeypatch.setattr(usecase, "checked_rig", stopped)
    r = runner.invoke(app, ["run", "--resume", str(out), flag])
    assert r.exit_code == 130, r.output
    named = f"continue it with rti-rig run --resume {out} {flag}."
    assert named in said(r), r.output
    monkeypatch.setattr(usecase, "checked_rig", real)
    r = runner.invoke(app, ["run", "--resume", str(out), flag, "--no-verdict"])
    assert r.exit_code == 0, r.output
    assert _images(out) == _images(ref)


def test_reshoot_lost_keeps_an_intact_image_whose_journal_line_was_lost(
    made: tuple[Path, Path, Path], tmp_path: Path
) -> None:  # see also the journal lost whole, below
    """A completed session: image_003's journal line overwritten (a sync tool), image_005.jpg
    deleted. --reshoot-lost had set image_003 aside and shot it again with image_005 (it keeps
    only the journaled images); the manifest proves it, so its record is restored and only
    image_005 is reshot."""
    _, ref, _ = made
    out = tmp_path / "done"
    shutil.copytree(ref, out)
    journal = out / "journal.jsonl"
    lines = journal.read_bytes().split(b"\n")
    lines[2] = b"\x00" * len(lines[2])
    journal.write_bytes(b"\n".join(lines))
    (out / "image_005.jpg").unlink()
    kept = {n: (out / n).stat().st_ino for n in ("image_003.jpg", "linear/image_003.tif")}
    r = runner.invoke(app, ["run", "--resume", str(out), "--reshoot-lost", "--no-verdict"])
    assert r.exit_code == 0, r.output
    assert "1 record(s) it had lost restored from manifest.json (image_003)" in said(r)
    assert "1 of those images kept, their files as recorded (image_003), not reshot" in said(r)
    assert "1 of 8 light" in said(r)
    assert {n: (out / n).stat().st_ino for n in kept} == kept  # never moved
    aside = sorted(p.name for p in (out / "recovered").rglob("image_*"))
    assert aside == ["image_005.tif"]
    assert _images(out) == _images(ref)
    r = runner.invoke(app, ["fit", str(out), "--out", str(tmp_path / "fit")])
    assert r.exit_code == 0 and "not checked" not in said(r), r.output


def test_reshoot_lost_with_nothing_lost_names_the_rebuild_of_a_line_it_cannot_check(
    made: tuple[Path, Path, Path], tmp_path: Path
) -> None:
    """It had advised a backup alone, of a journal line the manifest can restore."""
    out = tmp_path / "done"
    shutil.copytree(made[1], out)
    journal = out / "journal.jsonl"
    lines = journal.read_bytes().split(b"\n")
    lines[2] = b"\x00" * len(lines[2])
    journal.write_bytes(b"\n".join(lines))
    r = runner.invoke(app, ["run", "--resume", str(out), "--reshoot-lost"])
    assert r.exit_code == 2, r.output
    assert "finds nothing lost" in said(r)
    assert f"rti-rig run --resume {out} --rebuild-journal, then run this again" in said(r)


def test_reshoot_lost_of_a_session_whose_journal_is_lost_reshoots_only_the_lost_image(
    made: tuple[Path, Path, Path], tmp_path: Path
) -> None:
    """A completed session without its journal and with image_005.jpg deleted: --reshoot-lost
    had found nothing it could check, and the rebuild (every image as captured) refused for
    image_005: no way on without a backup. The manifest's records are restored; only
    image_005 is reshot."""
    _, ref, _ = made
    out = tmp_path / "done"
    shutil.copytree(ref, out)
    (out / "journal.jsonl").unlink()
    (out / "image_005.jpg").unlink()
    reshoot = f"rti-rig run --resume {out} --reshoot-lost"
    # export-lp names the reshoot (it had named a backup alone)
    r = runner.invoke(app, ["export-lp", str(out), "--out", str(tmp_path / "x.lp")])
    assert r.exit_code == 2 and "as image_005 is missing or changed since capture" in said(r)
    assert f"with the object where it was: {reshoot}" in said(r), r.output
    r = runner.invoke(app, ["run", "--resume", str(out), "--reshoot-lost", "--no-verdict"])
    assert r.exit_code == 0, r.output
    assert "8 record(s) it had lost restored" in said(r) and "7 of those images kept" in said(r)
    assert sorted(p.name for p in (out / "recovered").rglob("image_*")) == ["image_005.tif"]
    assert _images(out) == _images(ref)
    r = runner.invoke(app, ["fit", str(out), "--out", str(tmp_path / "fit")])
    assert r.exit_code == 0 and "not checked" not in said(r), r.output
    assert "QA verdict: good" in said(r)


def test_a_stop_held_while_a_rebuild_records_an_image_lost_says_it_is_not_whole(
    made: tuple[Path, Path, Path], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A Ctrl-C held while the journal of a completed session with image_004.jpg deleted is
    rebuilt: acted on once it is; "the session is whole again" must not be said, but what
    is lost and the reshoot that gets it back."""
    import rti_rig.runtime.session as session

    _, ref, _ = made
    out = tmp_path / "done"
    shutil.copytree(ref, out)
    (out / "journal.jsonl").unlink()
    (out / "image_004.jpg").unlink()
    real_relist = session._relist_verified

    _ctrl_c_once_relisted(monkeypatch, real_relist)
    r = runner.invoke(app, ["run", "--resume", str(out), "--rebuild-journal"])
    assert r.exit_code == 130, r.output
    assert "whole again" not in said(r), r.output
    assert "once journal.jsonl was rebuilt: 1 image(s) lost since capture (image_004" in said(r)
    assert f"rti-rig run --resume {out} --reshoot-lost" in said(r)
    assert (out / "journal.jsonl").read_bytes() == (ref / "journal.jsonl").read_bytes()


def test_a_rebuild_of_a_whole_journal_names_the_image_lost_and_its_reshoot(
    made: tuple[Path, Path, Path], tmp_path: Path
) -> None:
    """A completed session with its journal intact and image_006.jpg deleted: a user reaching
    for --rebuild-journal was told "nothing to rebuild" and sent to a fit to find out what was
    wrong. Now what is lost is named with the reshoot; nothing changes."""
    _, ref, _ = made
    out = tmp_path / "done"
    shutil.copytree(ref, out)
    (out / "image_006.jpg").unlink()
    before = _files(out)
    r = runner.invoke(app, ["run", "--resume", str(out), "--rebuild-journal"])
    assert r.exit_code == 2 and "nothing to rebuild" in said(r), r.output
    assert "1 image(s) lost since capture (image_006: image_006.jpg missing)" in said(r)
    assert said(r).endswith(f"rti-rig run --resume {out} --reshoot-lost"), r.output
    assert _files(out) == before
