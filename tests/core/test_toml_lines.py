"""The line a config error names: where its key is written in the TOML file."""

from __future__ import annotations

import tomllib
from pathlib import Path

import pytest

from rti_rig.core.errors import ConfigError
from rti_rig.core.toml_lines import key_line, key_line_in_file

TEXT = '''\
name = "rig"            # line 1
description = """
exposure_s = 1 is not a key here
"""
[dome]
layout = "lp"
"lp_file" = "a.lp"      # line 7
serial.port = "/dev/ttyACM0"

[camera]
exposure_s = 0.05       # line 11
decode = { white_balance = [0, 1, 1, 1] }

[[emulator.faults]]     # line 14
at_command = 3
kind = "drop_reply"

[[emulator.faults]]
at_command = 5          # line 19
kind = "bogus"

[emulator.faults.extra]
why = "a sub-table of the second fault"   # line 23

[ring_table]
rings = [              # line 26
  { elevation_deg = 10.0, count = 12 },
  { elevation_deg = 25.0, count = 12 },
]
after = 1              # line 30
[first_inline]
rings = [ { count = 1 },   # line 32
  { count = "a, {b}" },    # line 33: a comma and braces in a string are no structure
]
[scalars]
rings = [ [1, 2],
  { count = 3 },           # line 37
]
'''


@pytest.mark.parametrize(
    ("key", "line"),
    [
        ("name", 1),
        ("dome", 5),
        ("dome.lp_file", 7),
        ("dome.serial.port", 8),
        ("camera.exposure_s", 11),
        ("camera.decode.white_balance", 12),  # inside an inline table: its assignment's line
        ("emulator.faults[0].at_command", 15),
        ("emulator.faults[1].at_command", 19),
        ("emulator.faults[1].kind", 20),
        ("emulator.faults[1].extra.why", 23),
        ("ring_table.rings", 26),
        # an inline table of an array over several lines: its own line (the shipped configs'
        # rings had been named with no line)
        ("ring_table.rings[0].count", 27),
        ("ring_table.rings[1].elevation_deg", 28),
        ("ring_table.after", 30),  # after a value over several lines: counted on
        ("first_inline.rings[0].count", 32),  # an element on the assignment's own line
        ("first_inline.rings[1].count", 33),
        ("scalars.rings[1].count", 37),  # elements counted past a nested array
    ],
)
def test_a_key_is_found_on_the_line_it_is_written(key: str, line: int) -> None:
    tomllib.loads(TEXT)  # the text is TOML, as any file a key is refused in has been read
    assert key_line(TEXT, key) == line


@pytest.mark.parametrize(
    "key",
    [
        "exposure_s",  # only inside a multi-line string
        "camera.width",  # a key its table lacks: the header is not its line
        "emulator.faults[2].kind",
        "scene.name",
        # inside a value over several lines: its first line is not the key's (a wrong line is
        # worse than none; the shipped simulated_dome.toml's rings had been named line 11)
        "ring_table.rings[2].count",
        "ring_table.elevation_deg",
    ],
)
def test_a_key_not_written_has_no_line(key: str) -> None:
    assert key_line(TEXT, key) is None


def test_a_config_error_names_the_line_of_its_key(tmp_path: Path) -> None:
    cfg = tmp_path / "rig.toml"
    cfg.write_text(TEXT)
    said = str(ConfigError(cfg, "emulator.faults[1].kind", "unknown fault"))
    assert said == f"{cfg}, line 20: key 'emulator.faults[1].kind': unknown fault"
    assert str(ConfigError(cfg, "camera.width", "required")).startswith(f"{cfg}: key ")


def test_a_file_that_cannot_be_read_gives_no_line(tmp_path: Path) -> None:
    assert key_line_in_file(tmp_path / "gone.toml", "name") is None
    binary = tmp_path / "b.toml"
    binary.write_bytes(b"\xff\xfe\x00name = 1")
    assert key_line_in_file(binary, "name") is None
    assert key_line_in_file(tmp_path, "name") is None  # a folder


def test_a_file_with_a_byte_order_mark_finds_its_first_key(tmp_path: Path) -> None:
    cfg = tmp_path / "bom.toml"
    cfg.write_bytes("\ufeffname = 1\nkind = 2\n".encode())
    assert key_line_in_file(cfg, "name") == 1 and key_line_in_file(cfg, "kind") == 2
