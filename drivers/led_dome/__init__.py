"""LED dome over a serial port: protocol profiles (codecs), transports, driver, settings.

Start at :func:`rti_rig.drivers.led_dome.factory.build_driver` (the runtime policy above it is
joined in :func:`rti_rig.app.dome_factory.build_dome`); the protocol is specified in
``docs/protocols/led-dome.md``.
"""

from rti_rig.drivers.led_dome.driver import LedDomeDriver
from rti_rig.drivers.led_dome.factory import build_driver
from rti_rig.drivers.led_dome.profiles import make_codec
from rti_rig.drivers.led_dome.settings import DomeSerialSettings
from rti_rig.drivers.led_dome.transport import SerialTransport, Transport, TransportError

__all__ = [
    "DomeSerialSettings",
    "LedDomeDriver",
    "SerialTransport",
    "Transport",
    "TransportError",
    "build_driver",
    "make_codec",
]
