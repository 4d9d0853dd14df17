"""An all-off that went through after others failed says so, in the lights line.

A run whose all-offs went unanswered printed "teardown problem: all LEDs off … no reply" and
then, of the closing all-off the dome acknowledged, "lights are off", with nothing saying it
was another all-off, sent after the failed ones: it read as a contradiction (QA, 2026-12-05).
The dome policy counts its own failed all-offs, so the order said is established.
"""

from __future__ import annotations

import re
import sys
from pathlib import Path

import pytest
from conftest import CONFIGS
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.core.dome_link import OffOutcome, OffReport

pytestmark = [
    pytest.mark.pty,
    pytest.mark.slow,  # reply timeouts of 4 s
    pytest.mark.skipif(sys.platform != "linux", reason="pty semantics tested on Linux"),
]


def _run_with_replies_dropped(tmp_path: Path, commands: range) -> str:
    faults = "".join(
        f'\n[[emulator.faults]]\nat_command = {k}\nkind = "drop_reply"\n' for k in commands
    )
    text = (CONFIGS / "emulated_dome.toml").read_text()
    text = text.replace('lp_file = "', f'lp_file = "{CONFIGS}/')
    # one try per command, and a reply timeout no loaded machine's late reply reaches: each
    # all-off that fails is one dropped reply, and no other reply is taken for lost
    text = text.replace("reply_timeout_s = 0.5", "reply_timeout_s = 4.0")
    text = text.replace("retries = 2", "retries = 0")
    assert "reply_timeout_s = 4.0" in text and "retries = 0" in text
    cfg = tmp_path / "rig.toml"
    cfg.write_text(text + faults)
    out = tmp_path / "S"
    r = CliRunner().invoke(
        app,
        ["run", str(cfg), "--out", str(out), "--lights", "1", "--allow-no-normals"],
        terminal_width=400,
    )
    assert r.exit_code == 2, r.output
    return " ".join(r.output.split())


def test_the_closing_all_off_acknowledged_after_failed_ones_says_it_came_after_them(
    tmp_path: Path,
) -> None:
    # commands 3 and 4 unanswered: the session's all-off and the teardown's give up; the
    # closing all-off, command 5, is acknowledged
    said = _run_with_replies_dropped(tmp_path, range(3, 5))
    assert "teardown problem: all LEDs off" in said, said
    # 2 that failed (the session's and the teardown's); a reply late beyond 4 s would add one
    # more failure, never a success: the count is a floor, the claim's order is what matters
    found = re.search(r"lights are off \(this all-off was sent after (\d+) that failed\)", said)
    assert found is not None and int(found[1]) >= 2, said


def test_an_all_off_that_failed_last_claims_nothing_after(tmp_path: Path) -> None:
    said = _run_with_replies_dropped(tmp_path, range(3, 6))
    assert "lights are off" not in said, said
    assert "not acknowledged" in said and "that failed)" not in said, said


@pytest.mark.parametrize(
    ("outcome", "after", "said"),
    [
        (
            OffOutcome.ACKNOWLEDGED,
            1,
            "lights are off (this all-off was sent after one that failed)",
        ),
        (OffOutcome.ACKNOWLEDGED, 0, "lights are off"),
        (OffOutcome.SENT_NO_ACK, 3, "(this all-off was sent after 3 that failed)"),
    ],
)
def test_the_sentence_counts_the_failed_all_offs_before_one_that_went_through(
    outcome: OffOutcome, after: int, said: str
) -> None:
    sentence = OffReport(outcome, after_failed=after).sentence()
    assert sentence.endswith(said) if after == 0 else said in sentence, sentence


def test_a_failed_all_off_does_not_say_it_came_after_others() -> None:
    sentence = OffReport(OffOutcome.SENT_UNCONFIRMED, after_failed=2).sentence()
    assert "that failed)" not in sentence and "may still be on" in sentence
