"""LED dome over a serial port: protocol profiles (codecs), transports, driver, settings.

Start at :func:`rti_rig.drivers.led_dome.factory.build_driver` (the runtime policy above it is
joined in :func:`rti_rig.app.dome_factory.build_dome`); the protocol is specified in
``docs/protocols/led-dome.md``.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from rti_rig.core.lazy_names import lazy_getattr

# The names below are loaded on first use (PEP 562): importing one light module of this
# package (its settings, for a rig config) must not import the driver, its transport and the
# vendor library (``rti-rig plan`` reads a config but drives nothing).
_WHERE = {
    "DomeSerialSettings": "rti_rig.drivers.led_dome.settings",
    "LedDomeDriver": "rti_rig.drivers.led_dome.driver",
    "SerialTransport": "rti_rig.drivers.led_dome.transport",
    "Transport": "rti_rig.drivers.led_dome.transport",
    "TransportError": "rti_rig.drivers.led_dome.transport",
    "build_driver": "rti_rig.drivers.led_dome.factory",
    "make_codec": "rti_rig.drivers.led_dome.profiles",
}

if TYPE_CHECKING:
    from rti_rig.drivers.led_dome.driver import LedDomeDriver
    from rti_rig.drivers.led_dome.factory import build_driver
    from rti_rig.drivers.led_dome.profiles import make_codec
    from rti_rig.drivers.led_dome.settings import DomeSerialSettings
    from rti_rig.drivers.led_dome.transport import SerialTransport, Transport, TransportError


__getattr__ = lazy_getattr(__name__, _WHERE, globals())


__all__ = [
    "DomeSerialSettings",
    "LedDomeDriver",
    "SerialTransport",
    "Transport",
    "TransportError",
    "build_driver",
    "make_codec",
]
