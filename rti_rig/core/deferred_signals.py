"""SIGINT and SIGTERM held while a short block that must not be cut runs, then acted on.

Why a module of its own: the controller holds them while devices go safe and while an image is
committed, metering while its lights go off, and a resume while it sets unverified images aside
and relists ``lights.lp`` (a stop in between had left the `.lp` listing a moved image). In the
core, not the runtime, because the drivers hold them too, over a serial port's opening (a stop
landing just after the system's open, before pyserial keeps the descriptor, leaked it), and the
drivers may stand on the core alone.

It also holds :func:`signal_handlers`, the one way the CLI sets handlers for a block: the
save, install, restore and main-thread check had been written out by hand seven times, and
two of the copies lacked the check (a handler set off the main thread raises ValueError).
"""

from __future__ import annotations

import contextlib
import signal
import threading
from collections.abc import Callable, Iterator, Mapping
from typing import Any


def stop_words(signum: signal.Signals) -> str:
    """How a stop by ``signum`` is named to the user: ``Ctrl-C`` for SIGINT, else the
    signal's name (``SIGTERM``; ``SIGHUP`` for a SIGTERM that was a hang-up, see
    :func:`as_received`)."""
    return "Ctrl-C" if signum == signal.SIGINT else as_received(signum).name


#: A hang-up (SIGHUP) is being answered as a SIGTERM right now: the SIGTERM handler that
#: :func:`hangup_as_sigterm` called for it (or a hold delivering one it held) is running, and
#: the stop it makes is named, recorded and exited as SIGHUP (:func:`as_received`).
#:
#: Set only for that delivery, not for the rest of the block: it had stayed set from the
#: hang-up to the block's end, so a real SIGTERM after it (a supervisor's ``kill`` once the
#: terminal had closed) was named, recorded and exited as SIGHUP too, and one before it was
#: renamed SIGHUP by a hang-up that came during its teardown. Whatever keeps a stop's signal
#: for later (an exception, a list of held signals) keeps :func:`as_received`'s answer.
_hung_up = False


def as_received(signum: int) -> signal.Signals:
    """The signal a stop really came as: SIGHUP for a SIGTERM while a hang-up answered as one
    is being delivered (:func:`hangup_as_sigterm`), else ``signum`` itself. What names a stop
    (the words, the manifest's record, the exit code 128 + its number) goes through it, and
    a handler that keeps the signal for later keeps this, not its ``signum``."""
    sig = signal.Signals(signum)
    if _hung_up and sig == signal.SIGTERM:
        return signal.SIGHUP
    return sig


def _deliver(handler: Callable[[int, Any], Any], received: int, frame: Any) -> None:
    """Call SIGTERM's ``handler`` for a stop that came as ``received`` (SIGTERM, or a hang-up
    answered as one): for a hang-up, :func:`as_received` names it SIGHUP for that call only."""
    global _hung_up
    before, _hung_up = _hung_up, received == getattr(signal, "SIGHUP", None)
    try:
        handler(signal.SIGTERM if _hung_up else received, frame)
    finally:
        _hung_up = before


@contextlib.contextmanager
def hangup_as_sigterm() -> Iterator[None]:
    """For the block (a whole ``run`` or ``check``), a SIGHUP is answered by whatever answers a
    SIGTERM at that moment: the stop and teardown (all-off, arm stopped), a hold, a late
    record; it is named, recorded and exited as itself (SIGHUP, exit 129: :func:`as_received`).

    Why: SIGHUP (the terminal or the ssh connection closing) had no handler: the process died
    at once with exit 129, no teardown (a dome's LED left lit, an arm holding) and no end in
    the manifest. One mechanism, SIGTERM's, rather than a second copy of every SIGTERM handler
    (the opening's, the capture's, the holds', the verdict's). Where SIGTERM's action is the
    default, SIGHUP's is too (the process ends by SIGHUP). The flag is cleared as the block
    begins; it is set only while the hang-up's SIGTERM handler runs (what it names then is
    kept: an exception's signal, a held signal), so a real SIGTERM before or after the hang-up
    is named SIGTERM. No SIGHUP
    (Windows), or SIGHUP ignored as the block begins (``nohup``): nothing is installed."""
    global _hung_up
    _hung_up = False
    sighup = getattr(signal, "SIGHUP", None)
    if sighup is None or signal.getsignal(sighup) == signal.SIG_IGN:
        yield  # ignored as the command began (``nohup``): the session is meant to outlive
        return  # its terminal, and goes on to its end

    def hung_up(signum: int, frame: Any) -> None:
        handler = signal.getsignal(signal.SIGTERM)
        if callable(handler):
            _deliver(handler, sighup, frame)
        elif handler != signal.SIG_IGN:  # the default (or a handler set outside Python)
            # within run/check/preview, nothing opened yet: the words are waited on (a
            # hang-up a port's opening held is acted on by the hold, without the wait)
            default_action(sighup)

    with signal_handlers({sighup: hung_up}):
        yield


