"""Each ability a lighting adapter asks of its source answers from that source, on every
shipped config, as the composition root builds it.

Why: ``DomeLighting`` and ``ArmLighting`` (and the controller, of the lighting) had guessed at
their source's optional abilities with ``getattr`` (``hold``, ``lit_limit_s``, ``guard``,
``off_report``, ``stats``, ``listen``, ``ending``, ``link.port_open``; the carrier's
``resends``, ``torque_release_note``, ``check_held``), so that a renamed or misspelt attribute
silently answered "none": a dome never held open, no thermal limit, no resend reported, an
arm's sagging pose never checked. Each adapter method is called here on each concrete source,
and what it says is the source's: a rename fails here, and a source without an ability (a
simulated dome or arm) gets the documented default.
"""

from __future__ import annotations

import contextlib
from typing import Any

import pytest
from conftest import CONFIGS

from rti_rig.app.compose import build_rig
from rti_rig.app.config import load_rig_config
from rti_rig.core.devices import ReadBackCarrier
from rti_rig.core.schedule import LightStep
from rti_rig.planner.uniform import plan_uniform
from rti_rig.runtime.dome_policy import DomePolicy, DutyWait
from rti_rig.runtime.lighting import ArmLighting, DomeLighting
from rti_rig.runtime.rig import Rig

SHIPPED = sorted(p.name for p in CONFIGS.glob("*.toml"))

#: The source each shipped config puts under its lighting (every one of them is covered).
SOURCES = {
    "emulated_cceh_rti.toml": "CameraTriggeredLighting",
    "simulated_dome.toml": "SimulatedDome",
    "virtual_arm.toml": "SimulatedArm",
    "simulated_arm.toml": "DynamixelArm",
}


@pytest.fixture(autouse=True)
def _tether_folder(tmp_path: Any, monkeypatch: pytest.MonkeyPatch) -> None:
    """A home holding the watched folder the shipped folder-watch config names
    (``~/Pictures/rti-tether``): a rig whose folder is missing is refused as it is built."""
    (tmp_path / "Pictures" / "rti-tether").mkdir(parents=True)
    monkeypatch.setenv("HOME", str(tmp_path))


def _source_name(rig: Rig) -> str:
    lighting: Any = rig.lighting
    if isinstance(lighting, DomeLighting):
        return type(lighting.source).__name__
    if isinstance(lighting, ArmLighting):
        return type(lighting.carrier).__name__
    return type(lighting).__name__


def test_every_shipped_config_is_covered() -> None:
    assert SHIPPED, CONFIGS
    for name in SHIPPED:
        with build_rig(load_rig_config(CONFIGS / name)) as rig:
            assert _source_name(rig) == SOURCES.get(name, "DomePolicy"), name


def _lit_step(rig: Rig, led: int = 0) -> LightStep:
    d = rig.geometry.directions[led]  # type: ignore[union-attr]
    return LightStep((float(d[0]), float(d[1]), float(d[2])), led=led)


@pytest.mark.parametrize("name", SHIPPED)
def test_each_adapter_ability_answers_from_its_source(name: str) -> None:
    """A hardware config's dome is built and asked what needs no port; every other is
    connected, lit, held, made safe and closed."""
    loaded = load_rig_config(CONFIGS / name)
    with build_rig(loaded) as rig:
        kind = _source_name(rig)
        if kind == "DomePolicy":
            _dome_policy(rig, connect=loaded.config.backend != "hardware")
        elif kind == "SimulatedDome":
            _simulated_dome(rig)
        elif kind == "DynamixelArm":
            _read_back_arm(rig)
        elif kind == "SimulatedArm":
            _simulated_arm(rig)
        else:
            _camera_stepped(rig)


def _no_link_defaults(lighting: Any, step: LightStep, at: float, link_open: bool = False) -> None:
    """What a lighting with no port to lose, record or guard answers (on purpose); its link
    is open only where ``link_open`` (a connected simulated dome, which gets the all-off a
    session's close sends as a real dome does)."""
    assert lighting.lit_limit_s() is None
    assert lighting.off_said() is None and lighting.cool_down_s(step, at) == 0.0
    assert lighting.resends() == ({}, None) and lighting.reconnections() == []
    assert lighting.link_open is link_open


def _camera_stepped(rig: Rig) -> None:
    lighting = rig.lighting
    lighting.listen(lambda text: pytest.fail(text))
    lighting.connect()
    step = _lit_step(rig)
    lighting.set(step)
    lighting.check_held()
    lighting.off()
    _no_link_defaults(lighting, step, rig.clock.now())
    lighting.hold()
    assert lighting.safe() == []
    lighting.close()


