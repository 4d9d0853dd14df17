"""A session whose manifest or journal was damaged outside rti-rig, through the front door.

Found by an input audit: a manifest holding JSON that is no object (a list, null, a string) or
binary bytes gave a Python traceback on export-lp, fit, run --resume and calibrate-lights; with
the journal gone or a line of it damaged, the QA verdict said "good" for a session with a
changed JPEG and export-lp left an image out without a word, because nothing could be checked
and nothing said so. A config's negative scene seed was numpy's traceback.
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest
from conftest import CONFIGS, shipped_variant
from typer.testing import CliRunner

from rti_rig.cli import app

runner = CliRunner()


def said(result) -> str:  # type: ignore[no-untyped-def]
    return " ".join(result.output.split())


SMALL = (("width = 512", "width = 96"), ("height = 512", "height = 96"))


@pytest.fixture(scope="module")
def session(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """12 lights of the shipped simulated dome at 96 px: the damage these tests do is to the
    session's files (manifest, journal, records, images), and what is said of it is the files',
    not the frame size's; each fit of a copy is the cheaper for it."""
    rig = shipped_variant(tmp_path_factory.mktemp("rig"), "simulated_dome.toml", SMALL)
    out = tmp_path_factory.mktemp("dry") / "s"
    r = runner.invoke(app, ["run", str(rig), "--out", str(out), "--lights", "12"])
    assert r.exit_code == 0, r.output
    return out


def _copy(session: Path, tmp_path: Path) -> Path:
    copy = tmp_path / "s"
    shutil.copytree(session, copy)
    return copy


@pytest.mark.parametrize(
    ("content", "kind"),
    [(b"[1, 2, 3]", "array"), (b"null", "null"), (b'"hi"', "string"), (b"\xff\xfe\x00", "JSON")],
)
def test_a_manifest_that_is_no_object_is_named_not_a_traceback(
    session: Path, tmp_path: Path, content: bytes, kind: str
) -> None:
    s = _copy(session, tmp_path)
    (s / "manifest.json").write_bytes(content)
    for args in (
        ["export-lp", str(s), "--out", str(tmp_path / "a.lp")],
        ["run", "--resume", str(s)],
        ["calibrate-lights", str(s), "--rig", str(CONFIGS / "emulated_dome.toml")],
    ):
        r = runner.invoke(app, args)
        text = said(r)
        assert r.exit_code not in (0, None) and isinstance(r.exception, SystemExit), (args, text)
        assert "Traceback" not in r.output, (args, r.output)
        assert "manifest.json" in text and kind in text, (args, text)
        assert "restore manifest.json from a backup copy" in text, (args, text)
    # fit reads lights.lp, not the manifest: it fits, and its verdict says what it could not check
    r = runner.invoke(app, ["fit", str(s), "--out", str(tmp_path / "fit")])
    assert r.exit_code == 0, r.output
    verdict = json.loads((tmp_path / "fit" / "qa.json").read_text())["verdict"]
    assert "not checked against their capture checksums (manifest.json unreadable)" in verdict
    assert "restore manifest.json from a backup copy" in verdict  # not the journal


def test_a_missing_journal_is_said_by_the_verdict_and_export_lp(
    session: Path, tmp_path: Path
) -> None:
    s = _copy(session, tmp_path)
    jpeg = s / "image_004.jpg"
    jpeg.write_bytes(jpeg.read_bytes()[:-200] + b"\x00" * 200)  # changed since capture
    (s / "journal.jsonl").unlink()
    shutil.rmtree(s / "records")  # and its step record files: the manifest alone
    r = runner.invoke(app, ["fit", str(s), "--out", str(tmp_path / "fit")])
    assert r.exit_code == 0, r.output
    qa = json.loads((tmp_path / "fit" / "qa.json").read_text())
    assert any("not checked against their capture checksums" in c for c in qa["caveats"]), qa
    assert "journal.jsonl is missing" in qa["verdict"] and "image_004" in qa["verdict"]
    r = runner.invoke(app, ["export-lp", str(s), "--out", str(tmp_path / "a.lp")])
    assert r.exit_code != 0 and "journal.jsonl is missing" in said(r), r.output