#: How many :func:`after_a_stop` blocks are open (in the main thread, where handlers run).
_after_a_stop = 0


@contextlib.contextmanager
def after_a_stop() -> Iterator[None]:
    """Within this block, the holds a further stop may end (``signals_deferred(second_stops=
    True)``, a serial port's opening) hold nothing: a stop was already acted on, and the one
    that comes now is the user's second.

    Why: after a stop cut a port's opening short, the teardown reopens the port to send the
    all-off; a stop during that reopening is the user insisting, but the opening's own hold
    counted it as the first of *its* block and held it until the open returned: the port was
    opened again (a board that resets on open reset once more) and an open that hung could not
    be ended."""
    global _after_a_stop
    _after_a_stop += 1
    try:
        yield
    finally:
        _after_a_stop -= 1


def within_after_a_stop() -> bool:
    """Whether an :func:`after_a_stop` block is open: a stop's teardown reopening a port, where
    a further stop is the user insisting that a hung opening be ended (the CLI raises it there
    rather than only saying it)."""
    return _after_a_stop > 0


@contextlib.contextmanager
def signals_deferred(
    on_held: Callable[[int], None] | None = None, *, second_stops: bool = False
) -> Iterator[None]:
    """Hold SIGINT/SIGTERM while devices are put in their safe state, or while a captured
    image is committed (its files and journal line).

    ``on_held`` (called with the signal's number, as received: SIGHUP for a hang-up answered
    as a SIGTERM; in the main thread, as each is held) lets
    the block cut short a long wait of its own that a stop must not sit through (the arm's
    final park, which lasts up to ``move_timeout_s``): it should only record the request (set
    a flag), never raise; the signal is still delivered once the block is done.

    An emergency-stop handler raising in the middle of teardown could leave a light on, and in
    the middle of a commit an image that ``lights.lp`` does not list; the signals are delivered
    (and acted on) as soon as the block is done. Held at the level of Python's handlers, not
    the thread's signal mask: a signal sent to the process is delivered to any thread that does
    not block it (BLAS, the progress bar, an emulator's), and Python then runs the handler in
    the main thread all the same — a mask in the main thread alone had held nothing.

    ``second_stops``: a second signal while one is held ends the hold at once, both delivered
    in their order where the block is (the drivers' hold over a serial port's opening). Why:
    the block is meant to be short, but an opening can hang (a wedged USB adapter, a tty whose
    last close still drains); every Ctrl-C and SIGTERM had been held until it returned, so the
    user's only way out was SIGKILL, which skips the teardown's all-off. A second stop is the
    user insisting: the descriptor the hold guards may leak then, the stop is not lost. Inside
    another hold (the teardown's), the signals go to that hold, which keeps them.
    """
    if threading.current_thread() is not threading.main_thread():
        yield  # handlers can only be set from the main thread, where they run
        return
    if second_stops and _after_a_stop:
        yield  # a stop was already acted on: a further one acts at once (see after_a_stop)
        return
    pending: list[tuple[int, Any, int]] = []  # signal, frame, as received
    raised: list[BaseException] = []  # by a pending signal's handler as a handler was swapped

    released = False  # the hold was ended early by a second stop (``second_stops``)

    def release() -> None:
        """Put the handlers back and deliver what was held, in order, as they would have
        been (a handler's exception is kept in ``raised``)."""
        nonlocal released
        released = True
        for sig, handler in installed.items():
            _swap_handler(sig, handler, raised)
        held, pending[:] = list(pending), []
        for signum, frame, received in held:
            handler = installed.get(signum)
            if handler is None:
                continue
            if handler == signal.SIG_DFL or handler is default_after_hooks:
                # the default action, now unheld, with no wait for the CLI's words (not even
                # a hang-up's, which :func:`hangup_as_sigterm`'s handler would have waited
                # on): SIGTERM's action is the default only in a command with no SIGTERM
                # handler, whose hold is a port's opening (a dome may be lit from its boot,
                # its all-off not yet sent)
                _default_now(received)  # a hang-up's: SIGHUP (exit 129)
            elif callable(handler):
                try:  # a held hang-up is delivered as one: named SIGHUP, not SIGTERM
                    _deliver(handler, received, frame)
                except BaseException as exc:
                    raised.append(exc)

    def hold(signum: int, frame: Any) -> None:
        received = as_received(signum)  # SIGHUP for a hang-up's: delivered later as one
        pending.append((signum, frame, received))
        if on_held is not None:
            on_held(received)
        if second_stops and len(pending) > 1 and not released:
            release()  # the user insists: acted on here, in the block, as if never held
            if raised:
                first = _first_of(raised)
                raised.clear()
                raise first

    installed: dict[int, Any] = {}
    try:  # a stop that came as the hold was set (in ``raised``) acts after the block too
        # the swaps inside the ``try``: a handler raising between two of them (SIGINT held,
        # SIGTERM's own handler still in place) had left SIGINT's hold installed for ever, a
        # hold no block would release (every later Ctrl-C kept in a list nobody reads)
        for sig in (signal.SIGINT, signal.SIGTERM):
            if signal.getsignal(sig) is None:  # set outside Python: it could not be put back
                continue
            installed[sig] = _swap_handler(sig, hold, raised)
        yield
    finally:
        if not released:
            release()  # delivered now, as they would have been
        else:  # a hold the loop above set after a second stop had ended it: put back too
            for sig, handler in installed.items():
                if signal.getsignal(sig) is hold:
                    _swap_handler(sig, handler, raised)
        if raised:
            raise _first_of(raised)


