"""Every dome link the composition root builds from a shipped config provides every member of
:class:`~rti_rig.core.dome_link.DomeLink`, the stop hooks included.

Why: the policy had read the stop hooks (``port_open``, ``open_cut_short``, ``reopen_port``,
``finish_boot``, ``off_outcome``...) with ``getattr`` and a default, so a link type lacking one
silently got "nothing to do" (no reopening of a port a stop cut short, no all-off after the
stop). They are declared on the protocol now and read as attributes; this holds each driver to
them, so removing one from a driver fails here, not on a lit dome after a Ctrl-C."""

from __future__ import annotations

import inspect
from pathlib import Path

import pytest

from rti_rig.app.config import load_rig_config
from rti_rig.app.dome_factory import build_dome
from rti_rig.core.clock import VirtualClock
from rti_rig.core.dome_link import DomeLink
from rti_rig.drivers.led_dome.driver import LedDomeDriver
from rti_rig.drivers.led_dome.scripted import ScriptedDomeDriver

CONFIGS = Path(__file__).resolve().parents[3] / "rig_configs"
#: the shipped configs with a serial dome (a driver behind the policy)
SERIAL_DOMES = sorted(
    p for p in CONFIGS.glob("*.toml") if "[dome.serial]" in p.read_text(encoding="utf-8")
)


def declared_members() -> set[str]:
    """What :class:`DomeLink` declares: its annotated attributes, properties and methods."""
    names = set(DomeLink.__annotations__)
    for name, value in vars(DomeLink).items():
        if name.startswith("_"):
            continue
        if isinstance(value, property) or inspect.isfunction(value):
            names.add(name)
    return names


def test_the_stop_hooks_are_declared_on_the_protocol() -> None:
    """The list this test holds drivers to is the protocol's, and holds the stop hooks."""
    members = declared_members()
    hooks = {"port_open", "open_cut_short", "reopen_port", "finish_boot", "off_outcome"}
    assert hooks <= members, hooks - members
    assert {"connect", "all_off", "light", "device"} <= members
    # what a self-test step may be said to have established, and the clock the link waits on,
    # had been read with getattr defaults ("passed"; the rig's own clock)
    assert {"light_confirmed", "clock"} <= members


def test_both_driver_kinds_are_among_the_shipped_configs() -> None:
    """Else the test below would hold only one of them to the protocol."""
    kinds = {type(_link_of(path)) for path in SERIAL_DOMES}
    assert kinds == {LedDomeDriver, ScriptedDomeDriver}


@pytest.mark.parametrize("config", SERIAL_DOMES, ids=lambda p: p.name)
def test_every_shipped_dome_link_provides_every_declared_member(config: Path) -> None:
    link = _link_of(config)
    missing = sorted(name for name in declared_members() if not hasattr(link, name))
    assert not missing, f"{type(link).__name__} ({config.name}) lacks {missing}"
    assert isinstance(link, DomeLink)
    for name in ("reopen_port", "finish_boot", "connect", "all_off", "close"):
        assert callable(getattr(link, name)), name
    assert link.clock is link.transport.clock  # type: ignore[attr-defined]
    assert isinstance(link.light_confirmed, bool)  # type: ignore[attr-defined]


def _link_of(config: Path) -> object:
    """The link behind the dome the composition root builds from ``config`` (nothing opened)."""
    settings = load_rig_config(config).config.dome.serial
    return build_dome(settings, VirtualClock()).link


def test_every_transport_declares_whether_its_opening_resets_the_board() -> None:
    """``reopen_port`` reads ``resets_on_open`` as an attribute: a transport lacking it had
    been taken, by a ``getattr`` default, for one whose opening resets the board."""
    from rti_rig.drivers.led_dome.transport import SerialTransport, Transport
    from rti_rig.simulator.dome_firmware import InProcessDomeTransport

    assert isinstance(vars(Transport).get("resets_on_open"), property)
    assert SerialTransport("/dev/ttyACM0").resets_on_open is True
    assert SerialTransport("socket://localhost:1").resets_on_open is False
    assert InProcessDomeTransport.resets_on_open is True  # its firmware reboots at each opening


@pytest.mark.parametrize("hook", ["close", "_boot_wait_s", "_wait_out_boot", "_refused"])
def test_a_driver_lacking_a_port_opening_hook_cannot_be_built(hook: str) -> None:
    """The mixin's hooks are abstract: a driver without one fails when built, not when a stop
    calls it (a ``NotImplementedError`` had surfaced only in the all-off path)."""
    from rti_rig.drivers.led_dome.port_opening import PortOpening

    hooks = {
        "close": lambda self: None,
        "_boot_wait_s": lambda self: 0.0,
        "_wait_out_boot": lambda self: None,
        "_refused": lambda self, exc: None,
    }
    del hooks[hook]
    Partial = type("Partial", (PortOpening,), hooks)
    with pytest.raises(TypeError, match=hook):
        Partial()
    Whole = type("Whole", (PortOpening,), {**hooks, hook: lambda self, *a: None})
    Whole()._init_opening()
