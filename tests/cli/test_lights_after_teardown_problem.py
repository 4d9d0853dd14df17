"""A teardown problem with an all-off, then the lights' state: said as the later all-off's.

Before: a red "teardown problem: all LEDs off … no reply" printed directly above "All-off
sent and acknowledged by the dome: lights are off", nothing saying that the acknowledged
all-off was a later one (the claim held; the two lines read as a contradiction)."""

from __future__ import annotations

from pathlib import Path

import pytest
from typer.testing import CliRunner

from rti_rig.cli import app

CONFIGS = Path(__file__).resolve().parents[2] / "rig_configs"


@pytest.mark.pty
def test_an_acknowledged_all_off_after_a_teardown_problem_says_it_came_after(
    tmp_path: Path,
) -> None:
    text = (CONFIGS / "emulated_dome.toml").read_text(encoding="utf-8")
    text = text.replace('lp_file = "', f'lp_file = "{CONFIGS}/')
    # a reply that is only late, on a loaded machine, must not count as one of those lost
    assert "reply_timeout_s = 0.5" in text
    text = text.replace("reply_timeout_s = 0.5", "reply_timeout_s = 1.5")
    for n in range(3, 11):  # the replies to the first all-offs lost
        text += f'\n[[emulator.faults]]\nat_command = {n}\nkind = "drop_reply"\n'
    config = tmp_path / "drops.toml"
    config.write_text(text, encoding="utf-8")
    out = tmp_path / "s"
    r = CliRunner().invoke(
        app, ["run", str(config), "--out", str(out), "--lights", "1", "--allow-no-normals"]
    )
    said = " ".join(r.output.split())
    assert r.exit_code == 2, said
    assert "teardown problem: all LEDs off" in said, said
    assert (
        "lights are off (said of the last all-off, sent after the teardown problem above)" in said
    ), said
