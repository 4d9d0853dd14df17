"""A config number out of its range is refused with the whole range, and with its line.

pydantic's "Input should be greater than 0 (got 0)" named one end of the range, so a value
typed in its place could be refused again at the other end (``max_duty`` is at most 1); and a
key inside the shipped configs' rings (``rings = [`` then a table per line) was named with no
line at all. Through ``rti-rig check`` on copies of the shipped configs.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from conftest import CONFIGS
from typer.testing import CliRunner

from rti_rig.cli import app


def _check(tmp_path: Path, shipped: str, old: str, new: str, more: str = "") -> str:
    text = (CONFIGS / shipped).read_text()
    assert old in text
    cfg = tmp_path / "rig.toml"
    cfg.write_text(text.replace(old, new, 1) + more)
    r = CliRunner().invoke(app, ["check", str(cfg)], terminal_width=400)
    said = " ".join(r.output.split())
    assert r.exit_code == 2 and "Traceback" not in said, said
    assert "Input should be" not in said, said
    return said


@pytest.mark.parametrize(
    ("shipped", "old", "new", "more", "expected"),
    [
        (
            "emulated_elexol.toml",
            "",
            "",
            "\n[dome.serial.thermal]\nmax_duty = 0\n",
            "line 45: key 'dome.serial.thermal.max_duty': must be more than 0 and at most 1 "
            "(got 0)",
        ),
        (
            "emulated_elexol.toml",
            "led_count = 12 ",
            "led_count = 0 ",
            "",
            "line 26: key 'dome.serial.protocol.led_count': must be at least 1 and at most 1000 "
            "(got 0)",
        ),
        (
            "simulated_dome.toml",
            "exposure_s = 0.05",
            "exposure_s = -1",
            "",
            "line 22: key 'camera.exposure_s': must be more than 0",
        ),
        (
            "simulated_dome.toml",
            "elevation_deg = 55.0",
            "elevation_deg = -5.0",
            "",
            "line 15: key 'dome.rings[3].elevation_deg': must be at least 0 and at most 90 "
            "(got -5.0)",
        ),
    ],
)
def test_a_number_out_of_range_is_said_with_its_range_and_line(
    tmp_path: Path, shipped: str, old: str, new: str, more: str, expected: str
) -> None:
    said = _check(tmp_path, shipped, old, new, more)
    assert f"rig.toml, {expected}" in said, said
