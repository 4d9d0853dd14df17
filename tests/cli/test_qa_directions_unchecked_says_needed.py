"""A verdict that leaves the lights unchecked because too few images fit a Lambertian
rendering says how many it needed: "only 3 of 6 images are close … (median misfit 9%, limit
10%)" had read as a check passed, a median under its limit, with no word of the 5 needed."""

from __future__ import annotations

import re
from pathlib import Path

from conftest import REPO, said
from typer.testing import CliRunner

from rti_rig.cli import app

runner = CliRunner()
ACQ = REPO / "tests" / "data" / "neuralrti_replay" / "dirs.lp"


def test_too_few_close_images_are_said_against_the_number_needed(tmp_path: Path) -> None:
    r = runner.invoke(app, ["run", str(ACQ), "--out", str(tmp_path / "s"), "--lights", "6"])
    text = said(r)
    assert r.exit_code == 0, text
    found = re.search(
        r"only (\d+) of (\d+) images are close to any Lambertian rendering of the fit "
        r"\(misfit within 10%; (\d+) are needed to judge the lights; median misfit \d+%\)",
        text,
    )
    assert found is not None, text
    close, judged, needed = (int(g) for g in found.groups())
    assert judged == 6 and close < needed <= judged