def _dome_policy(rig: Rig, connect: bool) -> None:
    lighting = rig.lighting
    assert isinstance(lighting, DomeLighting)
    policy = lighting.source
    assert isinstance(policy, DomePolicy) and lighting.policy is policy
    max_on_s = policy.settings.thermal.max_on_s
    limit = lighting.lit_limit_s()
    assert limit is not None and 0 < limit <= max_on_s
    said = lighting.lit_limit_said()
    assert said == (f"max_on_s = {max_on_s:g} s" if limit == max_on_s else said)
    assert "light_on_s" in said or "max_on_s" in said, said
    wait = lighting.duty_wait()
    assert isinstance(wait, DutyWait) and wait.limits.max_on_s == max_on_s
    assert lighting.off_said() is None  # no all-off sent yet: nothing established
    assert lighting.link_open is False
    assert lighting.resends() == ({}, None) and lighting.reconnections() == []
    if not connect:
        return
    heard: list[str] = []
    lighting.listen(heard.append)
    lighting.connect()
    try:
        assert lighting.link_open is True
        step = _lit_step(rig)
        lighting.set(step)
        rig.clock.sleep(0.01)
        lighting.off()
        report = policy.off_report
        assert report is not None and lighting.off_said() == str(report.outcome)
        # an LED never lit needs no cooling; the one just lit may (its guard says how long)
        assert lighting.cool_down_s(_lit_step(rig, 1), rig.clock.now()) == 0.0
        guard_s = policy.guard.earliest_start(0, rig.clock.now()) - rig.clock.now()
        assert lighting.cool_down_s(step, rig.clock.now()) == pytest.approx(max(0.0, guard_s))
        lighting.hold()  # all off, the port kept open for the next connect
        assert lighting.link_open is True
        lighting.connect()  # reuses the held port
        assert lighting.link_open is True
        assert lighting.resends() == ({}, None) and lighting.reconnections() == []
        assert lighting.safe() == []
    finally:
        lighting.close()
    assert lighting.link_open is False
    assert heard == []  # nothing was lost, so no reopening said


def _simulated_dome(rig: Rig) -> None:
    lighting = rig.lighting
    assert isinstance(lighting, DomeLighting) and lighting.policy is None
    # the documented defaults of a source with no port, guard or retries
    assert lighting.lit_limit_s() is None and lighting.duty_wait() is None
    lighting.listen(lambda text: pytest.fail(text))
    lighting.connect()
    step = _lit_step(rig)
    lighting.set(step)
    lighting.check_held()  # an LED does not move
    lighting.off()
    _no_link_defaults(lighting, step, rig.clock.now(), link_open=True)
    lighting.hold()  # no port to keep open: closed
    assert lighting.link_open is False
    lighting.connect()  # and opened again
    assert lighting.safe() == []
    lighting.close()


def _reachable_step(rig: Rig) -> LightStep:
    for step in plan_uniform(rig.geometry, 8).steps:  # type: ignore[arg-type]
        if rig.lighting.problem(step) is None:
            return step
    raise AssertionError("no reachable step")


def _read_back_arm(rig: Rig) -> None:
    lighting = rig.lighting
    assert isinstance(lighting, ArmLighting)
    assert lighting.read_back is lighting.carrier
    lighting.connect()
    step = _reachable_step(rig)
    lighting.set(step)
    lighting.check_held()  # holds: nothing raised, no failure remembered
    assert lighting.arm_failure is None
    _no_link_defaults(lighting, step, rig.clock.now())  # its resends counted: none yet
    # a servo that overloads during the exposure: the check reads it back and raises
    rig.emulator.inject_hardware_error(1, 0x20)  # type: ignore[attr-defined]
    with pytest.raises(Exception, match=r"(?i)overload"):
        lighting.check_held()
    assert lighting.arm_failure is not None
    lighting.safe()
    # so no park: a faulty arm is not driven near the object
    assert lighting.end is not None and lighting.end.outcome == "park-unconfirmed"
    with contextlib.suppress(Exception):  # its close's stop of the limp servo fails: said above
        lighting.close()


def _simulated_arm(rig: Rig) -> None:
    lighting = rig.lighting
    assert isinstance(lighting, ArmLighting) and lighting.read_back is None
    assert lighting.lit_limit_s() is None
    lighting.listen(lambda text: pytest.fail(text))
    lighting.connect()
    step = _reachable_step(rig)
    lighting.set(step)
    lighting.check_held()  # a carrier that cannot tell: nothing to check
    assert lighting.arm_failure is None
    _no_link_defaults(lighting, step, rig.clock.now())
    lighting.hold()  # an arm keeps no link open: its close (lamp off, stop)
    lighting.connect()
    assert lighting.safe() == []
    lighting.close()
    assert lighting.end is not None and lighting.end.outcome == "parked"
    assert lighting.end.torque is None  # no release note from a carrier without one


def test_a_carrier_that_declares_read_back_and_lacks_an_ability_cannot_be_built() -> None:
    """The declared protocol's methods are abstract: a rename in the concrete class fails at
    construction, never as a silent "none" in the adapter."""

    class Misspelt(ReadBackCarrier):
        def resends(self) -> tuple[list[str], str | None]:
            return [], None

        def torque_release_note(self) -> str | None:
            return None

        def check_hold(self) -> None:  # a misspelt check_held
            pass

    with pytest.raises(TypeError, match="check_held"):
        Misspelt()  # type: ignore[abstract]
