"""`run --resume S --reshoot IMAGE`: the images the QA verdict names misfired (their files
intact) reshot in place, the verdict giving the command.

The verdict said "reshoot: image_004 (misfired, no light …)" and no command did it:
`--reshoot-lost` takes only images lost or changed since capture ("nothing to reshoot"), so a
dead LED mended on the spot left a choice of the whole session again or a hole in the lights.
"""

from __future__ import annotations

import hashlib
import json
import shlex
import shutil
from pathlib import Path

import pytest
from conftest import CONFIGS, interrupted, said
from typer.testing import CliRunner

from rti_rig.cli import app

pytestmark = [pytest.mark.pty, pytest.mark.slow]
runner = CliRunner()


def _tree(folder: Path) -> dict[str, str]:
    return {
        p.relative_to(folder).as_posix(): hashlib.sha256(p.read_bytes()).hexdigest()
        for p in sorted(folder.rglob("*"))
        if p.is_file()
    }


def test_a_misfired_image_is_reshot_in_place_with_the_command_its_verdict_gives(
    tmp_path: Path,
) -> None:
    # the shipped Nab dome with LED 3 dead: image_004 is shot dark, and named so
    rig = tmp_path / "nab.toml"
    mended = (CONFIGS / "emulated_nab_rti_v1.toml").read_text()
    rig.write_text(mended + "\n[emulator]\ndead_leds = [3]\n")
    out = tmp_path / "s"
    r = runner.invoke(app, ["run", str(rig), "--out", str(out)], terminal_width=400)
    assert r.exit_code == 0, r.output
    text = said(r)
    assert "QA verdict: reshoot: image_004 (misfired, no light" in text, text
    lead = (
        "; to reshoot image_004 in place, once what made the light wrong is mended (an LED "
        "that did not fire, a loose connector, a swapped LED): "
    )
    assert lead in text, text
    command = text.split(lead, 1)[1].split(" Next:", 1)[0]
    assert command == f"rti-rig run --resume {out} --reshoot image_004", text
    kept = {k: v for k, v in _tree(out).items() if k.startswith(("image_", "linear/"))}
    journal_lines = (out / "journal.jsonl").read_text().count("\n")
    # the LED mended (its connector pushed home): the config without the fault, the command
    rig.write_text(mended)
    r = runner.invoke(app, shlex.split(command)[1:], terminal_width=400)
    assert r.exit_code == 0, r.output
    text = said(r)
    assert "11 of 12 images verified on disk" in text and "1 of 12 lights left" in text, text
    assert "QA verdict: good" in text, text
    assert "file(s) of the images to reshoot set aside in recovered/" in text, text
    # the dark image set aside, never deleted; every other image as it was
    (aside,) = (out / "recovered").iterdir()
    assert (aside / "image_004.jpg").read_bytes() and hashlib.sha256(
        (aside / "image_004.jpg").read_bytes()
    ).hexdigest() == kept["image_004.jpg"]
    now = _tree(out)
    for name, digest in kept.items():
        if "image_004" not in name:
            assert now[name] == digest, name
    assert now["image_004.jpg"] != kept["image_004.jpg"]
    assert (out / "journal.jsonl").read_text().count("\n") > journal_lines
    assert len((out / "lights.lp").read_text().splitlines()) == 13  # count + 12 lights


