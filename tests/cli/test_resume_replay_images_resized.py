"""A replay session whose acquisition was re-exported at another size since it began: its
resume is refused, rightly (another acquisition, another size). It had been told that the .lp
"changes what this session's images are … set it back to continue (rti-rig run --resume DIR
with the session's own config)": the .lp is the session's own and untouched, and nothing can
be set back. It is told the images changed, that this session cannot be continued on them,
and the command that starts a new session; that command runs as printed."""

from __future__ import annotations

import re
import shlex
import shutil
from pathlib import Path

import cv2
from conftest import journal, said
from test_resume_replay_new_session_command import ACQ, _cut_session
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.core.image_files import read_linear_tiff
from rti_rig.core.lp_format import read_lp

runner = CliRunner()


def test_a_replay_whose_images_were_re_exported_at_another_size_is_told_to_start_a_new_session(
    tmp_path: Path,
) -> None:
    acq, out = tmp_path / "acq", tmp_path / "S"
    shutil.copytree(ACQ, acq)
    _cut_session(acq, out, lights=8)
    before = sorted(p.relative_to(out).as_posix() for p in out.rglob("*"))
    for entry in read_lp(acq / "dirs.lp"):  # re-exported at half size
        image = cv2.imread(str(acq / entry.name))
        assert cv2.imwrite(str(acq / entry.name), cv2.resize(image, (200, 196)))

    for extra in ([], ["--accept-rig-change"]):
        r = runner.invoke(app, ["run", str(acq / "dirs.lp"), "--resume", str(out), *extra])
        text = said(r)
        assert r.exit_code == 2 and "Traceback" not in text, text
        assert "camera size: 402×395 → 200×196" in text and "recorded images: changed" in text
        assert "are not the ones this session began with" in text, text
        assert "set it back" not in text and "session's own config" not in text, text
        assert "this session cannot be continued on them" in text, text
        assert sorted(p.relative_to(out).as_posix() for p in out.rglob("*")) == before

    command = re.search(
        r"Start a new session from the acquisition as it is now \(rti-rig run "
        r"([^()]+)\)$",
        text,
    )
    assert command, text
    args = shlex.split(command.group(1))
    assert args[:2] == [str(acq / "dirs.lp"), "--out"], args
    new = Path(args[2])
    assert new.parent == out.parent and not new.exists(), args
    r = runner.invoke(app, ["run", *args, "--no-verdict"])  # as printed
    assert r.exit_code == 0, r.output
    steps = journal(new)
    assert len(steps) == 8  # the session's --lights 8
    assert read_linear_tiff(new / steps[0]["linear_image"]).shape == (196, 200, 3)
    assert len(journal(out)) == 3  # the first session kept as it was


def test_an_older_replay_session_re_exported_since_is_not_told_its_images_are_the_same(
    tmp_path: Path,
) -> None:
    """A replay session begun before its acquisition's images were recorded (no
    ``recorded_images`` in its manifest's identity), whose acquisition was re-exported at
    another size since. Nothing tells those files from the same ones read otherwise, and the
    refusal had said "replays the same recorded images this session began with": a state
    nothing established. It says it cannot be told, and the command still runs as printed."""
    import json

    acq, out = tmp_path / "acq", tmp_path / "S"
    shutil.copytree(ACQ, acq)
    _cut_session(acq, out, lights=8)
    manifest = json.loads((out / "manifest.json").read_text())
    del manifest["rig"]["identity"]["recorded_images"]  # as an rti-rig before 2026-11-29 wrote
    (out / "manifest.json").write_text(json.dumps(manifest, indent=2))
    before = sorted(p.relative_to(out).as_posix() for p in out.rglob("*"))
    for entry in read_lp(acq / "dirs.lp"):  # re-exported at half size
        image = cv2.imread(str(acq / entry.name))
        assert cv2.imwrite(str(acq / entry.name), cv2.resize(image, (200, 196)))

    r = runner.invoke(app, ["run", "--resume", str(out)])
    text = said(r)
    assert r.exit_code == 2 and "Traceback" not in text, text
    assert "camera size: 402×395 → 200×196" in text, text
    assert "the same recorded images" not in text, text
    # nor that they are other images: the same files read otherwise are not
    assert "now read otherwise than this session's (camera size" in text, text
    assert "re-exported since, or the same files read otherwise" in text, text
    assert "so which cannot be told" in text, text
    assert sorted(p.relative_to(out).as_posix() for p in out.rglob("*")) == before
    command = re.search(r"\(rti-rig run ([^()]+)\)$", text)
    assert command, text
    args = shlex.split(command.group(1))
    r = runner.invoke(app, ["run", *args, "--no-verdict"])  # as printed
    assert r.exit_code == 0, r.output
    assert len(journal(Path(args[2]))) == 8
