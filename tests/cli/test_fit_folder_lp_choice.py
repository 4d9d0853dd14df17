"""``rti-rig fit FOLDER`` of a folder without lights.lp holding more than one ``.lp``.

It had been fitted from the first ``.lp`` in name order: an acquisition folder with its
``dirs.lp`` and a 4-light ``a_subset.lp`` beside it was fitted from the subset, verdict
"good", not a word said. Which ``.lp`` lists the folder's lights cannot be told, so it is now
refused, naming them and the command that fits the one meant; with one ``.lp`` it is fitted.
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest
from conftest import SMALL_DOME, said, write_config
from typer.testing import CliRunner

from rti_rig.cli import app

runner = CliRunner()


@pytest.fixture(scope="module")
def session(tmp_path_factory: pytest.TempPathFactory) -> Path:
    base = tmp_path_factory.mktemp("lpchoice")
    cfg = write_config(base, SMALL_DOME)
    out = base / "s"
    r = runner.invoke(app, ["run", str(cfg), "--out", str(out), "--lights", "8", "--no-verdict"])
    assert r.exit_code == 0, r.output
    return out


def _subset(lp: Path, dest: Path, n: int) -> None:
    lines = lp.read_text().splitlines()
    dest.write_text("\n".join([str(n), *lines[1 : n + 1]]) + "\n")


def test_a_folder_with_two_lp_files_and_no_lights_lp_is_refused(
    session: Path, tmp_path: Path
) -> None:
    acq = tmp_path / "acq"
    acq.mkdir()
    for jpg in session.glob("image_*.jpg"):
        shutil.copy(jpg, acq / jpg.name)
    shutil.copy(session / "lights.lp", acq / "dirs.lp")
    _subset(session / "lights.lp", acq / "a_subset.lp", 4)
    r = runner.invoke(app, ["fit", str(acq), "--out", str(tmp_path / "fit")])
    assert r.exit_code == 2, r.output
    assert "2 .lp files and no lights.lp (a_subset.lp, dirs.lp)" in said(r)
    # the file to give instead, with the user's own --out (not a template "--out DIR" that,
    # pasted, made a folder named DIR)
    assert f"giving it in the folder's place, with the same --out (e.g. {acq / 'a_subset.lp'})" in (
        said(r)
    )
    assert "DIR" not in said(r)
    assert not (tmp_path / "fit").exists()
    r = runner.invoke(app, ["fit", str(acq / "dirs.lp"), "--out", str(tmp_path / "fit")])
    assert r.exit_code == 0, r.output
    (acq / "a_subset.lp").unlink()  # one .lp: it is the folder's
    r = runner.invoke(app, ["fit", str(acq), "--out", str(tmp_path / "fit1")])
    assert r.exit_code == 0, r.output


def test_a_session_without_its_lights_lp_and_two_others_names_the_rebuild(
    session: Path, tmp_path: Path
) -> None:
    s = tmp_path / "s"
    shutil.copytree(session, s)
    _subset(s / "lights.lp", s / "first4.lp", 4)
    (s / "lights.lp").rename(s / "all.lp")
    r = runner.invoke(app, ["fit", str(s), "--out", str(tmp_path / "fit")])
    assert r.exit_code == 2, r.output
    assert "(all.lp, first4.lp)" in said(r)
    assert f"rti-rig export-lp {s} --out {s / 'lights.lp'}" in said(r)


def test_export_lp_force_replaces_the_users_own_lp_in_the_session(
    session: Path, tmp_path: Path
) -> None:
    """The guide puts an exported .lp in the session folder (tools read its names beside it);
    exporting it again with --force had been refused as "a file of the session", though
    --force says it overwrites. The session's own files stay refused."""
    s = tmp_path / "s"
    shutil.copytree(session, s)
    mine = s / "linear.lp"
    r = runner.invoke(app, ["export-lp", str(s), "--out", str(mine), "--linear"])
    assert r.exit_code == 0, r.output
    mine.write_text("2\nimage_001.jpg 0 0 1\nimage_002.jpg 0 1 0\n")  # stale
    r = runner.invoke(app, ["export-lp", str(s), "--out", str(mine), "--linear"])
    assert r.exit_code == 2 and "--force" in said(r), r.output
    r = runner.invoke(app, ["export-lp", str(s), "--out", str(mine), "--linear", "--force"])
    assert r.exit_code == 0, r.output
    assert mine.read_text().startswith("8\nlinear/image_001.tif")
    for own in ("manifest.json", "journal.jsonl", "image_001.jpg"):
        before = (s / own).read_bytes()
        r = runner.invoke(app, ["export-lp", str(s), "--out", str(s / own), "--force"])
        assert r.exit_code == 2 and "never overwritten" in said(r), (own, r.output)
        assert (s / own).read_bytes() == before
    # lights.lp, the listing the run writes from the journal: never of another kind (--linear)
    before = (s / "lights.lp").read_bytes()
    r = runner.invoke(app, ["export-lp", str(s), "--out", str(s / "lights.lp"), "--linear"])
    assert r.exit_code == 2 and "never overwritten" in said(r), r.output
    r = runner.invoke(app, ["export-lp", str(s), "--out", str(s / "lights.lp")])  # the same
    assert r.exit_code == 0 and "left as it is" in said(r), r.output
    assert "already lists them" in said(r) and "→" not in said(r), r.output
    assert (s / "lights.lp").read_bytes() == before


