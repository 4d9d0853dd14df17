"""An .lp naming an image no file here can have is refused by line, in every command.

94 CJK characters are a legal NTFS file name and 274 bytes in UTF-8, over the 255 a Linux file
system holds: `check`, `fit` and `bench tradeoff --from` had shown a "File name too long"
traceback, `run` an "unexpected OSError" (QA, 2026-12-06).
"""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest
from typer.testing import CliRunner

from rti_rig.cli import app

ACQ = Path(__file__).resolve().parents[1] / "data" / "neuralrti_replay"


@pytest.mark.parametrize(
    "argv",
    [
        ["check", "{lp}"],
        ["fit", "{lp}", "--out", "{tmp}/f"],
        ["run", "{lp}", "--out", "{tmp}/r"],
        ["bench", "tradeoff", "--from", "{lp}"],
    ],
)
def test_an_image_name_too_long_here_is_refused_by_line(tmp_path: Path, argv: list[str]) -> None:
    acq = tmp_path / "acq"
    shutil.copytree(ACQ, acq)
    lines = (acq / "dirs.lp").read_text(encoding="utf-8").splitlines()
    long = "文" * 90 + ".jpg"
    name, rest = lines[3].split(" ", 1)
    lines[3] = f"{long} {rest}"
    (acq / name).unlink()
    lp = acq / "dirs.lp"
    lp.write_text("\n".join(lines) + "\n", encoding="utf-8")
    words = [w.format(lp=lp, tmp=tmp_path) for w in argv]
    r = CliRunner().invoke(app, words, terminal_width=400)
    said = " ".join(r.output.split())
    assert r.exit_code == 2, said
    assert "Traceback" not in said and "unexpected" not in said, said
    assert f"{lp}, line 4: image name part" in said and "is 274 bytes long" in said, said
    assert not (tmp_path / "f").exists() and not (tmp_path / "r").exists()


def test_a_plan_of_such_an_acquisition_needs_only_its_directions(tmp_path: Path) -> None:
    """`plan --rig ACQ/dirs.lp` reads the lights, not the images: it plans (it had been
    refused once the long name was checked where the .lp is read)."""
    acq = tmp_path / "acq"
    shutil.copytree(ACQ, acq)
    lines = (acq / "dirs.lp").read_text(encoding="utf-8").splitlines()
    name, rest = lines[3].split(" ", 1)
    lines[3] = f"{'文' * 90}.jpg {rest}"
    (acq / name).unlink()
    (acq / "dirs.lp").write_text("\n".join(lines) + "\n", encoding="utf-8")
    out = tmp_path / "p.lp"
    argv = ["plan", "--rig", str(acq / "dirs.lp"), "--lights", "6", "--out", str(out)]
    r = CliRunner().invoke(app, argv, terminal_width=400)
    assert r.exit_code == 0, r.output
    assert "Traceback" not in r.output
    assert out.is_file()
