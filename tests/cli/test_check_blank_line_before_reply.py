"""A stray CR LF before a ``default``-profile reply is skipped, not read as a garbled reply.

Found by a review: serial firmwares leave stray line endings (an Arduino sketch's
``Serial.println()`` after its banner, a CR LF host line ending echoed back), and the driver
read the empty line as a garbled reply, resent the command and counted a fault the board never
made. No firmware in dome-firmwares.md is recorded emitting an empty line alone; the Nab
sketch's multi-line banner and its CR LF endings, and the Elexol board's ``\\r\\n``, are the
line endings real boards do send. The emulated board (``blank_line_before_reply``) sends the
CR LF ahead of its reply on the pty, through the shipped dry run's real driver and pyserial."""

from __future__ import annotations

from pathlib import Path

from conftest import CONFIGS, shipped_variant
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.drivers.led_dome.codec_default import DefaultCodec
from rti_rig.drivers.led_dome.messages import Ack, Garbled, Light

LP = ('lp_file = "example_dome_48.lp"', f'lp_file = "{CONFIGS / "example_dome_48.lp"}"')
#: the CR LF before the handshake's reply, and before a light command's in the walk
FAULTS = (
    'faults = [{ at_command = 1, kind = "blank_line_before_reply" }, '
    '{ at_command = 5, kind = "blank_line_before_reply" }]\n'
)


def _check(config: Path) -> tuple[int, str]:
    r = CliRunner().invoke(app, ["check", str(config)], terminal_width=400)
    return r.exit_code, " ".join(r.output.split())


def test_a_stray_crlf_before_a_reply_is_no_fault(tmp_path: Path) -> None:
    code, text = _check(shipped_variant(tmp_path, "emulated_dome.toml", (LP,), FAULTS))
    assert code == 0, text
    assert "recovery: 0 retries, 0 reconnects, 0 re-handshakes" in text, text
    assert "garbled" not in text and text.endswith("RESULT: PASS"), text


def test_the_fault_is_refused_on_a_link_where_crlf_is_no_line(tmp_path: Path) -> None:
    config = shipped_variant(
        tmp_path, "emulated_dome.toml", (LP, ('profile = "default"', 'profile = "binary"')), FAULTS
    )
    code, text = _check(config)
    assert code == 2, text
    assert "emulator.faults[0]: blank_line_before_reply is a stray CR LF" in text, text
    assert "Traceback" not in text, text


def test_only_an_empty_line_is_skipped_a_garbled_one_is_still_refused() -> None:
    codec = DefaultCodec(checksum=False)
    reply = b"OK 3 L 1 2\r\n"
    assert codec.decode_reply(b"\r\n" + reply, None) == (None, 2)
    assert codec.decode_reply(b"\n" + reply, None) == (None, 1)
    assert codec.decode_reply(reply, None) == (Ack(3, Light(1, 2)), len(reply))
    for noise in (b" \r\n", b"\x00\r\n", b"OK\r\n"):
        got, used = codec.decode_reply(noise + reply, None)
        assert isinstance(got, Garbled) and used == len(noise), noise
    got, used = DefaultCodec().decode_reply(b"OK 8 X\r\n", None)  # its checksum lost
    assert isinstance(got, Garbled) and "missing checksum" in got.reason
