"""The lights line of a timed firmware (RTIPy: no all-off, each LED dark by itself after its
``light_on_s``) says how long the last LED lit may stay lit, from the rig config's value.

It said only "it switches each LED off by itself at the end of its on-time": after a stop, a
user reaching for the object did not learn that an LED may stay lit for up to that long.
"""

from __future__ import annotations

import sys
from pathlib import Path

import pytest
from conftest import CONFIGS
from typer.testing import CliRunner

from rti_rig.cli import app


@pytest.mark.slow  # real firmware timing over a pty
@pytest.mark.pty
@pytest.mark.skipif(sys.platform != "linux", reason="pty semantics tested on Linux")
def test_the_rtipy_lights_line_bounds_the_last_leds_on_time(tmp_path: Path) -> None:
    text = (CONFIGS / "emulated_rtipy.toml").read_text()
    assert "light_on_s = 2.0" in text
    cfg = tmp_path / "rig.toml"
    cfg.write_text(text.replace("light_on_s = 2.0", "light_on_s = 3.0"))  # from the config
    out = tmp_path / "S"
    r = CliRunner().invoke(
        app, ["run", str(cfg), "--lights", "3", "--out", str(out), "--no-verdict"]
    )
    said = " ".join(r.output.split())
    assert r.exit_code == 0, said
    assert "switches each LED off by itself" in said, said
    assert "may stay lit for up to 3 s (its light_on_s)" in said, said
