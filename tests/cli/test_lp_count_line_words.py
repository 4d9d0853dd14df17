"""A count line with a word after its number (``2 lights``, ``48 LEDs``, as a hand-written or
a spreadsheet's list says it): read as the count, and noted (relight reads a number alone
there); other words after the number are refused saying what the first line must be. Both
had been read as a light line and refused as "found 2 field(s)", with nothing to do."""

from __future__ import annotations

from pathlib import Path

import pytest
from conftest import said
from typer.testing import CliRunner

from rti_rig.cli import app

runner = CliRunner()
LIGHTS = ["led01 0 0 1", "led02 0 0.6 0.8", "led03 0.6 0 0.8", "led04 -0.6 0 0.8"]


def _plan(lp: Path, out: Path) -> tuple[int, str]:
    r = runner.invoke(app, ["plan", "--rig", str(lp), "--lights", "4", "--out", str(out)])
    assert "Traceback" not in r.output
    return r.exit_code, said(r)


@pytest.mark.parametrize("count", ["4 lights", "4 LEDs", "4 Lights:"])
def test_a_count_word_after_the_number_reads_as_the_count(tmp_path: Path, count: str) -> None:
    lp = tmp_path / "dome.lp"
    lp.write_text("\n".join([count, *LIGHTS]) + "\n")
    out = tmp_path / "plan.lp"
    code, text = _plan(lp, out)
    assert code == 0, text
    assert out.exists()
    assert f"count line {count!r} read as the count 4" in text, text


@pytest.mark.parametrize("count", ["4 lights in dome A", "4 of 5 lights"])
def test_other_words_after_the_number_are_refused_saying_what_the_line_must_be(
    tmp_path: Path, count: str
) -> None:
    """``4 of 5 lights`` (a number among the words) had been read as the light ``4`` and
    refused as "x component 'of' is not a number"."""
    lp = tmp_path / "dome.lp"
    lp.write_text("\n".join([count, *LIGHTS]) + "\n")
    out = tmp_path / "plan.lp"
    code, text = _plan(lp, out)
    assert code == 2, text
    assert f"{lp}, line 1: count line {count!r} holds words" in text, text
    assert "the number of lights alone (e.g. '4')" in text, text
    assert not out.exists()
