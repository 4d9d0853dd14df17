"""A config table named in a command's help (``[camera]``, ``[dome.serial]``) reaches
``--help``.

Why: typer renders help as rich markup, which read ``[camera]`` as a tag and dropped it:
``plan --help`` said "Default: the rig config's  signal_noise" and ``calibrate-lights --help``
"for  intensity_correction_file in the rig config", losing the table the key goes in.
"""

from __future__ import annotations

import re

import typer
from typer.testing import CliRunner

from rti_rig.cli import app

runner = CliRunner()

#: A bracketed config table or key in a help text, escaped (``\\[camera]``) or not.
TABLE = re.compile(r"\\?\[([a-z][\w.]*)\]")


def _commands(command, path):  # type: ignore[no-untyped-def]
    yield path, command
    for name, sub in getattr(command, "commands", {}).items():
        yield from _commands(sub, [*path, name])


def test_every_table_named_in_a_help_text_is_shown_by_help() -> None:
    root = typer.main.get_command(app)
    checked = []
    for path, command in _commands(root, []):
        texts = [command.help or ""] + [getattr(p, "help", None) or "" for p in command.params]
        tables = {m for text in texts for m in TABLE.findall(text)}
        if not tables:
            continue
        r = runner.invoke(app, [*path, "--help"], terminal_width=200)
        assert r.exit_code == 0, r.output
        shown = " ".join(r.output.replace("│", " ").split())
        for table in tables:
            assert f"[{table}]" in shown, f"'{' '.join(path)} --help' dropped [{table}]"
            checked.append((" ".join(path), table))
    assert ("plan", "camera") in checked and ("calibrate-lights", "dome.serial") in checked
