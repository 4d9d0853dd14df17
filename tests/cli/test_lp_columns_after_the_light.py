"""A light list whose names are no image file names (a dome's ``led01``) with a column after
each light (an intensity, a colour): refused naming the line and the extra column, where the
line had been read the way relight reads it, the last three fields the vector, so ``led01 0 0
1 0.8`` became the light ``led01 0`` from (0, 1, 0.8): every light from a wrong direction,
with only a note of the vectors' length."""

from __future__ import annotations

from pathlib import Path

import pytest
from conftest import said
from typer.testing import CliRunner

from rti_rig.cli import app

runner = CliRunner()
LIGHTS = ["led01 0 0 1", "led02 0 0.6 0.8", "led03 0.6 0 0.8", "led04 -0.6 0 0.8"]


@pytest.mark.parametrize(
    ("extra", "said_extra"),
    [(" 0.85", "after it 0.85 is an extra column"), (" 255 240 230", "are extra columns")],
    ids=["intensity", "colour"],
)
def test_a_column_after_the_light_is_refused_naming_it(
    tmp_path: Path, extra: str, said_extra: str
) -> None:
    lp = tmp_path / "dome.lp"
    lp.write_text("\n".join(["4", *(f"{line}{extra}" for line in LIGHTS)]) + "\n")
    out = tmp_path / "plan.lp"
    r = runner.invoke(app, ["plan", "--rig", str(lp), "--lights", "4", "--out", str(out)])
    text = said(r)
    assert r.exit_code == 2, text
    assert f"{lp}, line 2: expected 'name x y z'" in text and said_extra in text, text
    assert "Traceback" not in r.output and not out.exists()

    # without the column the same lights plan
    lp.write_text("\n".join(["4", *LIGHTS]) + "\n")
    r = runner.invoke(app, ["plan", "--rig", str(lp), "--lights", "4", "--out", str(out)])
    assert r.exit_code == 0, said(r)


def test_a_name_ending_in_a_number_before_its_light_still_reads(tmp_path: Path) -> None:
    lp = tmp_path / "dome.lp"
    lp.write_text("\n".join(["4", *(f"led {line[3:]}" for line in LIGHTS)]) + "\n")
    out = tmp_path / "plan.lp"
    r = runner.invoke(app, ["plan", "--rig", str(lp), "--lights", "4", "--out", str(out)])
    assert r.exit_code == 0, said(r)


@pytest.mark.parametrize(
    ("line", "as_name", "as_column"),
    [
        ("led01 0 0 1 0", "'led01 0' from (0, 1, 0)", "'led01' from (0, 0, 1)"),
        ("my scan 2 0 0 1 0", "'my scan 2 0' from (0, 1, 0)", "'my scan 2' from (0, 0, 1)"),
    ],
    ids=["name", "name-with-spaces"],
)
def test_a_line_that_reads_as_a_name_or_as_a_column_is_refused_saying_both(
    tmp_path: Path, line: str, as_name: str, as_column: str
) -> None:
    """``led01 0 0 1 0`` (an LED at intensity 0): its last three fields and the three before
    the last are both unit vectors, so it is the light ``led01 0`` from (0, 1, 0) or ``led01``
    from (0, 0, 1) with a column after it; it had been read the first way, unsaid. So had a
    name with spaces before the numbers (``my scan 2 0 0 1 0``, read as ``my scan 2 0``)."""
    lp = tmp_path / "dome.lp"
    lines = [f"{line} 0.85" for line in LIGHTS]
    lines[0] = line
    lp.write_text("\n".join(["4", *lines]) + "\n")
    out = tmp_path / "plan.lp"
    r = runner.invoke(app, ["plan", "--rig", str(lp), "--lights", "4", "--out", str(out)])
    text = said(r)
    assert r.exit_code == 2, text
    assert f"{lp}, line 2: '{line}' reads two ways" in text, text
    assert as_name in text and as_column in text, text
    assert "delete the column after the light" in text, text
    assert "Traceback" not in r.output and not out.exists()
