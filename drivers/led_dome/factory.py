"""Composition: rig-config settings → codec + transport + driver + rig policy.

The CLI and the rig config loader call :func:`build_dome`; tests and the dry run pass their own
transport (the emulator in-process or on a pty) and the same settings.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from drivers.led_dome.driver import LedDomeDriver
from drivers.led_dome.profiles import make_codec
from drivers.led_dome.settings import DomeSerialSettings
from drivers.led_dome.transport import SerialTransport, Transport
from rti_rig.clock import Clock
from rti_rig.dome_policy import DomePolicy, DomePolicySettings, ThermalLimits


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


def policy_settings(settings: DomeSerialSettings) -> DomePolicySettings:
    """The policy part of the serial settings."""
    t = settings.thermal
    corr = settings.intensity_correction
    return DomePolicySettings(
        retries=settings.retries,
        retry_backoff_s=settings.retry_backoff_s,
        reconnect_attempts=settings.reconnect_attempts,
        reconnect_backoff_s=settings.reconnect_backoff_s,
        thermal=ThermalLimits(t.max_on_s, t.max_duty, t.duty_window_s),
        intensity_correction=None if corr is None else tuple(corr),
        confirm_with_query=settings.confirm_with_query,
        expected_led_count=settings.expected_led_count,
        shutter_pulse_ms=settings.shutter_pulse_ms,
    )


def build_dome(
    settings: DomeSerialSettings,
    clock: Clock,
    *,
    transport: Transport | None = None,
    directions: NDArray[np.float64] | None = None,
    name: str = "dome",
) -> DomePolicy:
    """A ready-to-connect dome light source (a ``DiscreteLightSource``); nothing is opened yet."""
    return DomePolicy(
        build_driver(settings, transport, name=name),
        clock,
        policy_settings(settings),
        directions=directions,
        name=name,
    )