def test_a_damaged_journal_line_proven_by_its_record_file_is_checked_and_said(
    session: Path, tmp_path: Path
) -> None:
    """Its step record file (records/image_006.json) proves image_006: checked against it,
    fitted and listed, and the verdict says the journal is damaged and what mends it."""
    s = _copy(session, tmp_path)
    journal = s / "journal.jsonl"
    lines = journal.read_text().splitlines(keepends=True)
    journal.write_text("".join(lines[:5]) + lines[5][:40] + "\n" + "".join(lines[6:]))
    r = runner.invoke(app, ["fit", str(s), "--out", str(tmp_path / "fit")])
    assert r.exit_code == 0, r.output
    verdict = json.loads((tmp_path / "fit" / "qa.json").read_text())["verdict"]
    assert "not checked" not in verdict, verdict
    assert (
        "journal.jsonl is damaged (line 6 unreadable) and holds no record of image_006: it was "
        "checked against its step record file (records/) instead, as captured; "
        f"rti-rig run --resume {s} --rebuild-journal writes it back into journal.jsonl"
    ) in verdict, verdict
    r = runner.invoke(app, ["export-lp", str(s), "--out", str(tmp_path / "a.lp")])
    assert r.exit_code == 0, r.output
    assert "image_006" in (tmp_path / "a.lp").read_text()
    r = runner.invoke(app, ["run", "--resume", str(s), "--rebuild-journal"])
    assert r.exit_code == 0, r.output
    assert [json.loads(x)["index"] for x in journal.read_text().splitlines()] == list(range(12))
    r = runner.invoke(app, ["fit", str(s), "--out", str(tmp_path / "fit2")])
    verdict = json.loads((tmp_path / "fit2" / "qa.json").read_text())["verdict"]
    assert r.exit_code == 0 and verdict == "good", verdict


def test_a_damaged_journal_line_is_said_by_the_verdict_and_export_lp(
    session: Path, tmp_path: Path
) -> None:
    """Without its step record file (a session written before them, or the file lost too)."""
    s = _copy(session, tmp_path)
    (s / "records" / "image_006.json").unlink()
    journal = s / "journal.jsonl"
    lines = journal.read_text().splitlines(keepends=True)
    journal.write_text("".join(lines[:5]) + lines[5][:40] + "\n" + "".join(lines[6:]))
    r = runner.invoke(app, ["fit", str(s), "--out", str(tmp_path / "fit")])
    assert r.exit_code == 0, r.output
    verdict = json.loads((tmp_path / "fit" / "qa.json").read_text())["verdict"]
    assert "image_006 not checked against its capture checksum" in verdict, verdict
    assert "journal.jsonl line 6 unreadable" in verdict
    r = runner.invoke(app, ["export-lp", str(s), "--out", str(tmp_path / "a.lp")])
    assert r.exit_code == 0, r.output
    assert "not verifiable as captured (journal.jsonl line 6 unreadable): image_006" in said(r)
    assert "image_006" not in (tmp_path / "a.lp").read_text()


def test_an_intact_session_has_no_integrity_caveat(session: Path, tmp_path: Path) -> None:
    r = runner.invoke(app, ["fit", str(session), "--out", str(tmp_path / "fit")])
    assert r.exit_code == 0, r.output
    qa = json.loads((tmp_path / "fit" / "qa.json").read_text())
    assert not any("capture checksum" in c for c in qa["caveats"]), qa["caveats"]


def test_a_negative_scene_seed_is_a_named_config_error(tmp_path: Path) -> None:
    text = (CONFIGS / "simulated_dome.toml").read_text()
    assert "seed = 0" in text
    cfg = tmp_path / "rig.toml"
    cfg.write_text(text.replace("seed = 0", "seed = -1"))
    r = runner.invoke(app, ["check", str(cfg)])
    assert r.exit_code != 0 and "Traceback" not in r.output
    assert "seed" in said(r) and "must be at least 0 (got -1)" in said(r), r.output