@pytest.fixture(scope="module")
def finished(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("done") / "s"
    r = runner.invoke(
        app,
        ["run", str(CONFIGS / "simulated_dome.toml"), "--out", str(out), "--lights", "8",
         "--no-verdict"],
    )  # fmt: skip
    assert r.exit_code == 0, r.output
    return out


@pytest.mark.parametrize(
    ("names", "refusal"),
    [
        (["image_009"], "--reshoot image_009: {s} has no image of that name; give its images "
         "as the verdict names them, image_001 to image_008"),
        (["image_002,photo.jpg"], "--reshoot photo.jpg: {s} has no image of that name"),
        # a script's variable unset: it had resumed as if --reshoot were not given
        ([""], "--reshoot '': name the images to reshoot, as the QA verdict names them"),
        ([" , "], "--reshoot ' , ': name the images to reshoot"),
    ],
)  # fmt: skip
def test_a_name_the_session_has_no_image_of_is_refused_before_anything_moves(
    finished: Path, tmp_path: Path, names: list[str], refusal: str
) -> None:
    out = tmp_path / "s"
    shutil.copytree(finished, out)
    before = _tree(out)
    args = [w for n in names for w in ("--reshoot", n)]
    r = runner.invoke(app, ["run", "--resume", str(out), *args], terminal_width=400)
    assert r.exit_code == 2, r.output
    assert refusal.format(s=out) in said(r), said(r)
    assert _tree(out) == before


def test_names_as_files_and_repeated_take_each_image_once(finished: Path, tmp_path: Path) -> None:
    from rti_rig.app.usecases.session import reshoot_steps
    from rti_rig.runtime.session import read_manifest

    manifest = read_manifest(finished)
    steps = reshoot_steps(manifest, ("image_005.jpg,image_002", "image_002"), finished)
    assert steps == (1, 4)


def test_an_unfinished_or_adaptive_session_is_refused(tmp_path: Path) -> None:
    from rti_rig.app.usecases.session import reshoot_steps
    from rti_rig.runtime.session import read_manifest

    out = tmp_path / "a"
    interrupted(CONFIGS / "simulated_dome.toml", out, after_step=4, lights=7)
    manifest = read_manifest(out)
    with pytest.raises(Exception, match="--reshoot is for a session that completed"):
        reshoot_steps(manifest, ("image_002",), out)
    manifest["runner"]["finish_reason"] = "completed"
    with pytest.raises(Exception, match="cannot reshoot an image of an adaptive session"):
        reshoot_steps(manifest, ("image_002",), out)
    json.dumps(manifest)  # still the manifest as read: nothing written


def test_reshoot_without_resume_is_refused(tmp_path: Path) -> None:
    r = runner.invoke(
        app,
        ["run", str(CONFIGS / "simulated_dome.toml"), "--out", str(tmp_path / "n"), "--reshoot",
         "image_001"],
    )  # fmt: skip
    assert r.exit_code == 2 and "--reshoot goes with --resume SESSION_DIR only" in said(r)
    assert not (tmp_path / "n").exists()


def test_reshoot_with_rebuild_journal_names_the_option_given(
    finished: Path, tmp_path: Path
) -> None:
    out = tmp_path / "s"
    shutil.copytree(finished, out)
    before = _tree(out)
    r = runner.invoke(
        app,
        ["run", "--resume", str(out), "--reshoot", "image_002", "--rebuild-journal"],
        terminal_width=400,
    )
    assert r.exit_code == 2, r.output
    assert "--rebuild-journal and --reshoot go one at a time" in said(r), said(r)
    assert "--reshoot-lost" not in said(r) and _tree(out) == before


def test_a_reshoot_cut_short_is_said_set_aside_not_lost_by_the_resume_after(
    finished: Path, tmp_path: Path
) -> None:
    """The plain resume a --reshoot stopped part-way advises had said of the images it had
    set aside "lost since capture: what was captured is no longer there"."""
    from rti_rig.app.usecases.session import (
        ResumeRequest,
        open_resumed_session,
        run_opened_session,
    )
    from rti_rig.runtime.controller import CancelToken, StepCompleted

    out = tmp_path / "s"
    shutil.copytree(finished, out)
    opened = open_resumed_session(ResumeRequest(out, reshoot=("image_003,image_006",)))
    cancel = CancelToken()

    def on_event(event: object) -> None:
        if isinstance(event, StepCompleted):
            cancel.cancel()

    run_opened_session(opened, cancel=cancel, on_event=on_event)
    r = runner.invoke(app, ["run", "--resume", str(out), "--no-verdict"], terminal_width=400)
    assert r.exit_code == 0, r.output
    text = said(r)
    assert "lost since capture" not in text and "no longer there" not in text, text
    assert "1 image(s) an earlier resume set aside to reshoot (image_006 (in recovered/" in text
    assert "8 image(s) in the session" in text, text


def test_a_replayed_acquisition_is_refused_a_reshoot(finished: Path) -> None:
    """A replay gives the recording's image again: its reshoot could not help."""
    from rti_rig.app.usecases.session import reshoot_steps
    from rti_rig.runtime.session import read_manifest

    manifest = read_manifest(finished)
    manifest["rig"]["backend"] = "replay"
    with pytest.raises(Exception, match="cannot help a replayed acquisition"):
        reshoot_steps(manifest, ("image_002",), finished)
