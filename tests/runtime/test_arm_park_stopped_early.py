"""A stop (Ctrl-C, SIGTERM) that comes as the teardown switches the lamp off or stops the arm,
before its park: no park is begun, the arm is left where the stop held it, and the signal is
still acted on once the teardown is done (its caller holds it, as the controller does).

The CLI test (tests/cli/test_run_arm_park_stopped.py) sends its signal once the park moves;
this one, at a known call, covers the moment before the park is sent.
"""

from __future__ import annotations

import signal
from typing import Any

import numpy as np
import pytest

from rti_rig.core.deferred_signals import signals_deferred
from rti_rig.core.geometry import direction_from_az_el
from rti_rig.runtime.lighting import ArmLighting


class _Carrier:
    """An arm that records its teardown and is sent ``sig`` as it is stopped."""

    name = "arm"

    def __init__(self, sig: int) -> None:
        self.sig = sig
        self.log: list[str] = []

    def lamp(self, on: bool) -> None:
        self.log.append(f"lamp {on}")

    def stop(self) -> None:
        self.log.append("stop")
        signal.raise_signal(self.sig)

    def park(self, cancelled: Any = None) -> None:
        self.log.append("park")

    def reached_direction(self) -> np.ndarray:
        return direction_from_az_el(30.0, 50.0)


@pytest.mark.parametrize(("sig", "who"), [(signal.SIGINT, "Ctrl-C"), (signal.SIGTERM, "SIGTERM")])
def test_a_stop_during_the_teardown_s_stop_begins_no_park(sig: int, who: str) -> None:
    carrier = _Carrier(sig)
    lighting = ArmLighting(carrier, config="arm.toml")  # type: ignore[arg-type]
    seen: list[int] = []

    def handler(signum: int, frame: Any) -> None:
        seen.append(signum)

    previous = signal.signal(sig, handler)
    try:
        with signals_deferred():  # the controller's hold around its teardown
            failures = lighting.safe()
            assert seen == []  # held until the teardown is done
    finally:
        signal.signal(sig, previous)
    assert seen == [sig]  # then acted on, as ever
    assert failures == [] and "park" not in carrier.log
    assert lighting.stopped_by == sig
    end = lighting.end
    assert end is not None and end.outcome == "left"
    assert end.why == f"the park was stopped by {who}: held where it stopped, torque on"
    assert end.azimuth_deg == pytest.approx(30.0) and end.elevation_deg == pytest.approx(50.0)
