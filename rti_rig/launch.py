"""The `rti-rig` console entry point, kept apart from the command line it starts.

Why a module of its own: a console script imports its target before calling it, and
:mod:`rti_rig.cli` pulls in typer, rich and numpy — a few tenths of a second in which a Ctrl-C
would otherwise print Python's KeyboardInterrupt traceback. Nothing has been opened or moved
then, so the honest message is that nothing was done. This module imports nothing at load time.
"""

import sys

#: The exit status of a command stopped by Ctrl-C (128 + SIGINT), as the shell reports it.
INTERRUPTED_EXIT = 130


def main() -> None:
    """Import the command line and run it; a Ctrl-C no command handled ends quietly. However
    it ends, the exit status is the one raised here (see :func:`_exit_as_said`)."""
    try:
        _standard_streams_opened()
        _unencodable_replaced()
        _main()
    finally:
        _exit_as_said()


def _standard_streams_opened() -> None:
    """Give a standard stream the process was started without (``>&-``, ``2>&-``, ``<&-``,
    a supervisor that closed it) ``/dev/null``, as a daemon does, before anything is opened.

    Why: Python then leaves ``sys.stdout`` (or ``sys.stderr``) ``None``, and the first word
    printed raised ``AttributeError``: ``run … >&-`` ended before its session began with a
    traceback and exit 1, and ``run … --lights 200 2>&-`` exited 1, not the refusal's 2. And
    the closed descriptor is the lowest free one: the next file opened (a session file, the
    dome's serial port) would have become descriptor 1 or 2, where a library's or a child
    process's output goes. The words are dropped, as the caller chose; the exit code and the
    session's files say what happened."""
    import os

    for fd, mode in ((0, os.O_RDONLY), (1, os.O_WRONLY), (2, os.O_WRONLY)):
        try:
            os.fstat(fd)
        except OSError:
            devnull = os.open(os.devnull, mode)
            if devnull != fd:
                os.dup2(devnull, fd)
                os.close(devnull)
    for name, fd, mode in (("stdin", 0, "r"), ("stdout", 1, "w"), ("stderr", 2, "w")):
        if getattr(sys, name) is None:
            stream = open(fd, mode, encoding="utf-8", errors="backslashreplace", closefd=False)  # noqa: SIM115
            setattr(sys, name, stream)
            setattr(sys, f"__{name}__", stream)


def _unencodable_replaced() -> None:
    """Print a character stdout's encoding cannot hold as ``?``, not raise (stderr already
    prints it as ``\\u2192``).

    Why: the words hold ``→``, ``°``, ``━`` and the user's own paths; with a legacy encoding
    (a Latin-1 locale, ``PYTHONIOENCODING=ascii``, Windows' code page for a redirected
    stream) the first of them raised ``UnicodeEncodeError``: ``run`` ended with a traceback and
    exit 1 before its session began, or could have mid-capture. The words are for people: one
    character of them replaced is no loss; the files keep every name as it is."""
    from contextlib import suppress

    stream = sys.stdout  # stderr's errors are backslashreplace already (Python's default)
    encoding = (getattr(stream, "encoding", None) or "").lower().replace("_", "-")
    if not encoding.startswith("utf"):
        with suppress(AttributeError, ValueError, OSError):  # not a stream to reconfigure
            stream.reconfigure(errors="replace")


def _exit_as_said() -> None:
    """Forget any Ctrl-C CPython marked unhandled on the way: the exit status is the one the
    command chose (130 after its "Stopped (Ctrl-C)").

    Why: a Ctrl-C that lands inside code run from a string (``exec``/``eval``: a dataclass's or
    namedtuple's methods being made as a lazy import runs) marks it "unhandled" in CPython
    even when the command catches it, and under ``python -m`` nothing clears the mark: the
    process then killed itself with SIGINT at exit after its own message and exit 130, and its
    parent saw -2, not 130 (about one Ctrl-C in six during ``fit``'s first seconds). Running
    any string clears the mark; every Ctrl-C is handled here, so none is truly unhandled."""
    exec("pass", {})  # a constant string: clears CPython's mark, nothing else


