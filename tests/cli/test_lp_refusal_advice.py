"""A refused acquisition `.lp` says what to do: a line repeated, two lights under one image's
name, a last line cut short. Each had been told what was wrong alone ("image name
'image03.jpg' already used on line 4"; "expected 'name x y z', found 3 field(s)")."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest
from typer.testing import CliRunner

from rti_rig.cli import app

REPO = Path(__file__).resolve().parents[2]
SOURCE = REPO / "tests" / "data" / "neuralrti_replay"


def _lines(acq: Path) -> list[str]:
    return (acq / "dirs.lp").read_text().splitlines()


@pytest.mark.parametrize(
    ("edit", "said"),
    [
        (
            lambda ls: [*ls[:3], ls[2], *ls[3:]],
            "already used on line 3, with the same light: the line repeated? delete line 4",
        ),
        (
            lambda ls: [*ls[:3], ls[2].rsplit(" ", 3)[0] + " 0 0 1", *ls[3:]],
            "already used on line 3, with another light: each image has one light; give this "
            "line the name of the image it lit, or delete the line that is wrong",
        ),
        (
            lambda ls: [*ls[:-1], ls[-1].rsplit(" ", 1)[0]],
            "(the last line: the file cut short? copy it again from where it came from, or "
            "remove the line and leave its image out)",
        ),
    ],
    ids=["repeated", "two lights", "cut short"],
)
def test_a_refused_lp_line_says_what_to_do(tmp_path: Path, edit, said: str) -> None:  # type: ignore[no-untyped-def]
    acq = tmp_path / "acq"
    shutil.copytree(SOURCE, acq)
    (acq / "dirs.lp").write_text("\n".join(edit(_lines(acq))) + "\n")
    r = CliRunner().invoke(app, ["check", str(acq / "dirs.lp")], terminal_width=400)
    text = " ".join(r.output.split())
    assert r.exit_code != 0 and "Traceback" not in text, r.output
    assert said in text, text
