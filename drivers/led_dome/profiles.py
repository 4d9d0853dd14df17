"""From the rig config's profile name and options to a codec: no Python needed for a new dome."""

from __future__ import annotations

from rti_rig.drivers.led_dome.codec_base import DomeCodec
from rti_rig.drivers.led_dome.codec_binary import BinaryCodec
from rti_rig.drivers.led_dome.codec_default import DefaultCodec
from rti_rig.drivers.led_dome.codec_framed import FramedCodec, FramedSpec
from rti_rig.drivers.led_dome.settings import (
    BinaryOptions,
    DefaultProfileOptions,
    DomeSerialSettings,
    FramedOptions,
)


def make_codec(settings: DomeSerialSettings) -> DomeCodec:
    """The codec of ``settings.profile`` configured with its options."""
    if settings.profile == "default":
        d = settings.default or DefaultProfileOptions()
        return DefaultCodec(checksum=d.checksum)
    if settings.profile == "framed":
        f = settings.framed or FramedOptions()
        return FramedCodec(
            FramedSpec(
                start=f.start,
                end=f.end,
                separator=f.separator,
                line_ending=f.line_ending,
                codes=f.codes.model_dump(),
                index_base=f.index_base,
                send_level=f.send_level,
                sequence=f.sequence,
                ok_word=f.ok_word,
                err_word=f.err_word,
                ready_word=f.ready_word,
                full_level=settings.max_level,
            )
        )
    b = settings.binary or BinaryOptions()
    return BinaryCodec(start_byte=b.start_byte, index_base=b.index_base)
