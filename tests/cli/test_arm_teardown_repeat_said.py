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
