"""The run control a signal handler drives: a resume or a stop acts wherever it lands in a pause.

Python runs a signal handler in the main thread between two of its bytecodes, wherever that
thread is, including inside :meth:`CancelToken.wait_while_paused`. A token built on
``threading.Event`` deadlocked when the handler landed while the wait held the Event's lock
(the handler's ``set`` waited for that lock for ever); a SIGTERM sent with the SIGUSR1 that
resumed was then never acted on, and the paused run ended only on two Ctrl-C.
"""

from __future__ import annotations

import subprocess
import sys
import textwrap

from conftest import REPO

from rti_rig.runtime.controller import CancelToken

#: A child process calls the token's ``resume``/``cancel`` at every bytecode boundary of the
#: wait in turn (from a trace function, which runs where a signal handler may run: in the main
#: thread, between two bytecodes); a deadlock ends it through faulthandler with the stack.
_CHILD = textwrap.dedent(
    """
    import faulthandler, sys
    from rti_rig.runtime.controller import CancelToken

    faulthandler.dump_traceback_later(60, exit=True)  # ~2 s when it works, even under load
    BOUNDARIES = 300  # several polls of the wait, whatever it is made of
    for action in ("resume", "cancel"):
        for k in range(1, BOUNDARIES + 1):
            token = CancelToken()
            token.pause()
            seen = 0

            def trace(frame, event, arg):
                global seen
                frame.f_trace_opcodes = True
                seen += 1
                if seen == k:
                    getattr(token, action)()  # as the SIGUSR1 / Ctrl-C handler does
                return trace

            sys.settrace(trace)
            try:
                token.wait_while_paused(0.0)
            finally:
                sys.settrace(None)
            assert not token.paused, (action, k)
    print("ok")
    """
)


def test_resume_or_cancel_from_a_handler_ends_the_pause_wherever_it_lands() -> None:
    proc = subprocess.run(
        [sys.executable, "-c", _CHILD],
        cwd=REPO,
        capture_output=True,
        text=True,
        timeout=180,
    )
    assert proc.returncode == 0 and proc.stdout.strip() == "ok", proc.stderr[-3000:]


def test_pause_holds_until_resume_or_cancel() -> None:
    token = CancelToken()
    assert not token.paused and not token.cancelled
    token.pause()
    assert token.paused
    token.resume()
    assert not token.paused
    token.wait_while_paused(0.0)  # not paused: returns at once
    token.pause()
    token.cancel()  # a cancel ends a pause too
    assert token.cancelled and not token.paused
    token.wait_while_paused(0.0)