def _main() -> None:
    try:
        from rti_rig.cli import main as run_cli
    except KeyboardInterrupt:
        _say("rti-rig: stopped while starting (Ctrl-C); nothing was done\n")
        raise SystemExit(INTERRUPTED_EXIT) from None
    try:
        run_cli()
    except KeyboardInterrupt as exc:
        ending = _exit_under_way(exc)
        if ending is not None:
            # the command had already ended (a SIGTERM's stop said, its 143 on the way out)
            # and put its handlers back: the Ctrl-C landed in the unwinding. The stop is named
            # by the signal that began it: its words said SIGTERM, and the exit had said 130
            _say(_exit_stands(ending))
            raise SystemExit(ending) from None
        # a Ctrl-C no command handled: one line, not Python's traceback
        _say("rti-rig: stopped (Ctrl-C)\n")
        raise SystemExit(INTERRUPTED_EXIT) from None
    except SystemExit as exc:
        interrupt = _from_keyboard_interrupt(exc)
        ending = _exit_under_way(interrupt) if interrupt is not None else None
        if ending is not None:  # as above, the Ctrl-C turned into click's Abort on the way
            _say(_exit_stands(ending))
            raise SystemExit(ending) from None
        if interrupt is not None:
            # typer turns a Ctrl-C no command handled (its options still being parsed, a
            # command with nothing to make safe) into exit 130 without a word (older typer:
            # "Aborted!" and exit 1): said, and the shell's code for a Ctrl-C either way
            _say("rti-rig: stopped (Ctrl-C)\n")
            raise SystemExit(INTERRUPTED_EXIT) from None
        raise


def _say(text: str) -> None:
    """Write ``text`` on stderr, or nothing where stderr cannot be written (``2>/dev/full``, a
    terminal gone): the exit status is what says how the command ended.

    Why: before the command line has put its tolerant streams in place (a Ctrl-C while it is
    imported) a failed write raised here and the process exited 1, not 130; once they are in
    place, ``sys.stderr`` is one of them and this guard is not needed, but costs nothing."""
    try:
        sys.stderr.write(text)
        sys.stderr.flush()
    except (OSError, ValueError):
        pass


def _exit_under_way(exc: KeyboardInterrupt) -> int | None:
    """The exit status (not 0) a command was already leaving with when the Ctrl-C ``exc``
    was raised (a ``SystemExit``, or click's and typer's ``Exit``, in its context: a
    ``finally`` or ``except`` on the way out was running), else None.

    Why: a command that ends with a stop's status (``run`` stopped by SIGTERM: 143) puts its
    signal handlers back before the exit reaches the interpreter; a Ctrl-C then raised
    KeyboardInterrupt in the unwinding, which replaced the exit: "Emergency stop (SIGTERM)"
    said, exit 130. A command leaving with 0 has claimed nothing a Ctrl-C could belie: that
    Ctrl-C is the user's stop, exit 130 as ever."""
    seen: set[int] = set()
    link: BaseException | None = exc.__context__
    while link is not None and id(link) not in seen:
        seen.add(id(link))
        code = link.code if isinstance(link, SystemExit) else getattr(link, "exit_code", None)
        if isinstance(link, SystemExit | Exception) and isinstance(code, int) and code:
            return code
        link = link.__context__
    return None


def _exit_stands(code: int) -> str:
    """What a Ctrl-C that landed as the command left with ``code`` is told: the stop that
    ended it (a signal's: 128 + its number) or its exit, kept."""
    import signal

    try:
        stop = f"the stop by {signal.Signals(code - 128).name}"
    except ValueError:
        stop = "its exit"
    return f"rti-rig: Ctrl-C as the command was ending: {stop} stands (exit {code})\n"


def _from_keyboard_interrupt(exc: BaseException) -> KeyboardInterrupt | None:
    """The KeyboardInterrupt ``exc`` was raised while handling (its chain holds one), else
    None; a command's own exit 130 after its message is raised ``from None`` and holds none."""
    seen: set[int] = set()
    link: BaseException | None = exc
    while link is not None and id(link) not in seen:
        if isinstance(link, KeyboardInterrupt):
            return link
        seen.add(id(link))
        link = link.__cause__ or (None if link.__suppress_context__ else link.__context__)
    return None


if __name__ == "__main__":
    # `python -m rti_rig.launch ARGS`, the console script's own module run by hand (a checkout
    # whose venv scripts point elsewhere): it had loaded these definitions and exited 0 having
    # done nothing, a silent "success" of any command asked
    main()
