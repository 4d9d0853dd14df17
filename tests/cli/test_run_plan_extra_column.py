"""`rti-rig run RIG --plan X.lp` whose line has a fourth number says where the extra number is.

Found by an audit: a line with an extra number at its end (``a_1.jpg 0.6 0 0.8 1.0``, an
intensity after the vector) was asked "an extra column after the name?", which sent the user
to the wrong column. The refusal now names what the line has: four numbers where an .lp line
has three, and, where one run of three is the light's unit vector, which number is extra.
Nothing is shot either way.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from conftest import CONFIGS
from typer.testing import CliRunner

from rti_rig.cli import app

runner = CliRunner()


@pytest.mark.parametrize(
    ("line", "said"),
    [
        ("a_2.jpg 0.6 0 0.8 1.0", "0.6 0 0.8 is a unit vector, and after it 1.0 is an extra"),
        ("a_2.jpg 1.0 0.6 0 0.8", "0.6 0 0.8 is a unit vector, and before it 1.0 is an extra"),
    ],
)
def test_a_plan_line_with_an_extra_number_says_which_number_is_extra(
    tmp_path: Path, line: str, said: str
) -> None:
    plan = tmp_path / "plan.lp"
    plan.write_text(f"2\na_1.jpg 0 0 1\n{line}\n", encoding="utf-8")
    out = tmp_path / "session"
    r = runner.invoke(
        app,
        ["run", str(CONFIGS / "simulated_dome.toml"), "--out", str(out), "--plan", str(plan)],
        terminal_width=400,
    )
    text = " ".join(r.output.split())
    assert r.exit_code == 2, r.output
    assert "Traceback" not in r.output
    assert f"{plan}, line 3: expected 'name x y z', found 5 fields" in text, text
    assert "4 numbers after the name where an .lp line has 3" in text, text
    assert said in text, text
    assert "after the name?" not in text, text
    assert not out.exists()
