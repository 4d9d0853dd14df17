"""`rti-rig run RIG --plan X` with X not an `.lp` says what X is and what to give.

Found by a front-door audit: `--plan` an image (a JPEG of the session) was told "line 1: the
line holds NUL bytes: not plain text (UTF-16 …?) … save it again as UTF-8", `--plan` the rig
config "line 4: expected 'name x y z'", and `--plan` a session folder "cannot read: Is a
directory". Nothing was shot in any case; the messages sent the user after the wrong fault.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from conftest import CONFIGS
from typer.testing import CliRunner

from rti_rig.cli import app

REPO = Path(__file__).resolve().parents[2]
ACQ = REPO / "tests" / "data" / "neuralrti_replay"
runner = CliRunner()


@pytest.mark.parametrize(
    ("given", "said"),
    [
        (ACQ / "image01.jpg", "this is an image, not an .lp file"),
        (CONFIGS / "simulated_dome.toml", "this is a TOML file (a rig config?), not an .lp"),
        (ACQ, "is a folder, not an .lp file"),
    ],
)
def test_a_plan_that_is_not_an_lp_is_named_for_what_it_is(
    tmp_path: Path, given: Path, said: str
) -> None:
    out = tmp_path / "session"
    r = runner.invoke(
        app, ["run", str(CONFIGS / "simulated_dome.toml"), "--out", str(out), "--plan", str(given)]
    )
    text = "".join(r.output.split())
    assert r.exit_code == 2, r.output
    assert "Traceback" not in r.output
    assert "".join(f"{given}: {said}: give the .lp light list".split()) in text, r.output
    assert "NUL" not in text and "expected'namexyz'" not in text
    assert not out.exists()
