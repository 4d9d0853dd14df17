"""A Ctrl-C or SIGTERM while ``calibrate-lights`` starts (its use case being imported: seconds on
a loaded machine) says what is on disk, as one while measuring does.

Why: the import ran before the command's stop handling, so a Ctrl-C there said only "rti-rig:
stopped (Ctrl-C)" (not whether the --out file given with --force was kept) and a SIGTERM ended
the process without a word. The stop is raised from inside the import here (no sleeps).
"""

from __future__ import annotations

import importlib.abc
import sys
from pathlib import Path

import pytest
from conftest import said
from sigterm_support import Unhandled, sigterm_fails_the_test, terminated
from typer.testing import CliRunner

from rti_rig.cli import app

pytestmark = pytest.mark.skipif(sys.platform != "linux", reason="signals tested on Linux")

REPO = Path(__file__).resolve().parents[2]
USE_CASE = "rti_rig.app.usecases.calibrate"


class _StopsTheImport(importlib.abc.MetaPathFinder):
    """Finds nothing: a Ctrl-C (or a SIGTERM) arrives as the use case's module is looked for."""

    def __init__(self, how: str) -> None:
        self.how = how

    def find_spec(self, name, path=None, target=None):  # type: ignore[no-untyped-def]
        if name == USE_CASE:
            if self.how == "SIGTERM":
                terminated()
            raise KeyboardInterrupt
        return None


@pytest.mark.parametrize(("how", "code"), [("Ctrl-C", 130), ("SIGTERM", 143)])
def test_a_stop_while_the_command_starts_says_the_out_file_is_kept(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, how: str, code: int
) -> None:
    out = tmp_path / "my cal.toml"
    out.write_text("# the calibration of last month\n")
    monkeypatch.delitem(sys.modules, USE_CASE, raising=False)
    monkeypatch.setattr(sys, "meta_path", [_StopsTheImport(how), *sys.meta_path])
    argv = [
        "calibrate-lights",
        str(tmp_path / "card"),
        "--rig",
        str(REPO / "rig_configs" / "emulated_dome_card.toml"),
        "--out",
        str(out),
        "--force",
    ]
    with sigterm_fails_the_test("calibrate-lights"):
        r = CliRunner().invoke(app, argv)
    text = said(r)
    assert not isinstance(r.exception, Unhandled), text
    assert r.exit_code == code, (r.exception, text)
    assert (
        f"Stopped ({how}) before the calibration was written: nothing was written to {out} "
        "(the file already there is as it was)"
    ) in text, text
    assert out.read_text() == "# the calibration of last month\n"
