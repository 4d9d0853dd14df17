"""A control character in a path is said as a ``$'...'`` word, never raw.

``shown_path`` and ``shell_word`` had counted every character a stream could encode as
printable, so ``--out $'we\\x01ird.lp'`` was shown as ``→ we^Aird.lp`` (which pastes back as
no such file) and an escape sequence in a file name reached the terminal raw.
"""

from __future__ import annotations

import subprocess
from pathlib import Path

import pytest
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.core.shell_words import shell_word, shown_path

_NAMES = {
    "soh": ("we\x01ird.lp", "$'we\\x01ird.lp'"),
    "del": ("we\x7fird.lp", "$'we\\x7fird.lp'"),
    "tab": ("we\tird.lp", "$'we\\x09ird.lp'"),
    "newline": ("we\nird.lp", "$'we\\x0aird.lp'"),
    "escape": ("\x1b[31mred.lp", "$'\\x1b[31mred.lp'"),
}


@pytest.mark.parametrize("key", sorted(_NAMES))
def test_a_control_character_is_said_as_its_byte(key: str) -> None:
    name, word = _NAMES[key]
    assert shown_path(name) == word
    assert shell_word(name) == word


@pytest.mark.parametrize("key", sorted(_NAMES))
def test_the_word_pastes_back_as_the_name(key: str, tmp_path: Path) -> None:
    name, _ = _NAMES[key]
    got = subprocess.run(
        ["bash", "-c", f"printf %s {shell_word(name)}"], capture_output=True, check=True
    ).stdout
    assert got == name.encode()


def test_printable_names_are_unchanged() -> None:
    assert shown_path("plain dir/é.lp") == "plain dir/é.lp"
    assert shell_word("plain dir/é.lp") == "'plain dir/é.lp'"


def test_plan_out_with_a_control_character_is_shown_as_a_bash_word(tmp_path: Path) -> None:
    out = tmp_path / "we\x01ird.lp"
    r = CliRunner().invoke(
        app,
        ["plan", "--rig", "rig_configs/simulated_dome.toml", "--lights", "12", "--out", str(out)],
        terminal_width=400,
    )
    assert r.exit_code == 0, r.output
    assert out.exists()
    assert "\x01" not in r.output
    assert "we\\x01ird.lp'" in r.output
