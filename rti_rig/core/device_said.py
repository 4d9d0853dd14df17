"""How a device says what its user must know as it happens: through the listener the command
line set (``listen``), or, with none, as a warning record, never lost.

Why one function: the Dynamixel arm and the dome policy each had their own ``_tell``; the
dome's dropped a line said with no listener, where the arm's logged it, which the command line
says as a note (``rti_rig.cli.app.records_as_notes``) and a program's logging receives.
"""

from __future__ import annotations

import logging
from collections.abc import Callable


def say_or_log(text: str, say: Callable[[str], None] | None, log: logging.Logger) -> None:
    """Say ``text`` through ``say``, or as a warning record on ``log`` when none listens."""
    if say is not None:
        say(text)
    else:
        log.warning("%s", text)


def first_clause(text: str) -> str:
    """``text`` up to its first ``;`` at parenthesis depth 0 (all of it if there is none): an
    error's head, the fault itself, where its advice is said in full elsewhere. A ``;``
    inside parentheses (a quoted system error) is not an end."""
    depth = 0
    for i, ch in enumerate(text):
        if ch == "(":
            depth += 1
        elif ch == ")":
            depth = max(0, depth - 1)
        elif ch == ";" and depth == 0:
            return text[:i]
    return text