def _first_of(raised: list[BaseException]) -> BaseException:
    """The first of the exceptions the handlers of the signals a hold delivered raised, with
    each later one added to its notes ("also raised as the hold ended: …").

    Why: one hold can deliver several stops (a SIGTERM and a second Ctrl-C landing in the same
    commit); only the first can be raised, and it keeps the first stop's teardown, but the
    rest had been dropped without a trace. A handler that must be heard when a stop is under
    way says it as it runs (the CLI's "Ctrl-C also arrived" line); the notes keep what it
    raised for a traceback or a log."""
    first = raised[0]
    for later in raised[1:]:
        if later is not first:
            first.add_note(f"also raised as the hold ended: {type(later).__name__}: {later}")
    return first


def handlers_settable() -> bool:
    """Whether this thread may set signal handlers: only the main thread may (Python runs them
    there; ``signal.signal`` raises ValueError in any other). For the blocks whose handlers
    :func:`signal_handlers` cannot set (the capture's hand-over), the same check."""
    return threading.current_thread() is threading.main_thread()


#: What ``signal.signal`` accepts: a callable, ``SIG_DFL`` or ``SIG_IGN``.
Handler = Callable[[int, Any], Any] | int | signal.Handlers


@contextlib.contextmanager
def signal_handlers(wanted: Mapping[int, Handler]) -> Iterator[None]:
    """Install ``wanted`` (handler by signal) for the block; put back what was there before
    however it ends (a return, an error, a ``typer.Exit``).

    Off the main thread nothing is installed: Python sets and runs handlers only in the main
    thread (``signal.signal`` raises ValueError elsewhere), and there the caller's handlers,
    whatever they are, still apply. A signal whose handler was set outside Python
    (``getsignal`` says None: a program embedding Python, a preloaded library) is left to
    that handler, as :func:`signals_deferred` leaves it: it could not be put back, and ours
    stayed installed after the block (a later SIGTERM swallowed, or raised into the host).
    The restore is :func:`put_back`'s.
    """
    if not handlers_settable():
        yield
        return
    previous: dict[int, Any] = {}
    try:  # a handler that raises as the next is installed: those already set are put back
        for sig, handler in wanted.items():
            if signal.getsignal(sig) is None:  # set outside Python: left in charge
                continue
            previous[sig] = signal.signal(sig, handler)
        yield
    finally:
        put_back(previous)


