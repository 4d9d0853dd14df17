"""A required key left out of a rig config is said with what to write and where.

Before: pydantic's own words, ``key 'dome.serial.port': Field required``, with no hint of
the line to add (every other refusal of a config says what to do)."""

from __future__ import annotations

from pathlib import Path

import pytest
from typer.testing import CliRunner

from rti_rig.cli import app

CONFIGS = Path(__file__).resolve().parents[2] / "rig_configs"


@pytest.mark.parametrize(
    ("config", "line", "said"),
    [
        (
            "emulated_nab_rti_v1.toml",
            'port = "emulated"',
            "key 'dome.serial.port': required, and not given: add a line port = … under "
            "[dome.serial]",
        ),
        (
            "simulated_dome.toml",
            'name = "simulated-dome-48"',
            "key 'name': required, and not given: add a line name = … at the top of the file",
        ),
    ],
)
def test_a_required_key_left_out_is_said_with_the_line_to_add(
    tmp_path: Path, config: str, line: str, said: str
) -> None:
    text = (CONFIGS / config).read_text(encoding="utf-8")
    assert any(row.strip().startswith(line) for row in text.splitlines()), line
    kept = [row for row in text.splitlines() if not row.strip().startswith(line)]
    path = tmp_path / config
    path.write_text("\n".join(kept) + "\n", encoding="utf-8")
    r = CliRunner().invoke(app, ["check", str(path)])
    assert r.exit_code == 2, r.output
    assert said in " ".join(r.output.split()), r.output