def test_an_unwritable_out_is_refused_before_the_rig_lights(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """On a read-only disk a session had lit the rig and begun capturing before finding it
    could not write its first image. The folder's nearest existing parent is checked first.
    (The test stands in for a read-only mount, which needs privileges to make, by the
    operating system's answer for that folder.)"""
    import os

    import rti_rig.runtime.session as session_module

    locked = tmp_path / "locked"
    locked.mkdir()
    real_access = os.access

    def access(path, mode, *args, **kwargs):  # type: ignore[no-untyped-def]
        if Path(path) == locked and mode & os.W_OK:
            return False
        return real_access(path, mode, *args, **kwargs)

    monkeypatch.setattr(session_module.os, "access", access)
    out = locked / "new" / "s"
    r = runner.invoke(
        app, ["run", str(CONFIGS / "simulated_dome.toml"), "--out", str(out), "--lights", "6"]
    )
    text = said(r)
    assert r.exit_code != 0 and "cannot write there" in text and str(locked) in text, text
    assert "capturing" not in text and "Rig simulated-dome-48" not in text
    assert not (locked / "new").exists()


def test_the_verdict_of_an_unfinished_session_says_so(tmp_path: Path) -> None:
    """An adaptive session cancelled after 5 of at most 8 images was fitted with "QA verdict:
    good" and no word that it was unfinished and could be continued."""
    from conftest import SMALL_DOME, interrupted, write_config

    cfg = write_config(tmp_path, SMALL_DOME)
    part = tmp_path / "part"
    interrupted(cfg, part, after_step=4, lights=8)
    r = runner.invoke(app, ["fit", str(part), "--out", str(tmp_path / "fit")])
    assert r.exit_code == 0, r.output
    verdict = json.loads((tmp_path / "fit" / "qa.json").read_text())["verdict"]
    assert "the session is not finished (5 of at most 8 images; stopped by Ctrl-C)" in verdict
    assert f"rti-rig run --resume {part}" in verdict
    # finished, it says nothing of the kind
    r = runner.invoke(app, ["run", "--resume", str(part)])
    assert r.exit_code == 0, r.output
    r = runner.invoke(app, ["fit", str(part), "--out", str(tmp_path / "fit2")])
    verdict = json.loads((tmp_path / "fit2" / "qa.json").read_text())["verdict"]
    assert "not finished" not in verdict, verdict


def test_a_new_session_into_a_finished_one_is_not_offered_a_resume(session: Path) -> None:
    """It had said "or continue the interrupted session in it with rti-rig run --resume",
    which then answered "already completed"."""
    r = runner.invoke(
        app, ["run", str(CONFIGS / "simulated_dome.toml"), "--out", str(session), "--lights", "6"]
    )
    text = said(r)
    assert r.exit_code != 0 and "is not empty" in text, text
    assert "--resume" not in text and "it holds a finished session: fit it with" in text
    # a real, free folder beside it, pasteable as said (it had said --out DIR)
    advised = text.split("fit it with ", 1)[1].split(")", 1)[0]
    assert advised == f"rti-rig fit {session} --out {session}-fit", advised
    assert not Path(f"{session}-fit").exists()


def test_reshoot_lost_does_not_vouch_for_what_it_cannot_check(
    session: Path, tmp_path: Path
) -> None:
    """Found by a review: with image_006's journal line damaged and its files deleted,
    --reshoot-lost answered "every image is as captured". The manifest's record of it (its
    step's light) is restored, so it is found lost, and reshot alone."""
    s = _copy(session, tmp_path)
    journal = s / "journal.jsonl"
    lines = journal.read_text().splitlines(keepends=True)
    journal.write_text("".join(lines[:5]) + lines[5][:40] + "\n" + "".join(lines[6:]))
    (s / "image_006.jpg").unlink()
    (s / "linear" / "image_006.tif").unlink()
    r = runner.invoke(app, ["fit", str(s), "--out", str(tmp_path / "fit")])
    assert r.exit_code != 0 and "image_006" in said(r), said(r)  # lights.lp lists it: named
    r = runner.invoke(app, ["run", "--resume", str(s), "--reshoot-lost", "--no-verdict"])
    text = said(r)
    assert r.exit_code == 0 and "every image is as captured" not in text, text
    assert "1 record(s) it had lost restored from manifest.json (image_006)" in text
    assert "none of those images is as recorded" in text and "1 of 12 light" in text
    r = runner.invoke(app, ["fit", str(s), "--out", str(tmp_path / "fit2")])
    assert r.exit_code == 0 and "QA verdict: good" in said(r), said(r)


def test_a_missing_manifest_is_said_by_fit(session: Path, tmp_path: Path) -> None:
    """A session that lost its manifest.json had been fitted, and judged "good", without a
    word (run --resume refuses the folder as "not an rti-rig session folder"). fit still fits
    it from lights.lp — its images are vouched for by the journal — and says what is missing."""
    s = _copy(session, tmp_path)
    (s / "manifest.json").unlink()
    r = runner.invoke(app, ["fit", str(s), "--out", str(tmp_path / "fit")])
    assert r.exit_code == 0, r.output
    text = said(r)
    assert f"note: {s} is a session folder without its manifest.json: fitted from" in text
    assert "cannot be resumed; restore the manifest from a copy of the session" in text
    # and run --resume says the same of it (it had called it "not an rti-rig session folder")
    r = runner.invoke(app, ["run", "--resume", str(s)])
    assert r.exit_code == 2, r.output
    assert f"{s} is a session folder without its manifest.json" in said(r), said(r)
    assert "restore manifest.json from a backup copy" in said(r)
    # a folder of images and an .lp that never was a session (no journal, and none of the
    # image_NNN names rti-rig gives, which are said as a session whose record is lost) gets
    # no such note
    plain = tmp_path / "plain"
    plain.mkdir()
    from rti_rig.core.lp_format import LpEntry, read_lp, write_lp

    renamed = []
    for e in read_lp(s / "lights.lp"):
        name = "photo_" + e.name.removeprefix("image_")
        shutil.copy(s / e.name, plain / name)
        renamed.append(LpEntry(name, e.direction))
    write_lp(plain / "lights.lp", renamed)
    r = runner.invoke(app, ["fit", str(plain), "--out", str(tmp_path / "fit2")])
    assert r.exit_code == 0, r.output
    assert "manifest.json" not in said(r)


def test_fit_of_a_path_that_does_not_exist_says_so(tmp_path: Path) -> None:
    """A typo in fit's source had been told "give a session folder or an .lp file", as if the
    path were of the wrong kind."""
    r = runner.invoke(app, ["fit", str(tmp_path / "sesion"), "--out", str(tmp_path / "fit")])
    assert r.exit_code == 2, r.output
    assert f"{tmp_path / 'sesion'} does not exist" in said(r)
    assert not (tmp_path / "fit").exists()