def put_back(previous: Mapping[int, Any]) -> None:
    """Set each signal's handler back to ``previous``'s (as ``signal.signal`` or ``getsignal``
    returned it), main thread only: the restore of :func:`signal_handlers`, and of the blocks
    it cannot serve (the capture's, which puts back the hand-over's originals).

    Why not ``signal.signal`` in a loop: a None (a handler set outside Python) cannot be put
    back and raised TypeError, and a pending signal whose handler raises (the CLI's emergency
    stop) cut the loop short, leaving the rest of the block's handlers in place after it. Here
    each is swapped (:func:`_swap_handler`); the first such exception is raised once all are
    back. Off the main thread nothing is done (``signal.signal`` would raise ValueError there,
    and the swap's retry would spin on it)."""
    if not handlers_settable():
        return
    raised: list[BaseException] = []
    for sig, before in previous.items():
        if before is not None:  # None: set outside Python, cannot be put back
            _swap_handler(sig, before, raised)
    if raised:
        raise raised[0]


def _swap_handler(sig: int, handler: Any, raised: list[BaseException]) -> Any:
    """``signal.signal(sig, handler)``, made to happen: Python first runs the handlers of any
    signal already pending, and one that raises (the CLI's emergency stop) would skip the swap
    and leave a hold half set or half undone. Its exception is kept in ``raised``, the swap
    tried again. A handler ``signal.signal`` would refuse is refused before the loop, which
    would otherwise retry its TypeError for ever."""
    if not (callable(handler) or handler in (signal.SIG_DFL, signal.SIG_IGN)):
        raise TypeError(f"signal {sig}: {handler!r} is not a signal handler")
    while True:
        try:
            return signal.signal(sig, handler)
        except BaseException as exc:
            raised.append(exc)


#: Called (no arguments) just before :func:`default_action` ends the process; the CLI
#: registers the wait for its queued words here (the core may not import the CLI).
before_default_action: list[Callable[[], None]] = []


def default_action(sig: int) -> None:
    """End the process by ``sig``'s default action, the hooks of :data:`before_default_action`
    run first (an exception in one is dropped: the signal is still acted on).

    Why: the CLI's words are written by a thread of their own; the default action ends the
    process at once, and the words still queued for a slow reader were lost (a scratch script
    lost 1-11 of 50 lines in 4 runs of 10). Only for call sites where the rig is already safe
    (or was never opened): a hook may wait a moment for the reader."""
    for hook in list(before_default_action):
        with contextlib.suppress(BaseException):
            hook()
    _default_now(sig)


def _default_now(sig: int) -> None:
    """End the process by ``sig``'s default action at once: no hook, no handler of ours (a
    hang-up's SIGHUP would otherwise meet :func:`hangup_as_sigterm`'s, which may wait)."""
    signal.signal(sig, signal.SIG_DFL)
    signal.raise_signal(sig)


def default_after_hooks(signum: int, frame: Any) -> None:
    """A SIGTERM handler that is the default action with :data:`before_default_action`'s
    hooks run first: the CLI's handler for the moments no command has its own (``bench``;
    ``fit`` and ``plan`` once their work is done; any command's end, waiting for its words).

    Why a handler of the core's: the default action ended the process at once and the words
    the CLI still held for a slow reader were lost. A hold over a port's opening
    (:func:`signals_deferred`) knows it by name and takes the default action it stands for
    at once, without the wait."""
    default_action(as_received(signum))
