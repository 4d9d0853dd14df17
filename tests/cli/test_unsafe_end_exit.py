"""A complete session whose lights were not brought to a known safe state exits 1.

It had exited 0 while saying "all-off could NOT be sent … switch the dome off at its power
supply": a script chaining ``run && fit``, or a lab's batch, took it for a clean end with the
dome possibly lit (the nab-rti-v1 board boots with every LED on when its power comes back).
"""

from __future__ import annotations

import sys
from pathlib import Path

import pytest
from conftest import CONFIGS
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.core.lp_format import read_lp

pytestmark = [
    pytest.mark.skipif(sys.platform != "linux", reason="pty semantics tested on Linux"),
    pytest.mark.pty,
]


@pytest.mark.slow  # real firmware timing over a pty, and two failed reconnections
@pytest.mark.parametrize(
    ("command", "what"),
    # commands 1–3 are the opening all-offs, then light/all-off per image: with 2 lights, 8 is
    # the teardown's all-off (a teardown failure) and 9 the close's (the last word on the lights)
    [(8, "teardown problem: all LEDs off"), (9, "All-off could NOT be sent")],
)
def test_a_dome_gone_at_the_final_all_off_fails_the_run(
    tmp_path: Path, command: int, what: str
) -> None:
    cfg = tmp_path / "rig.toml"
    cfg.write_text(
        (CONFIGS / "emulated_nab_rti_v1.toml").read_text()
        + f'\n[emulator]\nfaults = [{{at_command = {command}, kind = "disconnect", '
        "delay_s = 60.0}]\n"
    )
    # one short reconnection attempt, the config's keys (the shipped 7.5 s of attempts, for a
    # real replug, had made each gone port cost the test 7.5 s, twice)
    cfg.write_text(
        cfg.read_text()
        .replace("reconnect_attempts = 4", "reconnect_attempts = 1")
        .replace("reconnect_backoff_s = 0.5", "reconnect_backoff_s = 0.05")
    )
    out = tmp_path / "s"
    args = ["run", str(cfg), "--out", str(out), "--lights", "2", "--no-verdict"]
    r = CliRunner().invoke(app, args, terminal_width=400)
    said = " ".join(r.output.split())
    assert r.exit_code == 1, r.output
    assert len(read_lp(out / "lights.lp")) == 2  # the images are kept all the same
    assert what in said
    assert "session is complete, but the rig was not brought to a known safe state" in said
    assert "make it safe by hand (switch the dome off)" in said
