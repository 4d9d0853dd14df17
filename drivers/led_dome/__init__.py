"""LED dome over a serial port: protocol profiles (codecs), transports, driver, settings.

Start at :func:`drivers.led_dome.factory.build_dome`; the protocol is specified in
``docs/protocols/led-dome.md``.
"""

from drivers.led_dome.driver import LedDomeDriver
from drivers.led_dome.factory import build_dome, build_driver
from drivers.led_dome.profiles import make_codec
from drivers.led_dome.settings import DomeSerialSettings
from drivers.led_dome.transport import SerialTransport, Transport, TransportError

__all__ = [
    "DomeSerialSettings",
    "LedDomeDriver",
    "SerialTransport",
    "Transport",
    "TransportError",
    "build_dome",
    "build_driver",
    "make_codec",
]
