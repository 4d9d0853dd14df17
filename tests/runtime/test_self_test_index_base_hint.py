"""The dome check's report names index_base where the one LED refused as out of the board's
range is the first or the last of the walk.

Before: a board numbered from 0 under a config's ``index_base = 1`` "passed" 47 LEDs (each
one its neighbour) and failed LED 47 alone, "LED index out of range", read as a dead LED."""

from __future__ import annotations

import pytest

from rti_rig.runtime.dome_policy import LedCheck, SelfTestReport

OUT = "refused: firmware error 3: LED index out of range; gave up after 3 attempts"


@pytest.mark.parametrize(("bad", "hinted"), [(47, True), (0, True), (20, False)])
def test_an_end_led_out_of_range_names_index_base(bad: int, hinted: bool) -> None:
    checks = [LedCheck(i, i != bad, OUT if i == bad else "") for i in range(48)]
    lines = SelfTestReport("dome", None, 48, checks).lines()
    said = " ".join(lines)
    assert ("index_base" in said) is hinted, said
    if hinted:
        assert f"only LED {bad}, at the end of the range, was out of the board's range" in said


def test_two_leds_refused_or_another_fault_get_no_hint() -> None:
    checks = [LedCheck(i, i < 46, OUT if i >= 46 else "") for i in range(48)]
    assert "index_base" not in " ".join(SelfTestReport("dome", None, 48, checks).lines())
    checks = [LedCheck(i, i != 47, "no reply within 0.5 s" if i == 47 else "") for i in range(48)]
    assert "index_base" not in " ".join(SelfTestReport("dome", None, 48, checks).lines())
