"""``rti-rig probe`` names a board that speaks one of rti-rig's own protocols.

The shipped hardware dome configs speak the project's own protocols (``default``, ``framed``),
whose boards print a ``READY`` banner at every boot. The probe knew only other projects'
firmwares: on such a board it said "No known dome firmware answered", the ``READY`` line among
the lines heard, and advised ``profile = "rti-dome-m"`` (a dome that never answers).
"""

from __future__ import annotations

import shlex
import sys
from pathlib import Path

import pytest
from conftest import CONFIGS, emulated_dome_as_hardware, said, shipped_dome_on_pty
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.simulator.own_protocols import BoardFacts, DefaultProfile

pytestmark = [
    pytest.mark.skipif(sys.platform != "linux", reason="pty semantics tested on Linux"),
    pytest.mark.pty,
]
runner = CliRunner()


def test_probe_names_the_default_protocol_of_the_shipped_emulated_dome(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    port = "/dev/ttyACM7"
    (tmp_path / "example_dome_48.lp").write_bytes((CONFIGS / "example_dome_48.lp").read_bytes())
    config = emulated_dome_as_hardware(tmp_path, "emulated_dome.toml", port)
    with shipped_dome_on_pty(monkeypatch, config) as firmware:
        r = runner.invoke(app, ["probe", port], terminal_width=400)
        words = said(r)
        assert r.exit_code == 0, words
        assert "No known dome firmware" not in words and "Traceback" not in words
        assert f'Found: default. Rig-config lines to use: [dome.serial] port = "{port}" ' in words
        assert 'profile = "default" baudrate = 115200' in words, words
        assert "it announced RTIDOME-EMU 1.0.0 with 48 LEDs" in words
        assert "Lights: nothing was lit by the probe" in words
        assert firmware.commands_received == 0  # it only listened


def test_probe_names_the_framed_protocol_of_the_shipped_hardware_dome(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    config = CONFIGS / "example_dome_48.toml"
    port = "/dev/serial/by-id/usb-Arduino_Mega_2560-if00"
    assert f'port = "{port}"' in config.read_text()
    with shipped_dome_on_pty(monkeypatch, config):
        r = runner.invoke(app, ["probe", port], terminal_width=400)
        words = said(r)
        assert r.exit_code == 0, words
        assert "No known dome firmware" not in words and "Traceback" not in words
        assert "Found: framed." in words and 'profile = "framed" baudrate = 115200' in words
        # what its banner does not tell (the shipped config's index_base = 1) is named
        assert "set [dome.serial.framed]" in words and "index_base" in words


def _probe_a_default_board(
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    codec: DefaultProfile,
    checksum: bool,
    *extra: str,
    code: int = 0,
) -> str:
    """What ``rti-rig probe`` says of the shipped emulated dome's board speaking ``codec``,
    checked for what every default board's probe must say (named, its checksum setting, and
    nothing sent to it)."""
    port = "/dev/ttyACM7"
    (tmp_path / "example_dome_48.lp").write_bytes((CONFIGS / "example_dome_48.lp").read_bytes())
    config = emulated_dome_as_hardware(tmp_path, "emulated_dome.toml", port)
    with shipped_dome_on_pty(monkeypatch, config) as firmware:
        firmware.codec = codec
        r = runner.invoke(app, ["probe", port, *extra], terminal_width=400)
        words = said(r)
        assert r.exit_code == code, words
        assert "No known dome firmware" not in words and "Traceback" not in words
        assert 'profile = "default" baudrate = 115200' in words, words
        assert ("checksum = false" in words) is not checksum, words
        assert firmware.commands_received == 0  # it only listened
    return words


@pytest.mark.parametrize("checksum", [True, False], ids=["checksum", "no-checksum"])
def test_probe_names_a_default_board_whose_lines_end_in_cr_lf(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, checksum: bool
) -> None:
    """An Arduino sketch's ``Serial.println`` ends its banner in CR LF (the emulator's
    ``line_end``; docs/protocols/led-dome.md allows it), which the driver
    reads: the probe's banner pattern wanted a bare LF, and such a board was "No known dome
    firmware answered", its READY line among the lines heard."""
    codec = DefaultProfile(checksum=checksum, line_end=b"\r\n")
    words = _probe_a_default_board(tmp_path, monkeypatch, codec, checksum)
    assert "it announced RTIDOME-EMU 1.0.0 with 48 LEDs" in words


class _WithRevision(DefaultProfile):
    """A default board whose banner has a field after the LED count (a board revision)."""

    def banner(self, facts: BoardFacts) -> bytes:
        return self._line(f"READY {facts.firmware_id} {facts.version} {facts.led_count} rev-B")


@pytest.mark.parametrize("checksum", [True, False], ids=["checksum", "no-checksum"])
def test_probe_names_a_default_board_whose_banner_has_an_extra_field_and_says_it(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, checksum: bool
) -> None:
    """A banner with a field after the LED count (a board revision) reads as damaged to the
    codec: the probe had said "No known dome firmware answered" and named nothing. Then it
    said "Found: default" and exited 0, though every check of the board fails on that
    banner: it exits 1, saying the board cannot be used as it is, and ends with the check of
    the rig config named by --rig, a command that pastes ("then run rti-rig check" had named
    no config)."""
    rig = tmp_path / "my rigs" / "dome.toml"
    words = _probe_a_default_board(
        tmp_path,
        monkeypatch,
        _WithRevision(checksum=checksum),
        checksum,
        "--rig",
        str(rig),
        code=1,
    )
    assert "carries 1 field(s) more than rti-rig's default protocol's" in words, words
    assert "('rev-B')" in words and "end the firmware's banner at the LED count" in words
    found = "Found: default, but its boot banner has fields after the LED count, so rti-rig "
    assert found + "cannot use it as it is" in words, words
    assert f"then run rti-rig check {shlex.quote(str(rig))}" in words, words


def test_probe_writes_a_windows_device_path_as_a_line_toml_reads_back(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A Windows port past COM9 is opened by its device path, ``\\\\.\\COM10``: the line the
    probe says to paste must read back as that port (it was written unescaped, a line TOML
    refuses for its ``\\.`` escape)."""
    import tomllib

    port = "\\\\.\\COM10"
    (tmp_path / "example_dome_48.lp").write_bytes((CONFIGS / "example_dome_48.lp").read_bytes())
    config = emulated_dome_as_hardware(tmp_path, "emulated_dome.toml", port)
    with shipped_dome_on_pty(monkeypatch, config):
        r = runner.invoke(app, ["probe", port], terminal_width=400)
    assert r.exit_code == 0, r.output
    block = r.output.split("Rig-config lines to use:", 1)[1].split("\n\n", 1)[0]
    lines = [
        line.strip()
        for line in block.splitlines()
        if line.strip().startswith(("[", "port", "profile", "baudrate"))
    ]
    assert tomllib.loads("\n".join(lines))["dome"]["serial"]["port"] == port, lines


def test_probe_of_a_firmware_that_reports_no_led_count_says_to_add_it_and_what_next(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The Nab sketch reports no LED count, and its lines pasted into a config of another
    count were refused at load: the probe says to add led_count, then the check to run (the
    probe had ended on its lines for every firmware but rti-rig's own)."""
    port = "/dev/ttyACM5"
    config = emulated_dome_as_hardware(tmp_path, "emulated_nab_rti_v1.toml", port)
    with shipped_dome_on_pty(monkeypatch, config):
        r = runner.invoke(app, ["probe", port, "--rig", str(config)], terminal_width=400)
    words = said(r)
    assert "Found: nab-rti-v1." in words, words
    assert "does not report how many LEDs it drives (at most 64)" in words, words
    assert "under [dome.serial.protocol] add led_count" in words, words
    assert f"Next: put these lines in {config}, then run rti-rig check {config}" in words, words
