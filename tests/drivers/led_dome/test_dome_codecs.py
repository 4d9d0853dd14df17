"""Byte-exact codec tests: scripted exchanges for every dome protocol profile, the host's side
(the commands it writes, the replies it reads), the bytes from docs/protocols/led-dome.md.

The codecs had a firmware side too (decoding commands, encoding replies), used by nothing but
these tests since the emulator reads the wire on its own (simulator/own_protocols.py); it
accepted sequence 0 and, on the binary link, 128 (whose ack byte 0x80 reads as an error), and
it is gone. What its tests showed of the host's side is kept: its commands' bytes, and that a
damaged reply is refused rather than read as another valid one."""

from __future__ import annotations

import pytest

from rti_rig.drivers.led_dome.codec_binary import BinaryCodec
from rti_rig.drivers.led_dome.codec_default import DefaultCodec
from rti_rig.drivers.led_dome.codec_framed import FramedCodec, FramedSpec
from rti_rig.drivers.led_dome.messages import (
    Ack,
    AllOff,
    Banner,
    DomeIdentity,
    Garbled,
    Hello,
    Light,
    LitState,
    Nak,
    Query,
    Shutter,
)
from rti_rig.drivers.led_dome.profiles import make_codec
from rti_rig.drivers.led_dome.settings import DomeSerialSettings

IDENT = DomeIdentity("RTIDOME", "1.2.0", 48)

# (seq, command, command bytes, reply, reply bytes): each row is one scripted exchange.
DEFAULT_SCRIPT = [
    (1, Hello(), b"1 ID*1C\n", Ack(1, IDENT), b"OK 1 ID RTIDOME 1.2.0 48*6B\n"),
    (
        7,
        Light(12, 200, 5000),
        b"7 L 12 200 5000*4F\n",
        Ack(7, Light(12, 200, 5000)),
        b"OK 7 L 12 200 5000*6B\n",
    ),
    (8, AllOff(), b"8 X*40\n", Ack(8, AllOff()), b"OK 8 X*64\n"),
    (9, Shutter(50), b"9 S 50*6F\n", Ack(9, Shutter(50)), b"OK 9 S 50*4B\n"),
    (10, Query(), b"10 Q*70\n", Ack(10, LitState(12, 200)), b"OK 10 Q 12 200*65\n"),
    (10, Query(), b"10 Q*70\n", Ack(10, LitState(None, 0)), b"OK 10 Q -1 0*78\n"),
    (
        11,
        Light(99, 255),
        b"11 L 99 255*5E\n",
        Nak(11, 3, "LED 99 of 48"),
        b"ERR 11 3 LED_99_of_48*41\n",
    ),
]

FRAMED_SCRIPT = [
    (1, Hello(), b"<9,1>", Ack(1, IDENT), b"<OK,1,9,RTIDOME,1.2.0,48>"),
    (7, Light(12, 200), b"<3,7,12,200>", Ack(7, Light(12, 200)), b"<OK,7,3,12,200>"),
    (8, AllOff(), b"<0,8>", Ack(8, AllOff()), b"<OK,8,0>"),
    (9, Shutter(50), b"<6,9,50>", Ack(9, Shutter(50)), b"<OK,9,6,50>"),
    (10, Query(), b"<8,10>", Ack(10, LitState(12, 200)), b"<OK,10,8,12,200>"),
    (10, Query(), b"<8,10>", Ack(10, LitState(None, 0)), b"<OK,10,8,-1,0>"),
    (11, Light(3, 10), b"<3,11,3,10>", Nak(11, 4, "LED fault"), b"<ERR,11,4,LED fault>"),
]

BINARY_SCRIPT = [
    (
        1,
        Hello(),
        bytes.fromhex("a5 01 01 00 00 00 a5"),
        Ack(1, DomeIdentity("binary-0x2A", "1.2", 48)),
        bytes.fromhex("01 01 02 00 30 2a 18"),
    ),
    (7, Light(12, 200), bytes.fromhex("a5 02 07 00 0c c8 64"), Ack(7), bytes.fromhex("07")),
    (8, AllOff(), bytes.fromhex("a5 03 08 00 00 00 ae"), Ack(8), bytes.fromhex("08")),
    (9, Shutter(50), bytes.fromhex("a5 04 09 00 32 00 9a"), Ack(9), bytes.fromhex("09")),
    (
        10,
        Query(),
        bytes.fromhex("a5 05 0a 00 00 00 aa"),
        Ack(10, LitState(12, 200)),
        bytes.fromhex("0a 00 0c c8 ce"),
    ),
    (
        10,
        Query(),
        bytes.fromhex("a5 05 0a 00 00 00 aa"),
        Ack(10, LitState(None, 0)),
        bytes.fromhex("0a ff ff 00 0a"),
    ),
    (11, Light(3, 10), bytes.fromhex("a5 02 0b 00 03 0a a5"), Nak(None, 4), bytes.fromhex("84")),
]

