"""Built-in dome protocols by name: each is one module holding a ``SPEC`` (a protocol description
as the rig config would write it) and one line in :data:`_MODULES`.

A new built-in profile = one new module here + its name in ``_MODULES``. Facts behind each
profile (firmware source, published host code) are cited in its module and in ``docs/domes.md``.
"""

from __future__ import annotations

import importlib
from typing import Any

#: profile name → module holding its SPEC (the registration).
_MODULES = {
    "nab-rti-v1": "nab_rti_v1",
    "rtipy": "rtipy",
    "minirti": "minirti",
    "elexol-24r1": "elexol",
    "rti-dome-m": "rti_dome",
    "nichlock": "nichlock",
}

#: The projects' own protocols (codecs in ``codec_*.py``), not descriptions.
CODEC_PROFILES = ("default", "framed", "binary")


def described_profiles() -> tuple[str, ...]:
    """Names of the built-in protocol descriptions."""
    return tuple(_MODULES)


def all_profiles() -> tuple[str, ...]:
    return (*CODEC_PROFILES, *_MODULES, "custom")


def builtin_spec(name: str) -> dict[str, Any]:
    """The protocol description of built-in profile ``name`` (a fresh dict, safe to merge into)."""
    if name not in _MODULES:
        raise KeyError(name)
    module = importlib.import_module(f"{__name__}.{_MODULES[name]}")
    return _deep_copy(module.SPEC)


def any_baudrate(name: str) -> bool:
    """True where built-in firmware ``name`` runs on a board whose own USB is its serial port
    (its module's ``ANY_BAUDRATE``): the host's baud rate is not used there."""
    if name not in _MODULES:
        return False
    module = importlib.import_module(f"{__name__}.{_MODULES[name]}")
    return bool(getattr(module, "ANY_BAUDRATE", False))


def bootloader_touch_baud(name: str) -> int | None:
    """The baud rate at which opening and closing the port resets built-in firmware ``name``'s
    board into its bootloader (its module's ``BOOTLOADER_TOUCH_BAUD``: the ATmega32u4's
    1200-baud touch), or None where no rate does."""
    if name not in _MODULES:
        return None
    module = importlib.import_module(f"{__name__}.{_MODULES[name]}")
    rate = getattr(module, "BOOTLOADER_TOUCH_BAUD", None)
    return None if rate is None else int(rate)


def max_led_count(name: str) -> int | None:
    """The most LEDs built-in firmware ``name`` can address (its module's ``MAX_LED_COUNT``), or
    None where no fixed maximum is known (an LED map decides, or ``custom``)."""
    if name not in _MODULES:
        return None
    module = importlib.import_module(f"{__name__}.{_MODULES[name]}")
    return getattr(module, "MAX_LED_COUNT", None)


def no_dimming(name: str) -> str:
    """Why built-in firmware ``name`` cannot dim an LED (its module's ``NO_DIMMING``).

    Declared by every module and read without a default, so a new firmware says what its light
    command can do: the profiles had been asked whether they dim through a codec chosen by
    elimination, which called every firmware here dimmable, and a light correction for an
    on/off sketch was accepted and then silently not applied. None of the described firmwares
    carries a brightness (their light commands switch an LED on), and a protocol description
    has no placeholder for one."""
    module = importlib.import_module(f"{__name__}.{_MODULES[name]}")
    return str(module.NO_DIMMING)


def merge(base: dict[str, Any], override: dict[str, Any]) -> dict[str, Any]:
    """``override`` laid over ``base`` table by table (the rig config's [dome.serial.protocol])."""
    out = _deep_copy(base)
    for key, value in override.items():
        if isinstance(value, dict) and isinstance(out.get(key), dict):
            out[key] = merge(out[key], value)
        else:
            out[key] = _deep_copy(value)
    return out


def _deep_copy(value: Any) -> Any:
    if isinstance(value, dict):
        return {k: _deep_copy(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_deep_copy(v) for v in value]
    return value