def test_a_lights_lp_edited_since_capture_is_named_against_the_journal(
    session: Path, tmp_path: Path
) -> None:
    """Two lines' directions swapped in lights.lp: the verdict blamed the images ("reshoot:
    image_002 (wrong light …)"), which were as captured; the journal holds the lights that
    fired, and it is the .lp that is now named, with how to write it again."""
    s = tmp_path / "s"
    shutil.copytree(session, s)
    lines = (s / "lights.lp").read_text().splitlines()
    a, b = lines[2].split(), lines[5].split()
    lines[2], lines[5] = " ".join([a[0], *b[1:]]), " ".join([b[0], *a[1:]])
    (s / "lights.lp").write_text("\n".join(lines) + "\n")
    r = runner.invoke(app, ["fit", str(s), "--out", str(tmp_path / "fit")])
    assert r.exit_code == 0, r.output
    assert "lights.lp gives image_002, image_005 another light than the journal" in said(r)
    assert f"rti-rig export-lp {s} --out {s / 'lights.lp'}" in said(r)
    # a defect of what was fitted, not a check left unmade: the verdict is not "good" (it had
    # been, in qa.json too, the note a caveat after it; a script reading "good" archived it)
    assert "QA verdict: lights.lp wrong: lights.lp gives image_002" in said(r), said(r)
    assert _qa(tmp_path / "fit")["good"] is False
    (s / "lights.lp").rename(tmp_path / "edited.lp")
    r = runner.invoke(app, ["export-lp", str(s), "--out", str(s / "lights.lp")])
    assert r.exit_code == 0, r.output
    r = runner.invoke(app, ["fit", str(s), "--out", str(tmp_path / "fit2")])
    assert r.exit_code == 0 and "another light than the journal" not in said(r), r.output
    assert _qa(tmp_path / "fit2")["good"] is True


def _qa(fit: Path) -> dict:  # type: ignore[type-arg]
    return json.loads((fit / "qa.json").read_text())


@pytest.mark.parametrize(("decimals", "wrong"), [(3, False), (2, True)])
def test_a_lights_lp_rounded_to_three_decimals_is_the_journals_lights(
    session: Path, tmp_path: Path, decimals: int, wrong: bool
) -> None:
    """lights.lp rewritten with three decimals (a spreadsheet's, another tool's): every light
    moves by up to ~0.05°, rounding noise, which had been judged "lights.lp wrong: lights.lp
    gives image_001, … another light than the journal records" (the .lp's own six decimals
    were all it took). Two decimals move a light by up to ~0.5°: still named."""
    s = tmp_path / "s"
    shutil.copytree(session, s)
    lines = (s / "lights.lp").read_text().splitlines()
    rounded = [lines[0]] + [
        " ".join([w[0], *(f"{float(v):.{decimals}f}" for v in w[1:])])
        for w in (line.split() for line in lines[1:])
    ]
    (s / "lights.lp").write_text("\n".join(rounded) + "\n")
    r = runner.invoke(app, ["fit", str(s), "--out", str(tmp_path / "fit")])
    assert r.exit_code == 0, r.output
    assert ("another light than the journal" in said(r)) is wrong, said(r)
    assert _qa(tmp_path / "fit")["good"] is not wrong


