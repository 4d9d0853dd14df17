"""What the lights line says of a joint a failed stop did not hold depends on what was read
of its servo: torque off after a fault (limp), on (held goal), not read (both said), or no
fault read at all (a servo no command reaches). Through a rig's own teardown
(``ArmLighting.safe``) and the sentence it is said by; the overload through ``run`` is
tests/cli/test_arm_teardown_repeat_said.py.
"""

from __future__ import annotations

import pytest
from conftest import CONFIGS

from rti_rig.app.compose import build_rig
from rti_rig.app.config import load_rig_config
from rti_rig.app.usecases.safe_state import lights_state, not_sent_sentence
from rti_rig.core.errors import StopIncomplete, UnheldJoint

HELD = "last goal under torque"
SAG = "so the arm may sag"


@pytest.mark.parametrize(
    ("torque_on", "said", "not_said"),
    [
        (False, ["shut itself off after its fault (torque read off)", SAG], [HELD]),
        (True, ["kept its torque after its fault (read on)", "it keeps its last goal"], [SAG]),
        (None, ["its torque could not be read", SAG, HELD], []),
    ],
)
def test_a_faulted_servo_is_said_as_its_torque_was_read(
    torque_on: bool | None, said: list[str], not_said: list[str]
) -> None:
    rig = build_rig(load_rig_config(CONFIGS / "virtual_arm.toml"))
    with rig:
        carrier = rig.lighting.carrier

        def stop() -> None:
            exc = StopIncomplete("arm", "stop incomplete: servo 2 held where it is", "stop")
            exc.unheld = (UnheldJoint("elevation", 2, True, torque_on),)
            raise exc

        carrier.stop = stop  # type: ignore[method-assign]
        failures = rig.lighting.safe()
        assert [f.split(":")[0] for f in failures] == ["stop"], failures
        text = lights_state(rig, teardown_failed=True)
        del carrier.stop
    assert text.startswith("lamp off was requested, but the stop failed at a servo"), text
    assert "the elevation servo (id 2)" in text, text
    for words in said:
        assert words in text, text
    for words in not_said:
        assert words not in text, text
    power = "support the arm and switch its power supply off"
    assert (power in text) is (torque_on is not True), text


def test_a_servo_that_did_not_answer_is_said_as_before() -> None:
    said = not_sent_sentence(("stop",), unheld=(UnheldJoint("azimuth", 1, False, None),))
    assert HELD in said and SAG not in said and "id 1" not in said, said
    assert said.endswith("switch the arm's power supply off"), said


@pytest.mark.parametrize("torque_on", [False, None])
def test_a_limp_azimuth_is_said_to_let_the_arm_turn_not_sag(torque_on: bool | None) -> None:
    """The azimuth turns about the vertical: limp, it lets the arm swing round if pushed. "so
    the arm may sag; support the arm" had been said of it (QA, 2026-12-05)."""
    said = not_sent_sentence(("stop",), unheld=(UnheldJoint("azimuth", 1, True, torque_on),))
    assert "the azimuth servo (id 1)" in said, said
    assert "so the arm turns freely about the vertical if pushed" in said, said
    assert SAG not in said and "support the arm" not in said, said
    # with the elevation limp too, the arm hangs on it: supported
    both = not_sent_sentence(
        ("stop",),
        unheld=(UnheldJoint("azimuth", 1, True, False), UnheldJoint("elevation", 2, True, False)),
    )
    assert SAG in both and "support the arm and switch its power supply off" in both, both