CASES = [
    ("default", DefaultCodec(), DEFAULT_SCRIPT),
    ("framed", FramedCodec(), FRAMED_SCRIPT),
    ("binary", BinaryCodec(), BINARY_SCRIPT),
]
PARAMS = [
    pytest.param(codec, row, id=f"{name}-{i}")
    for name, codec, script in CASES
    for i, row in enumerate(script)
]


@pytest.mark.parametrize(("codec", "row"), PARAMS)
def test_host_encodes_command_bytes_exactly(codec, row):
    seq, cmd, cmd_bytes, _, _ = row
    assert codec.encode_command(seq, cmd) == cmd_bytes


@pytest.mark.parametrize(("codec", "row"), PARAMS)
def test_host_decodes_the_reply_bytes(codec, row):
    _, cmd, _, reply, reply_bytes = row
    assert codec.decode_reply(reply_bytes, cmd) == (reply, len(reply_bytes))
    # byte by byte, a partial reply asks for more and consumes nothing
    for cut in range(len(reply_bytes)):
        got, used = codec.decode_reply(reply_bytes[:cut], cmd)
        assert got is None and used == 0, cut


def test_banners_of_each_profile():
    for codec, raw in (
        (DefaultCodec(), b"READY RTIDOME 1.2.0 48*18\n"),
        (FramedCodec(), b"<READY,RTIDOME,1.2.0,48>"),
    ):
        assert codec.decode_reply(raw, None) == (Banner(IDENT), len(raw))
    assert BinaryCodec().decode_reply(b"\xffRDY", None) == (Banner(None), 4)


def test_default_checksum_catches_a_flipped_byte():
    codec = DefaultCodec()
    reply = bytearray(b"OK 7 L 12 200 5000*6B\n")
    reply[7] ^= 0x01  # '1' -> '0': "L 02" would otherwise parse as LED 2
    got, used = codec.decode_reply(bytes(reply), Light(12, 200))
    assert isinstance(got, Garbled) and "checksum" in got.reason and used == len(reply)
    cmd = bytearray(b"7 L 12 200 5000*4F\n")
    assert codec.encode_command(7, Light(12, 200, 5000)) == bytes(cmd)
    assert DefaultCodec().decode_reply(b"ERR 0 6 checksum_mismatch*35\n", None) == (
        Nak(None, 6, "checksum mismatch"),
        29,
    )


def test_default_without_checksum_and_with_crlf():
    codec = DefaultCodec(checksum=False)
    assert codec.encode_command(3, Light(1, 2)) == b"3 L 1 2\n"
    assert codec.decode_reply(b"OK 3 L 1 2\r\n", None) == (Ack(3, Light(1, 2)), 12)


def test_default_rejects_noise_and_unknown_verbs():
    codec = DefaultCodec(checksum=False)
    got, used = codec.decode_reply(b"HELLO THERE\n", None)
    assert isinstance(got, Garbled) and used == 12
    got, used = codec.decode_reply(b"x" * 300, None)
    assert isinstance(got, Garbled) and used == 300
    got, _ = codec.decode_reply(b"OK 4 Z 1\n", None)
    assert isinstance(got, Garbled) and "unknown verb" in got.reason


#: Replies of the default profile without its checksum, each one byte from a good reply
#: (``OK 10 Q 12 200``, ``OK 1 ID RTIDOME 1.2.0 48`` …) that the host had read as another good
#: one: fields split on any run of spaces, numbers read by ``int``, extra fields ignored.
DAMAGED_DEFAULT = [
    b"OK 10 Q 12 20 \n",  # 200 -> "20 ": level 20 lit
    b"OK 10 Q 12  00\n",  # 200 -> " 00"
    b"OK 1 ID RTIDOME 1.2.0 4 \n",  # a board of 4 LEDs
    b"OK 1 ID RTIDOME 1.2.0 48 8\n",  # a field more
    b"OK 10 Q 1_2 200\n",  # int("1_2") is 12
    b"OK +7 X\n",
    b"OK 0 X\n",  # no command is numbered 0
    b"OK 10000 X\n",
    b"OK 7 L 12 +00\n",
    b"ERR 11 3 LED_99 of_48\n",
    b"OK 10 Q -2 0\n",
]


@pytest.mark.parametrize("raw", DAMAGED_DEFAULT, ids=repr)
def test_a_damaged_default_reply_without_its_checksum_is_garbled(raw):
    got, used = DefaultCodec(checksum=False).decode_reply(raw, None)
    assert isinstance(got, Garbled) and used == len(raw), got


#: The same of the framed profile, which has no checksum at all.
DAMAGED_FRAMED = [
    b"<OK,10,8,12, 20>",
    b"<OK,10,8,12,200,0>",
    b"<OK,1,9,RTIDOME,1.2.0, 8>",
    b"<OK,1,9,RTIDOME,1.2.0,48,8>",
    b"<OK,0,0>",
    b"<OK,+7,0>",
    b"<OK,7,3,1_2,200>",
    b"<READY,RTIDOME,1.2.0,4 >",
]


@pytest.mark.parametrize("raw", DAMAGED_FRAMED, ids=repr)
def test_a_damaged_framed_reply_is_garbled(raw):
    got, used = FramedCodec().decode_reply(raw, None)
    assert isinstance(got, Garbled) and used == len(raw), got


