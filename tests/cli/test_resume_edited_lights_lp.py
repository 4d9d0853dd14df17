"""A ``lights.lp`` edited by hand in a stopped session, then ``run --resume``: the resume writes
``lights.lp`` again from the journal (the record of the lights that fired), and had written it
over the user's edit with no copy and no word. Now the edited file is moved to
``recovered/STAMP/lights.lp`` first and the resume says so, naming both files; a ``lights.lp``
rti-rig wrote itself (one image short too, when the run was killed after an image's journal
line or record file and before ``lights.lp`` listed it) is neither copied nor said anything of.
"""

from __future__ import annotations

import json
import signal
from pathlib import Path

import pytest
from conftest import CONFIGS, said
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.core.lp_format import LpEntry, format_lp, read_lp
from rti_rig.testing.kill_hooks import popen_argv, popen_session

runner = CliRunner()
LIGHTS = 8


def _killed(tmp_path: Path, stage: str = "before_light", k: int = 3) -> Path:
    """A shipped-config dry run SIGKILLed at ``stage`` of step ``k`` (0-based)."""
    out = tmp_path / "s"
    proc = popen_session(stage, k, CONFIGS / "simulated_dome.toml", out, LIGHTS)
    _, stderr = proc.communicate(timeout=300)
    assert proc.returncode == -signal.SIGKILL, stderr.decode()
    return out


def _journal_lp(out: Path) -> bytes:
    """The ``lights.lp`` the journal's lights make, as rti-rig writes it."""
    records = [json.loads(line) for line in (out / "journal.jsonl").read_text().splitlines()]
    latest = {r["index"]: r for r in records}
    entries = [LpEntry(r["image"], tuple(r["actual_direction"])) for _, r in sorted(latest.items())]
    return format_lp(entries).encode("ascii")


def _resume(out: Path) -> str:
    r = runner.invoke(app, ["run", "--resume", str(out), "--no-verdict"])
    assert r.exit_code == 0, r.output
    return said(r)


def _kept(out: Path) -> list[Path]:
    return sorted((out / "recovered").rglob("lights.lp"))


@pytest.mark.slow
@pytest.mark.e2e
def test_a_lights_lp_edited_by_hand_is_kept_in_recovered_and_said(tmp_path: Path) -> None:
    out = _killed(tmp_path)
    lp = out / "lights.lp"
    assert lp.read_bytes() == _journal_lp(out)  # the run's own listing of its 3 images
    lines = lp.read_text().splitlines()
    name, *_ = lines[2].split()
    lines[2] = f"{name} 0.0 0.6 0.8"  # a light corrected by hand
    edited = "\n".join([lines[0], "# image_002 re-measured on the bench", *lines[1:]]) + "\n"
    lp.write_text(edited)

    text = _resume(out)

    (kept,) = _kept(out)
    assert kept.read_text() == edited  # the user's file, byte for byte
    stamp = kept.parent.name
    assert (
        f"{lp} differs from what rti-rig wrote from journal.jsonl (edited by hand?): kept as "
        f"{kept}; lights.lp is written again from the journal, which is the record of the "
        f"lights that fired; to keep your edit, make it again in {lp} once this run has ended"
    ) in text, text
    assert f"(what it set aside is in recovered/{stamp}/)" in text, text
    # the session's lights.lp is the journal's, every image listed
    assert lp.read_bytes() == _journal_lp(out)
    assert [e.name for e in read_lp(lp)] == [f"image_{i:03d}.jpg" for i in range(1, LIGHTS + 1)]
    manifest = json.loads((out / "manifest.json").read_text())
    assert f"recovered/{stamp}/lights.lp" in manifest["runs"][-1]["recovered_files"]


@pytest.mark.slow
@pytest.mark.e2e
def test_a_line_deleted_by_hand_is_an_edit_and_a_second_edit_keeps_the_first_copy(
    tmp_path: Path,
) -> None:
    """A line deleted (image_002 left out of the fit by hand) is kept too, though every line
    left is rti-rig's own; a resume stopped again and edited again keeps both copies."""
    out = _killed(tmp_path)
    lp = out / "lights.lp"
    first = lp.read_text().replace("3\n", "2\n", 1)
    first = "".join(line for line in first.splitlines(True) if not line.startswith("image_002"))
    lp.write_text(first)
    proc = popen_argv("before_light", 2, ["run", "--resume", str(out), "--no-verdict"])
    stdout, stderr = proc.communicate(timeout=300)
    assert proc.returncode == -signal.SIGKILL, stderr.decode()
    assert "differs from what rti-rig wrote" in " ".join((stdout + stderr).decode().split())
    assert [p.read_text() for p in _kept(out)] == [first]
    second = lp.read_text() + "# checked\n"
    lp.write_text(second)

    text = _resume(out)

    assert text.count("differs from what rti-rig wrote from journal.jsonl") == 1, text
    assert sorted(p.read_text() for p in _kept(out)) == sorted([first, second])
    assert lp.read_bytes() == _journal_lp(out)


@pytest.mark.slow
@pytest.mark.e2e
@pytest.mark.parametrize(
    "stage",
    [
        "before_light",  # stopped between images: lights.lp lists every image journaled
        "after_journal",  # image_004's journal line written, lights.lp not yet rewritten
        "after_record",  # image_004's record file written, neither its line nor lights.lp
    ],
)
def test_an_unedited_lights_lp_is_neither_copied_nor_said(tmp_path: Path, stage: str) -> None:
    out = _killed(tmp_path, stage)
    listed = [e.name for e in read_lp(out / "lights.lp")]
    assert listed == ["image_001.jpg", "image_002.jpg", "image_003.jpg"], listed

    text = _resume(out)

    assert not _kept(out), _kept(out)
    assert "differs from what rti-rig wrote" not in text and "edited by hand" not in text, text
    assert (out / "lights.lp").read_bytes() == _journal_lp(out)


@pytest.mark.slow
@pytest.mark.e2e
def test_the_rebuild_of_a_completed_session_keeps_an_edited_lights_lp(tmp_path: Path) -> None:
    """``--rebuild-journal`` of a completed session writes lights.lp again too: an edited one
    is kept and said, an unedited one is not."""
    out = tmp_path / "s"
    config = str(CONFIGS / "simulated_dome.toml")
    r = runner.invoke(app, ["run", config, "--out", str(out), "--lights", "6", "--no-verdict"])
    assert r.exit_code == 0, r.output
    own = (out / "lights.lp").read_bytes()
    (out / "journal.jsonl").unlink()
    r = runner.invoke(app, ["run", "--resume", str(out), "--rebuild-journal"])
    assert r.exit_code == 0, r.output
    assert not _kept(out) and "edited by hand" not in said(r), r.output
    assert (out / "lights.lp").read_bytes() == own

    (out / "journal.jsonl").unlink()
    edited = own.decode().replace("image_001.jpg", "image_001.jpg ", 1)
    (out / "lights.lp").write_text(edited)
    r = runner.invoke(app, ["run", "--resume", str(out), "--rebuild-journal"])
    assert r.exit_code == 0, r.output
    (kept,) = _kept(out)
    assert kept.read_text() == edited
    assert (
        f"{out / 'lights.lp'} differs from what rti-rig wrote from journal.jsonl (edited by "
        f"hand?): kept as {kept}; lights.lp is written again from the journal, which is the "
        f"record of the lights that fired; to keep your edit, make it again in "
        f"{out / 'lights.lp'}"
    ) in said(r), r.output
    assert "once this run has ended" not in said(r)
    assert (out / "lights.lp").read_bytes() == own
