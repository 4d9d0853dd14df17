"""A replay's verdict names each clipped image's recorded file as it is found beside the
`.lp`, not as the `.lp` writes it: a Windows tool's ``C:\\RTI\\image01.jpg`` (a path on the
machine that wrote the file; read here beside the `.lp`) and ``jpg\\image05.jpg`` (which a
shell reads as ``jpgimage05.jpg``) had been shown as written."""

from __future__ import annotations

import re
import shutil
from pathlib import Path

from conftest import REPO, said
from typer.testing import CliRunner

from rti_rig.cli import app

runner = CliRunner()
NAMED = re.compile(r"clipped in the recording, (\S+) \(a replayed acquisition")


def test_a_replay_verdict_names_windows_written_files_where_they_were_read(
    tmp_path: Path,
) -> None:
    acq = tmp_path / "acq"
    shutil.copytree(REPO / "tests" / "data" / "neuralrti_replay", acq)
    (acq / "jpg").mkdir()
    lines = (acq / "dirs.lp").read_text().splitlines()
    written = [lines[0]]
    for i, line in enumerate(lines[1:]):
        name, rest = line.split(" ", 1)
        if i % 2 or i % 8 == 6:  # the 9 lights replayed clip image09 and image25
            (acq / name).rename(acq / "jpg" / name)
            written.append(f"jpg\\{name} {rest}")
        else:
            written.append(f"C:\\RTI\\{name} {rest}")
    (acq / "dirs.lp").write_text("\r\n".join(written) + "\r\n")

    r = runner.invoke(
        app, ["run", str(acq / "dirs.lp"), "--out", str(tmp_path / "s"), "--lights", "9"]
    )
    text = said(r)
    assert r.exit_code == 0, text
    named = NAMED.findall(text)
    assert named, text
    assert all("\\" not in n for n in named), named
    assert all((acq / n).is_file() for n in named), named
    assert any(n.startswith("jpg/") for n in named), named  # read from jpg\
    assert any("/" not in n for n in named), named  # read beside the .lp for C:\RTI\
