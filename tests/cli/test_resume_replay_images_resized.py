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
