"""``--help`` says what the command does with these options.

``run --help`` said nothing of a camera-triggered dome refusing ``--lights N`` (its firmware
lights every LED in its own order), which the run then refuses; ``export-lp`` and ``plan``
described ``--out`` as "another name is written too, with a note", which reads as a second
file being written. What happens: a name not ending in .lp is written as given, with a note
to rename it.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from conftest import CONFIGS, said
from typer.testing import CliRunner

from rti_rig.cli import app

runner = CliRunner()


def _help(*command: str) -> str:
    """A command's --help as words, rich's box and line wrapping undone."""
    r = runner.invoke(app, [*command, "--help"])
    assert r.exit_code == 0, r.output
    return " ".join(r.output.replace("│", " ").split())


def test_run_help_says_a_camera_triggered_dome_refuses_lights(tmp_path: Path) -> None:
    words = _help("run")
    assert (
        "A camera-triggered dome ([dome.flash_sync]) refuses any number but all of its LEDs"
        in words
    ), words
    out = tmp_path / "s"
    # as the run does on the shipped camera-triggered dome, before anything opens
    r = runner.invoke(
        app, ["run", str(CONFIGS / "emulated_cceh_rti.toml"), "--lights", "6", "--out", str(out)]
    )
    assert r.exit_code == 2 and "--lights 6: this camera-triggered dome" in said(r), said(r)
    assert not out.exists()  # refused before the session folder was made


@pytest.mark.parametrize("command", ["export-lp", "plan"])
def test_lp_out_help_says_a_misnamed_file_is_written_with_a_note(command: str) -> None:
    words = _help(command)
    assert "another name is written too" not in words, words
    assert (
        "A name that does not end in .lp is still written, with a note to rename it: relight, "
        "RTIBuilder and rti-rig fit only read files ending in .lp" in words
    ), words
