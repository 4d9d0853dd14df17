"""`rti-rig check --help` does not promise a lamp flash the check cannot give.

It said an arm "flashes the lamp at each" pose; on the shipped arm (``lamp = "software"``, the
default) rti-rig does not switch the lamp at all, and the check itself then says "no flash
reached it at any pose".
"""

from __future__ import annotations

from typer.testing import CliRunner

from rti_rig.cli import app


def test_check_help_says_which_lamp_is_flashed() -> None:
    r = CliRunner().invoke(app, ["check", "--help"], terminal_width=200)
    said = " ".join(r.output.split())
    assert r.exit_code == 0, said
    assert "flashes the lamp at each if it hangs on a servo's LED output" in said, said
    assert 'a "software" lamp is not switched' in said
