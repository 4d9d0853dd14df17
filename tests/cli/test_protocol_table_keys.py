"""A slip in ``[dome.serial.protocol]`` is named by its full key, worded as in every table.

The table is validated by the LED dome's own settings, inside ``[dome.serial]``'s check, so it
had said ``key 'dome.serial': protocol.bogus_key: Extra inputs are not permitted`` (pydantic's
words) for each of the six emulated firmware configs, where every other table says
``key '…bogus_key': unknown key (check its spelling and the table it is in)``.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from conftest import at_key
from typer.testing import CliRunner

from rti_rig.cli import app

REPO = Path(__file__).resolve().parents[2]
FIRMWARES = ["elexol", "minirti", "nab_rti_v1", "nichlock", "rti_dome", "rtipy"]


def _with_protocol_line(tmp_path: Path, firmware: str, line: str) -> Path:
    text = (REPO / "rig_configs" / f"emulated_{firmware}.toml").read_text(encoding="utf-8")
    assert "[dome.serial.protocol]\n" in text
    cfg = tmp_path / f"{firmware}.toml"
    cfg.write_text(text.replace("[dome.serial.protocol]\n", f"[dome.serial.protocol]\n{line}\n"))
    return cfg


def _check(cfg: Path) -> str:
    r = CliRunner().invoke(app, ["check", str(cfg)])
    text = " ".join(r.output.split())
    assert r.exit_code == 2, text
    assert "Traceback" not in text
    return text


@pytest.mark.parametrize("firmware", FIRMWARES)
def test_an_unknown_protocol_key_is_named_in_full_as_in_every_table(
    tmp_path: Path, firmware: str
) -> None:
    cfg = _with_protocol_line(tmp_path, firmware, "bogus_key = 1")
    text = _check(cfg)
    assert (
        f"{at_key(cfg, 'dome.serial.protocol.bogus_key')}: unknown key "
        "(check its spelling and the table it is in)"
    ) in text, text
    assert "Extra inputs" not in text


def test_a_wrong_type_in_the_protocol_table_names_the_key_and_the_value(tmp_path: Path) -> None:
    cfg = _with_protocol_line(tmp_path, "minirti", 'columns = "many"')
    text = _check(cfg)
    assert f"{at_key(cfg, 'dome.serial.protocol.columns')}: Input should be a valid integer" in text
    assert "(got 'many')" in text, text
    assert "key 'dome.serial':" not in text
