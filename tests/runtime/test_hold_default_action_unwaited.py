"""A stop held over a port's opening where SIGTERM's action is the default (or the CLI's
:func:`~rti_rig.core.deferred_signals.default_after_hooks`, which stands for it) is acted on
as the hold ends with no wait for the CLI's words, a hang-up's too: that is a command whose
dome may be lit from its boot, its all-off not yet sent.

Before, the hold raised a held hang-up's SIGHUP again, and ``hangup_as_sigterm``'s handler
took it to ``default_action``, which waits up to 2 s for the words (the comment said there
was no wait). In a child process (the signal ends it); a ``before_default_action`` hook ends
the child with exit 7 if it is ever called, so the test needs no timing.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys

import pytest
from conftest import REPO

_CHILD = r"""
import os, signal, sys
from rti_rig.core import deferred_signals as ds

ds.before_default_action.append(lambda: os._exit(7))  # a wait for the words would begin here
if sys.argv[1] == "cli":
    signal.signal(signal.SIGTERM, ds.default_after_hooks)
with ds.hangup_as_sigterm():
    with ds.signals_deferred(second_stops=True):  # a port's opening
        signal.raise_signal(getattr(signal, sys.argv[2]))
print("the held stop did not end the process")
"""


@pytest.mark.skipif(sys.platform != "linux", reason="signals tested on Linux")
@pytest.mark.parametrize("sigterm", ["default", "cli"])
@pytest.mark.parametrize("stop", ["SIGHUP", "SIGTERM"])
def test_a_stop_held_by_an_opening_takes_the_default_action_unwaited(
    sigterm: str, stop: str
) -> None:
    result = subprocess.run(
        [sys.executable, "-c", _CHILD, sigterm, stop],
        capture_output=True,
        env={**os.environ, "PYTHONPATH": str(REPO)},
        timeout=600,
    )
    assert result.returncode == -getattr(signal, stop), (result.returncode, result.stdout)
