"""Rig-config serial settings → codec + transport + driver (the bytes side of a dome).

The retry/thermal policy above the driver is the runtime's; the composition root joins the two
(:func:`rti_rig.app.dome_factory.build_dome`). Tests and the dry run pass their own transport
(the emulator in-process or on a pty) and the same settings. This project's own protocols run
on :class:`LedDomeDriver` with a codec; real firmwares (built-in profiles by name, or "custom")
run on :class:`ScriptedDomeDriver` from their protocol description.
"""

from __future__ import annotations

from pathlib import Path

from rti_rig.core.errors import ConfigError
from rti_rig.core.shell_words import shown_path
from rti_rig.drivers.led_dome.driver import LedDomeDriver
from rti_rig.drivers.led_dome.profiles import make_codec
from rti_rig.drivers.led_dome.protocol_spec import MissingSection, ProtocolSpec, parse_led_map
from rti_rig.drivers.led_dome.scripted import ScriptedDomeDriver
from rti_rig.drivers.led_dome.settings import DomeSerialSettings
from rti_rig.drivers.led_dome.transport import SerialTransport, Transport


def protocol_for(settings: DomeSerialSettings) -> ProtocolSpec:
    """The protocol description of a firmware profile, its LED map file read if it names one."""
    led_map = None
    if settings.led_map_file is not None:
        path = Path(settings.led_map_file)
        try:
            text = path.read_text(encoding="utf-8")
        except OSError as exc:
            raise ConfigError(
                str(path), "dome.serial.led_map_file", f"cannot read it: {exc.strerror or exc}"
            ) from None
        try:
            # named in its errors as the user pastes it (a name not UTF-8 as its bytes)
            led_map = parse_led_map(text, settings.led_map_section, shown_path(path))
            return settings.protocol_spec(led_map)
        except MissingSection:
            raise  # the rig config's led_map_section is at fault: its loader names that key
        except ValueError as exc:
            raise ConfigError(str(path), "dome.serial.led_map_file", str(exc)) from None
    return settings.protocol_spec()


def build_driver(
    settings: DomeSerialSettings, transport: Transport | None = None, *, name: str = "dome"
) -> LedDomeDriver | ScriptedDomeDriver:
    """The driver for ``settings`` on ``transport`` (default: the serial port it names).

    The link's ``can_dim`` is the settings' (:meth:`DomeSerialSettings.can_dim`): the one answer
    to "can this dome dim", which ``calibrate-lights`` and the config loader read too; the
    drivers refuse a "yes" their bytes cannot carry."""
    port = transport or SerialTransport(settings.port, settings.baudrate)
    if settings.is_described:
        # reply_timeout_s is a floor under the profile's own timeouts (a slow USB bridge, or an
        # emulator sharing the CPU); its default 0.5 s is below every profile's.
        return ScriptedDomeDriver(
            port,
            protocol_for(settings),
            device=name,
            min_reply_timeout_s=settings.reply_timeout_s,
            led_count_source=settings.led_count_source(),
            can_dim=settings.can_dim,
        )
    return LedDomeDriver(
        port,
        make_codec(settings),
        device=name,
        reply_timeout_s=settings.reply_timeout_s,
        ready_timeout_s=settings.ready_timeout_s,
        max_level=settings.max_level,
        can_dim=settings.can_dim,
        senses_led_current=settings.senses_led_current,
    )
