"""The own protocols' emulator answers as docs/protocols/led-dome.md says, read from the page.

The emulator (``rti_rig.simulator.own_protocols``) is written from the page, not from the
driver's codecs, so that the driver's tests against it check the driver against the spec. These
tests hold the emulator to the page's own examples: the default profile's example exchange is
read from the page itself, so a page and an emulator that part ways fail here.
"""

from __future__ import annotations

import importlib.util
from pathlib import Path
from typing import Any

import pytest

from rti_rig.drivers.led_dome.messages import Ack, AllOff, Light, LitState, Nak
from rti_rig.drivers.led_dome.profiles import make_codec
from rti_rig.drivers.led_dome.settings import DomeSerialSettings
from rti_rig.simulator.dome_firmware import DomeFirmware, firmware_for
from rti_rig.simulator.own_protocols import (
    BinaryProfile,
    BoardFacts,
    DefaultProfile,
    FramedProfile,
    Refused,
    Request,
    Verb,
)

SPEC = Path(__file__).resolve().parents[2] / "docs" / "protocols" / "led-dome.md"
FACTS = BoardFacts("RTIDOME", "1.2.0", 48)


def spec_example_exchange() -> list[tuple[str, bytes]]:
    """The default profile's "Example exchange" block of the page, as (who, line) pairs."""
    text = SPEC.read_text(encoding="utf-8")
    block = text.split("Example exchange", 1)[1].split("```", 2)[1]
    pairs = []
    for line in block.splitlines():
        who, _, said = line.partition(":")
        if who in ("host", "board"):
            pairs.append((who, said.strip().encode("ascii") + b"\n"))
    return pairs


def test_the_default_board_answers_the_pages_example_exchange_byte_for_byte() -> None:
    """A firmware built like the page's board (RTIDOME 1.2.0, 48 LEDs, LED 12 at 200 lit
    before the X) says every board line of the example, banner included."""
    exchange = spec_example_exchange()
    assert len(exchange) >= 8, exchange
    firmware = DomeFirmware(DefaultProfile(), firmware_id="RTIDOME", version="1.2.0")
    said = [out.data for out in firmware.boot()]
    for who, line in exchange[1:]:
        if who == "host":
            said += [out.data for out in firmware.receive(line)]
    assert said == [line for who, line in exchange if who == "board"]


@pytest.mark.parametrize(
    "line",
    [
        b"7 L 12 200 5000*4E\n",
        b"7 L 12 200 5000*4f\n",
        b"7 L 12 200 5000\n",
        b"7 L 02 200 5000*4F\n",
    ],
    ids=["bad", "lower-case", "missing", "flipped-digit"],
)
def test_a_line_with_a_missing_or_bad_checksum_is_refused_with_error_6_seq_0(line: bytes) -> None:
    """The page: "A line with a missing or bad checksum is refused with error 6", and "seq is
    0 when the command was too damaged to read its number" (a bad check says no number is
    sure)."""
    codec = DefaultProfile()
    parsed, used = codec.decode(line + b"8 X*40\n")
    assert isinstance(parsed, Refused) and parsed.code == 6 and used == len(line)
    assert codec.err(parsed.seq, parsed.code, parsed.text).startswith(b"ERR 0 6 ")


def test_default_verbs_and_their_acknowledgements() -> None:
    codec = DefaultProfile(checksum=False)
    shutter, _ = codec.decode(b"9 S 50\n")
    assert shutter == Request(Verb.SHUTTER, 9, pulse_ms=50)
    assert codec.ok(shutter, FACTS, None) == b"OK 9 S 50\n"
    query, _ = codec.decode(b"10 Q\n")
    assert codec.ok(query, FACTS, None) == b"OK 10 Q -1 0\n"
    unknown, _ = codec.decode(b"4 Z 1\n")
    assert isinstance(unknown, Refused) and (unknown.seq, unknown.code) == (4, 1)
    negative, _ = codec.decode(b"4 L -1 2\n")
    assert isinstance(negative, Refused) and (negative.seq, negative.code) == (4, 2)
    assert codec.decode(b"4 L 1") == (None, 0)  # a line not yet ended waits


def test_framed_examples_of_the_page() -> None:
    codec = FramedProfile()
    light, used = codec.decode(b"\n<3,7,12,200>")
    assert (light, used) == (None, 1)  # bytes between frames are skipped
    light, used = codec.decode(b"<3,7,12,200>\n")
    assert light == Request(Verb.LIGHT, 7, 12, 200) and used == len(b"<3,7,12,200>")
    assert codec.ok(light, FACTS, None) == b"<OK,7,3,12,200>"
    assert codec.err(11, 4, "LED fault") == b"<ERR,11,4,LED fault>"
    assert codec.banner(FACTS) == b"<READY,RTIDOME,1.2.0,48>"


def test_framed_options_one_based_without_level_or_sequence() -> None:
    codec = FramedProfile(start="[", end="]", index_base=1, send_level=False, sequence=False)
    light, used = codec.decode(b"[3,48]\r\n")
    assert light == Request(Verb.LIGHT, None, 47, 255) and used == 6
    assert codec.ok(light, FACTS, None) == b"[OK,3,48]"
    assert codec.err(None, 4, "dead") == b"[ERR,4,dead]"


