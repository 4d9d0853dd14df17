"""Two rig configs with ``profile = "custom"`` describing different protocols are different
rigs to a resume: the identity holds what defines the protocol (its commands and LED
addressing), not the name "custom" alone, which had passed one board for another. What does
not change which light an LED index is (a reply timeout, the port) keeps the rig the same."""

from __future__ import annotations

from pathlib import Path

from rti_rig.app.config import load_rig_config
from rti_rig.app.rig_identity import identity_differences, rig_identity

#: the camera both templates end with (a folder watch: nothing here opens a device)
CAMERA = """
[camera]
width = 64
height = 48
exposure_s = 0.05

[camera.device]
kind = "folder_watch"
folder = "{folder}"
"""

CUSTOM = (
    """
name = "my-dome"
kind = "dome"
backend = "hardware"

[dome]
layout = "fibonacci"
count = 12
min_elevation_deg = 15.0

[dome.serial]
port = "{port}"
profile = "custom"
baudrate = 9600

[dome.serial.protocol]
name = "{protocol}"
led_count = 12
index_base = {base}
columns = {columns}

[dome.serial.protocol.light]
send = "{light}"
reply = {{ kind = "line", timeout_s = {timeout} }}

[dome.serial.protocol.all_off]
send = "X\\n"
reply = {{ kind = "line" }}
"""
    + CAMERA
)


def _identity(tmp_path: Path, name: str, **keys: object) -> dict[str, object]:
    values = {"port": "/dev/ttyUSB0", "base": 0, "light": "L{index}\\n", "timeout": 1.0}
    values.update(protocol="my-dome", columns=8)
    values["folder"] = str(tmp_path / "shots")
    values.update(keys)
    path = tmp_path / f"{name}.toml"
    path.write_text(CUSTOM.format(**values))
    return rig_identity(load_rig_config(path))


def test_two_custom_protocols_are_two_rigs(tmp_path: Path) -> None:
    first = _identity(tmp_path, "a")
    for name, change in (("b", {"light": "ON {index}\\n"}), ("c", {"base": 1})):
        said = identity_differences(first, _identity(tmp_path, name, **change))
        assert len(said) == 1, said
        assert said[0].startswith("dome protocol described in the config: changed"), said
        assert "profile name 'custom'" in said[0], said


def test_what_does_not_address_the_leds_keeps_the_custom_rig(tmp_path: Path) -> None:
    first = _identity(tmp_path, "a")
    again = _identity(tmp_path, "b", port="/dev/ttyUSB1", timeout=2.5)
    assert identity_differences(first, again) == []


def test_a_label_or_a_key_no_command_uses_keeps_the_custom_rig(tmp_path: Path) -> None:
    """The protocol's ``name`` is a label and ``columns`` only numbers ``{row}``/``{col}``:
    with neither in the commands, both had been in the digest and refused the resume as "its
    commands or LED numbering differ". Where a command does use them, columns is the rig."""
    first = _identity(tmp_path, "a")
    again = _identity(tmp_path, "b", protocol="renamed", columns=4)
    assert identity_differences(first, again) == []
    grid = _identity(tmp_path, "c", light="R{row}C{col}\\n")
    regrid = _identity(tmp_path, "d", light="R{row}C{col}\\n", columns=4)
    said = identity_differences(grid, regrid)
    assert len(said) == 1 and said[0].startswith("dome protocol described in the config"), said


def test_a_custom_session_recorded_before_the_protocol_digest_resumes(tmp_path: Path) -> None:
    before = _identity(tmp_path, "a")
    assert before.pop("dome_protocol")
    assert identity_differences(before, _identity(tmp_path, "b", light="ON {index}\\n")) == []


BUILTIN = (
    """
name = "minirti-64"
kind = "dome"
backend = "hardware"

[dome]
layout = "fibonacci"
count = 64
min_elevation_deg = 15.0

[dome.serial]
port = "/dev/ttyACM0"
profile = "minirti"
{table}
"""
    + CAMERA
)


def _builtin_identity(tmp_path: Path, name: str, table: str) -> dict[str, object]:
    path = tmp_path / f"{name}.toml"
    path.write_text(BUILTIN.format(table=table, folder=tmp_path / "shots"))
    return rig_identity(load_rig_config(path))


def test_a_table_restating_a_builtin_protocol_keeps_the_rig(tmp_path: Path) -> None:
    """A built-in profile without a ``[dome.serial.protocol]`` table is recorded without a
    digest; a table laid over it on resume that changes nothing defining (the built-in's own
    LED count, a boot wait) had been refused as "none → 4d016391974ed4e4". One that does
    change the addressing is named as changed, in words, not as a digest."""
    bare = _builtin_identity(tmp_path, "bare", "")
    assert bare["dome_protocol"] is None
    for name, table in (
        ("count", "[dome.serial.protocol]\nled_count = 64\n"),
        ("wait", "[dome.serial.protocol]\nboot_wait_s = 3.0\n"),
    ):
        restated = _builtin_identity(tmp_path, name, table)
        assert restated["dome_protocol"] is not None
        assert identity_differences(bare, restated) == []
        assert identity_differences(restated, bare) == []
    unused = _builtin_identity(
        tmp_path, "cols", '[dome.serial.protocol]\nname = "ours"\ncolumns = 4\n'
    )
    assert identity_differences(bare, unused) == [] == identity_differences(unused, bare)
    other = _builtin_identity(
        tmp_path, "lsb", '[dome.serial.protocol]\nmask_bit_order = "lsb-first"\n'
    )
    for said in (identity_differences(bare, other), identity_differences(other, bare)):
        assert len(said) == 1, said
        assert said[0].startswith("dome protocol described in the config: changed"), said
        assert "profile name 'minirti'" in said[0] and "none" not in said[0], said
