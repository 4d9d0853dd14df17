"""A described firmware's ``hello`` is said to leave the board dark only when it sends the
all-off and waits for the board's answer to it (``DomeLink.hello_leaves_dark``).

Why: it is what lets a reconnection say "it answered" and "the dome is off again"
(``DomePolicy``). It had been derived from the ``all_off`` verb's reply, not from the init
command that ``hello`` sends: an init of the all-off's bytes described with no reply, beside an
acknowledged ``all_off``, had the board said dark after an exchange nobody answered."""

from __future__ import annotations

import pytest

from rti_rig.drivers.led_dome.factory import protocol_for
from rti_rig.drivers.led_dome.protocol_spec import ProtocolSpec
from rti_rig.drivers.led_dome.scripted import ScriptedDomeDriver
from rti_rig.drivers.led_dome.settings import DomeSerialSettings
from rti_rig.drivers.led_dome.transport import SerialTransport

ACK = {"kind": "pattern", "pattern": "off"}


def _link(spec: ProtocolSpec) -> ScriptedDomeDriver:
    return ScriptedDomeDriver(SerialTransport("loop://"), spec)


def _custom(init: list[dict[str, object]]) -> ProtocolSpec:
    return ProtocolSpec.model_validate(
        {
            "led_count": 8,
            "light": {"send": "L{index}\n"},
            "all_off": {"send": "X\n", "reply": ACK},
            "init": init,
        }
    )


@pytest.mark.parametrize(
    ("profile", "dark"),
    [("nab-rti-v1", True), ("rti-dome-m", False), ("minirti", False), ("elexol-24r1", False)],
)
def test_only_an_answered_init_all_off_leaves_a_shipped_firmware_dark(
    profile: str, dark: bool
) -> None:
    settings = DomeSerialSettings(port="loop://", profile=profile)
    assert _link(protocol_for(settings)).hello_leaves_dark is dark


def test_an_init_all_off_sent_with_no_reply_awaited_is_not_taken_as_answered() -> None:
    assert _link(_custom([{"send": "X\n"}])).hello_leaves_dark is False
    assert _link(_custom([{"send": "X\n", "reply": ACK}])).hello_leaves_dark is True
    assert _link(_custom([{"send": "Y\n", "reply": ACK}])).hello_leaves_dark is False