def test_a_lights_lp_out_of_name_order_is_named_for_relight(session: Path, tmp_path: Path) -> None:
    """lights.lp's lines reversed by hand: the fit pairs by name and said "good", but relight
    pairs the lines with the JPEGs in name order, every image under another's light."""
    s = tmp_path / "s"
    shutil.copytree(session, s)
    count, *lines = (s / "lights.lp").read_text().splitlines()
    (s / "lights.lp").write_text("\n".join([count, *reversed(lines)]) + "\n")
    r = runner.invoke(app, ["fit", str(s), "--out", str(tmp_path / "fit")])
    assert r.exit_code == 0, r.output
    assert "lights.lp lists the images out of their name order" in said(r)
    assert _qa(tmp_path / "fit")["good"] is False
    assert f"rti-rig export-lp {s} --out {s / 'lights.lp'}" in said(r)


def test_a_captured_image_left_out_of_lights_lp_is_named(session: Path, tmp_path: Path) -> None:
    """A line deleted from lights.lp by hand: 7 images fitted, "good", of a session of 8 on
    disk (relight pairs 7 lines with 8 JPEGs)."""
    s = tmp_path / "s"
    shutil.copytree(session, s)
    lines = (s / "lights.lp").read_text().splitlines()
    del lines[4]
    (s / "lights.lp").write_text("\n".join(["7", *lines[1:]]) + "\n")
    r = runner.invoke(app, ["fit", str(s), "--out", str(tmp_path / "fit")])
    assert r.exit_code == 0, r.output
    assert "lights.lp does not list image_004, captured and on disk" in said(r)
    assert _qa(tmp_path / "fit")["good"] is False


def test_a_shuffled_lights_lp_names_its_journal_and_fix_first(
    session: Path, tmp_path: Path
) -> None:
    """Every line's direction moved to another: the QA also finds the lights likely wrong, and
    that branch had dropped the journal's finding and its export-lp (a review of the defect's
    first form found it)."""
    s = tmp_path / "s"
    shutil.copytree(session, s)
    count, *lines = (s / "lights.lp").read_text().splitlines()
    fields = [line.split() for line in lines]
    rolled = [[f[0], *g[1:]] for f, g in zip(fields, fields[3:] + fields[:3], strict=True)]
    (s / "lights.lp").write_text("\n".join([count, *(" ".join(f) for f in rolled)]) + "\n")
    r = runner.invoke(app, ["fit", str(s), "--out", str(tmp_path / "fit")])
    assert r.exit_code == 0, r.output
    assert "QA verdict: lights.lp wrong: lights.lp gives" in said(r), said(r)
    assert f"rti-rig export-lp {s} --out {s / 'lights.lp'}" in said(r)
    qa = _qa(tmp_path / "fit")
    assert qa["good"] is False and "another light than the journal" in qa["lp_defect"]


def test_another_lp_with_measured_lights_is_a_note_not_a_defect(
    session: Path, tmp_path: Path
) -> None:
    """An .lp of the user's beside the images (lights measured on a sphere, each nudged a
    little) fitted on purpose: the journal's finding is a caveat, not "lights.lp wrong"."""
    s = tmp_path / "s"
    shutil.copytree(session, s)
    count, *lines = (s / "lights.lp").read_text().splitlines()
    nudged = []
    for line in lines:
        name, *xyz = line.split()
        x, y, z = (float(v) for v in xyz)
        x, y = x + 0.01, y - 0.01
        n = (x * x + y * y + z * z) ** 0.5
        nudged.append(f"{name} {x / n:.6f} {y / n:.6f} {z / n:.6f}")
    (s / "measured.lp").write_text("\n".join([count, *nudged]) + "\n")
    r = runner.invoke(app, ["fit", str(s / "measured.lp"), "--out", str(tmp_path / "fit")])
    assert r.exit_code == 0, r.output
    qa = _qa(tmp_path / "fit")
    assert qa["lp_defect"] == "", qa["verdict"]
    assert any("measured.lp gives" in c for c in qa["caveats"]), qa["caveats"]
    assert "lights.lp wrong" not in qa["verdict"]
