"""An `.lp` with a title or a row of column headings above its lights (``LP file``,
``image x y z``, as a script's table writer or a spreadsheet puts there): refused naming the
file, the line, what it seems to be and the one edit that makes it read, where it had been
told "x component 'x' is not a number" or "found 2 field(s)" and nothing to do."""

from __future__ import annotations

from pathlib import Path

import pytest
from conftest import said
from typer.testing import CliRunner

from rti_rig.cli import app

runner = CliRunner()
LIGHTS = ["a_1.jpg 0 0 1", "a_2.jpg 0 0.6 0.8", "a_3.jpg 0.6 0 0.8"]
HINT = "a title or a row of column headings? an .lp has none: delete the line, or start it with '#'"


@pytest.mark.parametrize(
    ("above", "line"),
    [(["LP file", "3"], 1), (["3", "image\tx\ty\tz"], 2), (["filename lx ly lz"], 1)],
    ids=["title", "headings-under-count", "headings-no-count"],
)
def test_a_heading_line_is_refused_with_the_edit_that_reads_the_file(
    tmp_path: Path, above: list[str], line: int
) -> None:
    lp = tmp_path / "dirs.lp"
    lp.write_text("\r\n".join([*above, *LIGHTS]) + "\r\n")
    out = tmp_path / "plan.lp"
    r = runner.invoke(app, ["plan", "--rig", str(lp), "--lights", "3", "--out", str(out)])
    text = said(r)
    assert r.exit_code == 2, text
    assert f"{lp}, line {line}: " in text and HINT in text, text
    assert "Traceback" not in r.output and not out.exists()

    # the edit it offers is all it takes: the line kept as a comment
    marked = [f"# {a}" if not a.isdigit() else a for a in above]
    lp.write_text("\r\n".join([*marked, *LIGHTS]) + "\r\n")
    r = runner.invoke(app, ["plan", "--rig", str(lp), "--lights", "3", "--out", str(out)])
    assert r.exit_code == 0, said(r)
    assert "comment line(s) starting with '#' skipped" in said(r)


def test_a_light_line_that_lost_its_numbers_is_not_called_a_heading(tmp_path: Path) -> None:
    lp = tmp_path / "dirs.lp"
    lp.write_text("\n".join(["3", *LIGHTS[:2], "my photo 3.jpg"]) + "\n")
    r = runner.invoke(app, ["check", str(lp)])
    text = said(r)
    assert r.exit_code == 2 and f"{lp}, line 4: expected 'name x y z'" in text, text
    assert "headings" not in text
