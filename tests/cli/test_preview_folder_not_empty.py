"""A preview folder given again to ``preview --out`` (or ``run --out``) is refused with the
command that uses a preview: ``rti-rig plan`` with it, which works as said. It had been told
"it holds a finished session: fit it with rti-rig fit pv --out DIR", which cannot fit one image.
"""

from __future__ import annotations

import re
import shlex
from pathlib import Path

import pytest
from conftest import SMALL_DOME, said, write_config
from typer.testing import CliRunner

from rti_rig.cli import app

runner = CliRunner()


@pytest.mark.e2e
def test_a_preview_folder_not_empty_points_to_plan(tmp_path: Path) -> None:
    cfg = write_config(tmp_path, SMALL_DOME)
    pv = tmp_path / "pv"
    r = runner.invoke(app, ["preview", str(cfg), "--out", str(pv)])
    assert r.exit_code == 0, r.output
    before = sorted(p.name for p in pv.rglob("*"))
    for again in (["preview", str(cfg), "--out", str(pv)], ["run", str(cfg), "--out", str(pv)]):
        r = runner.invoke(app, again)
        text = said(r)
        assert r.exit_code == 2 and "Traceback" not in text, r.output
        assert "rti-rig fit" not in text, text
        hint = re.search(r"a finished preview: plan from it with (rti-rig plan .*?)\)", text)
        assert hint is not None, text
    assert sorted(p.name for p in pv.rglob("*")) == before  # nothing overwritten
    # the command offered works as given (its --lights a count: "N" was refused when pasted)
    args = shlex.split(hint.group(1))[1:]
    args = [str(tmp_path / a) if a == "plan.lp" else a for a in args]
    r = runner.invoke(app, args)
    assert r.exit_code == 0 and (tmp_path / "plan.lp").is_file(), r.output
