"""A ready-to-connect dome: the driver for its serial settings under the runtime's policy.

This is composition (it joins a driver to the runtime's :class:`DomePolicy`), so it lives beside
the composition root rather than in ``rti_rig.drivers``, which is built on the core only.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from rti_rig.core.clock import Clock
from rti_rig.drivers.led_dome.factory import build_driver
from rti_rig.drivers.led_dome.settings import DomeSerialSettings
from rti_rig.drivers.led_dome.transport import Transport
from rti_rig.runtime.dome_policy import DomePolicy, DomePolicySettings, ThermalLimits
from rti_rig.runtime.duty_ledger import DutyLedger


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
        link_hint=baudrate_hint(settings),
    )


def baudrate_hint(settings: DomeSerialSettings) -> str:
    """What to say of the port's baud rate when a built-in firmware's board answered nothing.

    A ``[dome.serial] baudrate`` overrides the profile's own, and one left from the example
    config (115200) on a 9600-baud sketch gave only "check the port, the baud rate and the
    protocol profile", naming neither the key nor the rate the firmware talks at.
    """
    from rti_rig.drivers.led_dome.dome_profiles import (
        any_baudrate,
        builtin_spec,
        described_profiles,
    )

    name = settings.profile
    if name not in described_profiles() or any_baudrate(name):
        return ""
    own = int(builtin_spec(name)["baudrate"])
    if settings.baudrate == own:
        return ""
    key = "dome.serial.baudrate"
    if settings.protocol is not None and "baudrate" in settings.protocol:
        key = "dome.serial.protocol.baudrate"
    return (
        f"the port opened at {key} = {settings.baudrate}, but the {name} firmware as "
        f"published talks at {own} baud: unless it was changed, remove that key or set it to "
        f"{own}"
    )


def build_dome(
    settings: DomeSerialSettings,
    clock: Clock,
    *,
    transport: Transport | None = None,
    directions: NDArray[np.float64] | None = None,
    name: str = "dome",
    ledger: DutyLedger | None = None,
) -> DomePolicy:
    """A ready-to-connect dome light source (a ``DiscreteLightSource``); nothing is opened yet.

    ``ledger``: the duty ledger its thermal guard shares with earlier and later commands on
    the same physical dome (:mod:`rti_rig.runtime.duty_ledger`); None counts this process's
    lightings alone (a test's own dome)."""
    return DomePolicy(
        build_driver(settings, transport, name=name),
        clock,
        policy_settings(settings),
        directions=directions,
        name=name,
        ledger=ledger,
    )
