"""Rig-config serial settings → codec + transport + driver (the bytes side of a dome).

The retry/thermal policy above the driver is the runtime's; the composition root joins the two
(:func:`rti_rig.app.dome_factory.build_dome`). Tests and the dry run pass their own transport
(the emulator in-process or on a pty) and the same settings.
"""

from __future__ import annotations

from rti_rig.drivers.led_dome.driver import LedDomeDriver
from rti_rig.drivers.led_dome.profiles import make_codec
from rti_rig.drivers.led_dome.settings import DomeSerialSettings
from rti_rig.drivers.led_dome.transport import SerialTransport, Transport


def build_driver(
    settings: DomeSerialSettings, transport: Transport | None = None, *, name: str = "dome"
) -> LedDomeDriver:
    """The driver for ``settings`` on ``transport`` (default: the serial port it names)."""
    return LedDomeDriver(
        transport or SerialTransport(settings.port, settings.baudrate),
        make_codec(settings),
        device=name,
        reply_timeout_s=settings.reply_timeout_s,
        ready_timeout_s=settings.ready_timeout_s,
        max_level=settings.max_level,
    )
