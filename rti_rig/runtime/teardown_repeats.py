"""How a teardown step that failed exactly as an earlier one did is said.

Why a module of its own: ``run``'s teardown (:mod:`rti_rig.runtime.controller`) and the arm's
self-test (:mod:`rti_rig.runtime.arm_check`) both point back to the earlier failure instead of
printing a device's paragraph twice (the arm's close stops it again), and had said it as
"light close: failed as 'stop' above": a user could not tell what the close had tried, nor
what state the lights and the arm were in after it.
"""

from __future__ import annotations


def failed_as_before(label: str, first: str) -> str:
    """``label: …`` for a step whose error is word for word that of the earlier ``first``.

    Only what the repetition establishes is said: the step failed with ``first``'s error, so
    nothing better than what ``first``'s line says is known of the rig. What the step tried is
    not said: a close switches the lights off and stops the arm again, but the same error
    after a park does not show that the close parked."""
    return (
        f"{label}: failed with the same error as '{first}' above; nothing more was "
        f"established of the lights or the arm than the '{first}' line says"
    )