def test_binary_packets_of_the_page() -> None:
    codec = BinaryProfile()
    hello, used = codec.decode(bytes.fromhex("a5 01 01 00 00 00 a5"))
    assert hello == Request(Verb.HELLO, 1) and used == 7
    facts = BoardFacts("any", "1.2", 48, firmware_code=0x2A)
    assert codec.ok(hello, facts, None) == bytes.fromhex("01 01 02 00 30 2a 18")
    query, _ = codec.decode(bytes.fromhex("a5 05 0a 00 00 00 aa"))
    assert codec.ok(query, facts, (12, 200)) == bytes.fromhex("0a 00 0c c8 ce")
    assert codec.ok(query, facts, None) == bytes.fromhex("0a ff ff 00 0a")
    light, _ = codec.decode(bytes.fromhex("a5 02 07 00 0c c8 64"))
    assert light == Request(Verb.LIGHT, 7, 12, 200) and codec.ok(light, facts, None) == b"\x07"
    assert codec.err(None, 4, "") == b"\x84"
    bad = bytearray(bytes.fromhex("a5 02 07 00 0c c8 64"))
    bad[4] ^= 0x41
    refused, used = codec.decode(bytes(bad))
    assert isinstance(refused, Refused) and refused.code == 6 and used == 7
    assert codec.decode(b"\x00\xa5\x02") == (None, 1)  # noise before a packet is skipped
    assert codec.banner(facts) == b"\xffRDY"


def test_a_sequence_number_outside_the_profiles_range_is_refused_with_error_2() -> None:
    """The page: ``default`` numbers 1..9999, ``binary`` 1..127 (an ack byte 0x00 or 0x80..
    would not be an ack); a board that acknowledged them would answer what no host can match."""
    for line in (b"0 X\n", b"10000 X\n"):
        refused, _ = DefaultProfile(checksum=False).decode(line)
        assert isinstance(refused, Refused) and (refused.seq, refused.code) == (None, 2), line
    for seq in (0x00, 0x80):
        packet = bytes([0xA5, 0x03, seq, 0, 0, 0])
        refused, _ = BinaryProfile().decode(packet + bytes([0xA5 ^ 0x03 ^ seq]))
        assert isinstance(refused, Refused) and refused.code == 2, seq
        assert BinaryProfile().err(refused.seq, refused.code, refused.text) == b"\x82"


def _codec_fixtures() -> Any:
    """``tests/drivers/led_dome/test_dome_codecs.py``, the page's normative byte-exact
    fixtures, loaded by its path (a test module, not a package's)."""
    path = Path(__file__).resolve().parents[1] / "drivers" / "led_dome" / "test_dome_codecs.py"
    spec = importlib.util.spec_from_file_location("_dome_codec_fixtures", path)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


_FIXTURES = _codec_fixtures()


@pytest.mark.parametrize(
    ("profile", "row"),
    [
        pytest.param(profile, row, id=f"{profile}-{i}")
        for profile, script in (
            ("default", _FIXTURES.DEFAULT_SCRIPT),
            ("framed", _FIXTURES.FRAMED_SCRIPT),
            ("binary", _FIXTURES.BINARY_SCRIPT),
        )
        for i, row in enumerate(script)
    ],
)
def test_the_emulator_answers_every_fixture_exchange_as_the_fixture_says(
    profile: str, row: tuple[Any, ...]
) -> None:
    """The page names the codec tests' scripted exchanges its normative examples: a board
    (RTIDOME 1.2.0, 48 LEDs, LED 3 dead) sent each command's bytes answers the reply's bytes,
    the state a query reports set first by the script's own light or all-off. An error's text
    is the board's own (the page fixes only its seq and code)."""
    settings = DomeSerialSettings(port="loop://", profile=profile)
    firmware = firmware_for(settings, firmware_id="RTIDOME", version="1.2.0", dead_leds={3})
    firmware.boot()
    script = {"default": _FIXTURES.DEFAULT_SCRIPT, "framed": _FIXTURES.FRAMED_SCRIPT}.get(
        profile, _FIXTURES.BINARY_SCRIPT
    )
    _, cmd, cmd_bytes, reply, reply_bytes = row
    echo = getattr(reply, "echo", None)
    if isinstance(echo, LitState):  # the state the query reads, set by the script
        wanted = Light if echo.index is not None else AllOff
        before = next(r for r in script if isinstance(r[1], wanted) and isinstance(r[3], Ack))
        firmware.receive(before[2])
    answered = b"".join(out.data for out in firmware.receive(cmd_bytes))
    if isinstance(reply, Nak):
        heard, used = make_codec(settings).decode_reply(answered, cmd)
        assert used == len(answered) and isinstance(heard, Nak), answered
        assert (heard.seq, heard.code) == (reply.seq, reply.code), answered
    else:
        assert answered == reply_bytes
