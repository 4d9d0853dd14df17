"""The sentence on the lights after an early stop says only what is so.

Found by an audit: a replayed acquisition's emergency stop said "lights were switched off"
(a replay has no lights), and an arm's said "(see any teardown problem above)" with nothing
above it.
"""

from __future__ import annotations

from pathlib import Path
from types import SimpleNamespace

from rti_rig.app.compose import build_rig
from rti_rig.app.config import load_rig_config
from rti_rig.app.usecases.safe_state import lights_state, safe_state_unsure
from rti_rig.runtime.lighting import DomeLighting

REPO = Path(__file__).resolve().parents[2]


def test_a_replay_has_no_lights_to_switch_off() -> None:
    rig = build_rig(load_rig_config(REPO / "tests" / "data" / "neuralrti_replay" / "dirs.lp"))
    with rig:
        assert lights_state(rig) == "a replayed acquisition has no lights to switch off"


def test_an_arm_points_at_teardown_problems_only_when_there_are_some() -> None:
    rig = build_rig(load_rig_config(REPO / "rig_configs" / "virtual_arm.toml"))
    with rig:
        assert lights_state(rig) == "lamp off and stop were requested"
        assert lights_state(rig, teardown_failed=True).endswith("(see the teardown problems above)")


class _RecordlessDome:
    """A light source that keeps no record of what its all-off established (neither a dome
    on a port nor a simulated one)."""

    name = "recordless dome"

    def __init__(self) -> None:
        self.offs = 0

    def connect(self) -> None: ...

    def close(self) -> None: ...

    def light_count(self) -> int:
        return 8

    def light(self, index: int, intensity: float = 1.0) -> None: ...

    def all_off(self) -> None:
        self.offs += 1


def test_a_dome_that_keeps_no_record_of_its_all_off_is_not_said_to_have_had_none() -> None:
    """The teardown sends such a source its all-off: what it established is not known, and
    that is what is said (it had been "no all-off was attempted", after one was sent)."""
    real = build_rig(load_rig_config(REPO / "rig_configs" / "simulated_dome.toml"))
    with real:
        source = _RecordlessDome()
        rig = SimpleNamespace(
            loaded=real.loaded, lighting=DomeLighting(source, real.lighting.geometry)
        )
        assert rig.lighting.safe() == []
        assert source.offs == 1
        said = lights_state(rig)
        assert said == "whether the dome's lights are off is not known: check them", said
        assert safe_state_unsure(rig) is True


def test_an_arm_whose_lamp_off_and_stop_could_not_be_sent_is_not_said_to_have_had_them() -> None:
    """A dead port (an unplugged adapter) fails both teardown writes: "lamp off and stop were
    requested" had been said of requests that never left the computer."""
    rig = build_rig(load_rig_config(REPO / "rig_configs" / "virtual_arm.toml"))
    with rig:
        carrier = rig.lighting.carrier

        def gone(*_: object) -> None:
            raise OSError("write failed: [Errno 5] Input/output error")

        carrier.lamp, carrier.stop = gone, gone  # type: ignore[method-assign]
        failures = rig.lighting.safe()
        assert [f.split(":")[0] for f in failures] == ["lamp off", "stop"], failures
        said = lights_state(rig, teardown_failed=True)
        assert said.startswith(
            "the lamp-off and the stop failed (not sent, or sent and not acknowledged): the lamp "
            "may still be lit, "
            "and a servo no command reaches keeps its last goal under torque, so the arm may "
            "hold there or still be moving to it; switch the arm's power supply off"
        ), said
        assert "requested" not in said, said
        del carrier.lamp, carrier.stop  # the class's own again, for the rig's close
