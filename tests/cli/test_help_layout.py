"""``--help`` prints each command's description as paragraphs, not as the docstring's source lines.

typer's rich help kept a docstring's line breaks: ``rti-rig run --help`` broke "stops at once
(lights" from "off, arm stopped ..." in mid-sentence, and the command list cut summaries at their
first source line. A description wrapped by the terminal fills each line greedily: no line is
broken where the next word would still have fitted on it.
"""

from __future__ import annotations

import itertools

import pytest
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.cli.bench import bench_app

runner = CliRunner()
#: A user's terminal, 80 columns: where a description wraps (the tests' own consoles are wider,
#: tests/conftest.py's ``_wide_console``, where a description would fit on one line).
at_80 = CliRunner(env={"COLUMNS": "80"})

#: Every command's help, as a user asks for it.
COMMANDS = [
    [c.name or c.callback.__name__] for c in app.registered_commands if c.callback is not None
] + [["bench", c.name or c.callback.__name__] for c in bench_app.registered_commands]


def description_lines(output: str) -> list[str]:
    """The lines between the usage line and the first boxed panel (arguments or options)."""
    lines = output.splitlines()
    start = next(i for i, ln in enumerate(lines) if "Usage:" in ln) + 1
    end = next(i for i, ln in enumerate(lines) if ln.lstrip().startswith("╭"))
    return [ln.rstrip() for ln in lines[start:end]]


def test_every_command_is_listed() -> None:
    assert ["run"] in COMMANDS and ["fit"] in COMMANDS and ["bench", "tradeoff"] in COMMANDS


@pytest.mark.parametrize("command", COMMANDS, ids=" ".join)
def test_a_description_is_wrapped_by_the_terminal_not_by_its_source(command: list[str]) -> None:
    r = at_80.invoke(app, [*command, "--help"])
    assert r.exit_code == 0, r.output
    width = max(len(ln) for ln in r.output.splitlines())  # the console's width
    described = description_lines(r.output)
    assert any(described), r.output
    for line, after in itertools.pairwise(described):
        if not line.strip() or not after.strip():
            continue  # a paragraph's end
        next_word = after.split()[0]
        assert len(line) + 1 + len(next_word) > width - 1, (
            f"'{' '.join(command)} --help' broke a line early:\n{line}\n{after}"
        )


def test_the_command_list_gives_whole_summaries() -> None:
    r = runner.invoke(app, ["--help"])
    text = " ".join(r.output.replace("│", " ").split())
    assert "the lights that actually fired, for every image on disk as captured" in text, text


def test_paragraphs_stay_apart() -> None:
    from rti_rig.cli.app import reflowed

    assert reflowed("One line\n    and its end.\n\nA second\nparagraph.") == (
        "One line and its end.\n\nA second paragraph."
    )


@pytest.mark.parametrize("command", ["run", "check", "preview"])
def test_commands_taking_a_rig_say_a_recorded_acquisitions_lp_is_one(command: str) -> None:
    """`run`, `check` and `preview` take an acquisition's .lp as a rig (the replay rig), but
    their help had said only "Rig config TOML" (and `check`'s that a dome lights its LEDs)."""
    r = runner.invoke(app, [command, "--help"], terminal_width=200)
    assert r.exit_code == 0, r.output
    text = " ".join(r.output.replace("│", " ").split())
    assert "or a recorded acquisition's .lp" in text, text