def test_framed_profile_adapts_to_a_legacy_firmware_without_python():
    """A Nab-style firmware: 1-based LEDs, no level, no sequence, CR LF after each frame."""
    settings = DomeSerialSettings.model_validate(
        {
            "port": "x",
            "profile": "framed",
            "framed": {
                "index_base": 1,
                "send_level": False,
                "sequence": False,
                "line_ending": "\r\n",
                "codes": {"hello": "H", "light": "3", "all_off": "0", "shutter": "6"},
                "start": "[",
                "end": "]",
            },
        }
    )
    codec = make_codec(settings)
    assert codec.encode_command(5, Light(0, 255)) == b"[3,1]\r\n"
    assert codec.encode_command(6, AllOff()) == b"[0]\r\n"
    assert codec.encode_command(7, Hello()) == b"[H]\r\n"
    assert codec.decode_reply(b"[OK,3,1]\r\n", Light(0, 255)) == (Ack(None, Light(0, 255)), 8)
    assert codec.decode_reply(b"[OK,3,48]", Light(47, 255)) == (Ack(None, Light(47, 255)), 9)
    got, _ = codec.decode_reply(b"[ERR,4,dead]", None)
    assert got == Nak(None, 4, "dead")


def test_framed_reports_bytes_outside_frames_and_skips_whitespace():
    codec = FramedCodec()
    got, used = codec.decode_reply(b"boot text<OK,1,0>", AllOff())
    assert isinstance(got, Garbled) and used == len(b"boot text")
    assert codec.decode_reply(b"\r\n<OK,1,0>", AllOff()) == (Ack(1, AllOff()), 10)
    got, used = codec.decode_reply(b"<OK,1,0", AllOff())
    assert got is None and used == 0
    got, _ = codec.decode_reply(b"<OK,1,7>", None)  # 7 is no command code
    assert isinstance(got, Garbled)


def test_framed_spec_with_other_words():
    codec = FramedCodec(FramedSpec(ok_word="ACK", err_word="NAK", ready_word="BOOT"))
    assert codec.decode_reply(b"<ACK,2,0>", AllOff()) == (Ack(2, AllOff()), 9)
    got, _ = codec.decode_reply(b"<OK,2,0>", AllOff())
    assert isinstance(got, Garbled)
    assert codec.decode_reply(b"<BOOT>", None) == (Banner(None), 6)


def test_binary_acks_and_errors_are_told_apart():
    codec = BinaryCodec()
    assert codec.decode_reply(b"\x05", AllOff()) == (Ack(5), 1)
    assert codec.decode_reply(b"\x86", AllOff()) == (Nak(None, 6), 1)
    for byte in (0x00, 0xC0, 0xFE):
        got, used = codec.decode_reply(bytes([byte]), AllOff())
        assert isinstance(got, Garbled) and used == 1
    got, _ = codec.decode_reply(b"\xffRDX", None)
    assert isinstance(got, Garbled)
    bad = bytearray(bytes.fromhex("0a 00 0c c8 ce"))
    bad[2] ^= 1
    got, _ = codec.decode_reply(bytes(bad), Query())
    assert isinstance(got, Garbled)


def test_binary_sequence_numbers_stay_acknowledgements():
    """Its ack byte is the sequence number, so 0 and 128 and above are never sent: 0x80 reads
    as an error byte (code 0, no code), and the host refuses it as garbled."""
    codec = BinaryCodec()
    for seq in (0, 128):
        with pytest.raises(ValueError, match=r"1\.\.127"):
            codec.encode_command(seq, AllOff())
    got, _ = codec.decode_reply(b"\x80", AllOff())
    assert isinstance(got, Garbled) and "0x80" in got.reason


def test_binary_index_base_one():
    codec = BinaryCodec(index_base=1)
    assert codec.encode_command(7, Light(0, 9))[3:5] == b"\x00\x01"
    reply = bytes.fromhex("03 00 05 09 0f")  # seq 3, LED 5 (1-based), level 9, xor
    assert codec.decode_reply(reply, Query()) == (Ack(3, LitState(4, 9)), 5)


#: Sample replies of the default profile, checksummed, and the commands they answer.
DEFAULT_REPLIES = [(row[3], row[4], row[1]) for row in DEFAULT_SCRIPT] + [
    (Banner(IDENT), b"READY RTIDOME 1.2.0 48*18\n", None)
]


@pytest.mark.parametrize(("reply", "raw", "cmd"), DEFAULT_REPLIES, ids=lambda v: repr(v)[:30])
def test_every_single_bit_flip_of_a_checksummed_reply_is_refused(reply, raw, cmd):
    """Damage on the wire is never read as another valid reply: it is garbled, or (its line
    ending damaged) still awaiting its end."""
    codec = DefaultCodec()
    assert codec.decode_reply(raw, cmd) == (reply, len(raw))
    for i in range(len(raw)):
        for bit in range(8):
            bad = bytearray(raw)
            bad[i] ^= 1 << bit
            got, _ = codec.decode_reply(bytes(bad), cmd)
            assert got is None or isinstance(got, Garbled), (i, bit, bytes(bad), got)
