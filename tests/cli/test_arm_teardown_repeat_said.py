"""A teardown step of ``run`` that failed as an earlier one did says that it failed with the
same error and what is known after it, not a bare pointer.

The arm's close stops it again, so an arm fault failed the stop and then the close with the
same error; the close was said as "light close: failed as 'stop' above", which told a user
neither what had failed nor in what state the lights and the arm were left.
"""

from __future__ import annotations

from pathlib import Path

from conftest import run_faulted_arm


def test_the_close_failing_as_the_stop_did_is_said_plainly(tmp_path: Path) -> None:
    said = run_faulted_arm(tmp_path, "overload")
    assert "teardown problem: stop: " in said, said
    assert (
        "teardown problem: light close: failed with the same error as 'stop' above; nothing "
        "more was established of the lights or the arm than the 'stop' line says"
    ) in said, said
    assert "failed as 'stop' above" not in said, said
    # the lights line says what the overload left of servo 1's torque, as read (off): it had
    # said "a servo no command reaches keeps its last goal under torque" of a limp joint
    # (tests/app/test_unheld_joint_said.py); asserted here, on the same run, to spare CI one
    lights = said.split("the stop failed at a servo", 1)[1].split("; the arm's park", 1)[0]
    assert (
        "the azimuth servo (id 1) shut itself off after its fault (torque read off): that "
        "joint is limp, so the arm turns freely about the vertical if pushed; switch the arm's "
        "power supply off"
    ) in lights, said
    assert "may sag" not in lights, said  # the azimuth turns about the vertical: no sag
    assert "keeps its last goal under torque" not in said, said
