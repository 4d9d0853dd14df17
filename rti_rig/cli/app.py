"""The `rti-rig` application object, its consoles and the helpers every command shares.

Every user-facing failure is an :class:`~rti_rig.core.errors.RtiRigError` printed as one clear
message (file, line or key, and what to do) with exit status 2, never a traceback.
"""

from __future__ import annotations

import io
import math
import os
import signal
import sys

import typer
from rich.console import Console
from rich.markup import escape

from rti_rig.core.deferred_signals import as_received
from rti_rig.core.errors import RtiRigError
from rti_rig.core.shell_words import shell_word as shell_word  # re-exported for the commands
from rti_rig.core.shell_words import shown_path as shown_path  # re-exported for the commands

app = typer.Typer(
    help=(
        "Drive Reflectance Transformation Imaging (RTI) rigs: LED domes and servo-arm light "
        "carriers with a camera, or their simulation.\n\n"
        "Typical use: 'rti-rig run RIG.toml --out SESSION' captures one image per light and "
        "writes SESSION/lights.lp for relight or RTIBuilder. A rig config whose backend is "
        "'simulated' gives a dry run that reports how long the real rig would take."
    ),
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
)
err = Console(stderr=True)
out = Console()


def _print_version(given: bool) -> None:
    """Print the versions a bug report needs and exit (``--version``): rti-rig's, as the
    manifest of every session records it, with Python's, numpy's, OpenCV's and the platform.

    Why: a user filing a problem, or checking that a lab's machines match, had only
    ``pip show`` (which names the installed metadata, not the code an editable checkout runs)."""
    if not given:
        return
    from rti_rig.runtime.session import software_versions

    versions = software_versions()
    out.print(
        f"rti-rig {versions['rti_rig']} (Python {versions['python']}, numpy "
        f"{versions['numpy']}, OpenCV {versions['opencv']}; {versions['platform']})",
        highlight=False,
        soft_wrap=True,
    )
    raise typer.Exit()


@app.callback()
def _options(
    version: bool = typer.Option(
        False,
        "--version",
        callback=_print_version,
        is_eager=True,
        help="Show rti-rig's version (and Python's, numpy's, OpenCV's) and exit.",
    ),
) -> None:
    """The options of ``rti-rig`` itself, before a command."""


def _flags_show_no_type() -> None:
    """Show on/off flags in help without a value type: typer 0.29 labels them ``<bool>``, as if
    ``--force`` took a value (it takes none). Every command's flags at once, in one place."""
    try:  # typer's internals: a release without them loses this polish, not the CLI
        from typer.core import TyperOption

        original = TyperOption.display_type_rich
    except (ImportError, AttributeError):
        return
    if getattr(original, "_rti_rig", False):
        return

    def display_type_rich(self, ctx):  # type: ignore[no-untyped-def]
        if getattr(self, "is_flag", False) and self.metavar is None:
            return None
        return original(self, ctx)

    display_type_rich._rti_rig = True  # type: ignore[attr-defined]
    TyperOption.display_type_rich = display_type_rich  # type: ignore[method-assign]


_flags_show_no_type()


def _is_path_annotation(annotation: object) -> bool:
    """Whether a parameter's annotation is ``Path`` or a list of them (``fit S1 S2 …``)."""
    import typing
    from pathlib import Path

    if annotation is Path:
        return True
    return typing.get_origin(annotation) is list and typing.get_args(annotation) == (Path,)


def _empty_paths_refused() -> None:
    """Refuse an empty path (``--out ""``, ``fit ""``) on every command as a usage error
    (exit 2) naming the option, before any command runs.

    Why: a path given as the empty string became ``Path("")``, the current folder: a script's
    ``--out "$part"`` with ``part`` unset wrote its session into whatever empty folder the
    script ran in (or was refused as ". is not empty", naming no empty argument), and
    ``--resume ""`` resumed the current folder. An empty string is never a folder or file a
    user meant; ``.`` is still accepted when written as such."""
    try:  # typer's internals: a release without them loses this refusal (its tests say so),
        # not the whole CLI (an ImportError here had ended every command before it ran)
        from typer._click.exceptions import UsageError
        from typer.core import _TyperParameter

        original = _TyperParameter.process_value
    except (ImportError, AttributeError):
        return
    if getattr(original, "_rti_rig", False):
        return

    def process_value(self, ctx, value):  # type: ignore[no-untyped-def]
        # getattr: typer's own object; a release that renames it must not fail every option
        annotation = getattr(getattr(self, "type_descriptor", None), "annotation", None)
        if _is_path_annotation(annotation):
            given = value if isinstance(value, list | tuple) else [value]
            if any(isinstance(v, str) and v == "" for v in given):
                raise typer.BadParameter(
                    "an empty path (a shell variable that was not set?): give a folder or "
                    "file, or '.' for the current folder",
                    ctx=ctx,
                    param=self,
                )
            if getattr(self, "metavar", None) == FILE:
                refusal = _folder_given_for_a_file(self, given)
                if refusal is not None:
                    raise UsageError(refusal, ctx=ctx)
        try:
            return original(self, ctx, value)
        except typer.BadParameter:
            refusal = _not_a_number(self, annotation, value)
            if refusal is None:
                raise
            raise UsageError(refusal, ctx=ctx) from None

    process_value._rti_rig = True  # type: ignore[attr-defined]
    _TyperParameter.process_value = process_value  # type: ignore[method-assign]


#: The metavar of an option that names a file to write (``plan --out``, ``--figure``,
#: ``export-lp --out``…): help shows ``--out FILE``, and a value ending in a path separator,
#: which names a folder, is refused (:func:`_folder_given_for_a_file`).
FILE = "FILE"


def _folder_given_for_a_file(param: object, given: list[object]) -> str | None:
    """The refusal of a file option given a value ending in ``/`` (``--out plans/``), or
    ``None``.

    Why: :class:`~pathlib.Path` drops a trailing separator, so ``plan … --out plans/`` with no
    folder ``plans`` wrote the plan as a *file* named ``plans``, said "Planned 12 lights →
    plans", and a later ``mkdir plans`` failed on it; the user had named a folder."""
    seps = tuple(s for s in (os.sep, os.altsep, "/") if s)
    for value in given:
        if isinstance(value, str) and value.endswith(seps) and value.rstrip("".join(seps)):
            opts = [o for o in getattr(param, "opts", ()) if o.startswith("--")]
            name = opts[0] if opts else str(getattr(param, "name", "the file"))
            return (
                f"{name} {value}: ends in {value[-1]!r}, which names a folder; give the name of "
                f"the file to write in it ({name} {value}NAME)"
            )
    return None


def _number_kind(annotation: object) -> type | None:
    """``int`` or ``float`` for an option typed so (or ``... | None``), else ``None``."""
    import typing

    kinds = [a for a in typing.get_args(annotation) if a is not type(None)] or [annotation]
    if len(kinds) == 1 and kinds[0] in (int, float):
        return kinds[0]  # type: ignore[no-any-return]
    return None


def _not_a_number(param: object, annotation: object, value: object) -> str | None:
    """The refusal of ``value`` given to a whole-number or number option that is not one:
    "--lights: 'N' is not a whole number: give one in digits, e.g. --lights 12", or ``None``
    when the value is a number (a range refusal keeps its own words).

    Why: typer's pydantic said "Invalid value for '--lights': Input should be a valid
    integer, unable to parse string as an integer", which is not what a user pasting a
    hint's ``--lights N`` needs: the value given and what to give instead."""
    kind = _number_kind(annotation)
    if kind is None or not isinstance(value, str):
        return None
    try:
        kind(value)
    except ValueError:
        pass
    else:
        return None
    opts = [o for o in getattr(param, "opts", ()) if o.startswith("--")]
    name = opts[0] if opts else str(getattr(param, "name", "the value"))
    default = getattr(param, "default", None)
    example = (
        f", e.g. {name} {default:g}"
        if isinstance(default, int | float) and not isinstance(default, bool) and opts
        else ""
    )
    if kind is int:
        return f"{name}: {value!r} is not a whole number: give one in digits{example}"
    return f"{name}: {value!r} is not a number: give one in digits (a point for decimals){example}"


_empty_paths_refused()


def reflowed(doc: str) -> str:
    """``doc`` with the line breaks inside each paragraph made spaces (blank lines still part
    paragraphs). Why: typer's rich help keeps a docstring's source line breaks, so ``--help``
    showed sentences broken mid-line ("stops at once (lights" / "off, arm stopped ...") and the
    command list cut each summary at its first source line."""
    paragraphs = [" ".join(p.split()) for p in doc.strip().split("\n\n")]
    return "\n\n".join(p for p in paragraphs if p)


def reflow_command_help(typer_app: typer.Typer) -> None:
    """Give every command of ``typer_app`` whose help is its docstring that docstring reflowed
    (:func:`reflowed`); an explicit ``help=`` is left as written."""
    import inspect

    for command in typer_app.registered_commands:
        if command.help is None and command.callback is not None:
            doc = inspect.getdoc(command.callback)
            if doc:
                command.help = reflowed(doc)


def fail(exc: RtiRigError) -> typer.Exit:
    # what a tolerant reader had noted of the file refused (a count line that disagrees, a
    # light clamped to the horizon): said first, or the user mends what the error names and
    # learns of the rest only on the next try
    print_notes(getattr(exc, "reader_notes", ()))
    # the message is plain text: "[camera]" or "[dome.serial]" in it must not be read as markup
    err.print(f"[bold red]error:[/] {escape(str(exc))}", highlight=False, soft_wrap=True)
    return typer.Exit(code=2)


def print_notes(notes) -> None:  # type: ignore[no-untyped-def]
    """What a tolerant reader accepted but the user should know (file, line, what was done)."""
    for note in notes:
        err.print(f"[yellow]note:[/] {escape(note)}", highlight=False, soft_wrap=True)


def print_note(note) -> None:  # type: ignore[no-untyped-def]
    """Show a use case's note: information on stdout, warnings on stderr."""
    if note.level == "warning":
        err.print(f"[yellow]note:[/] {escape(note.text)}", soft_wrap=True)
    else:
        out.print(note.text, highlight=False, markup=False)


def option_given(ctx: typer.Context, name: str) -> bool:
    """Whether option ``name`` was on the command line (or in the environment), not defaulted.

    By the source's name: typer's context may be its own click's, whose enum is not
    ``click.core.ParameterSource``."""
    source = ctx.get_parameter_source(name)
    return source is not None and source.name not in ("DEFAULT", "DEFAULT_MAP")


def parse_az_el(text: str | None, option: str = "--preview-light") -> tuple[float, float] | None:
    """``"AZ,EL"`` in degrees → a pair; a clear error naming ``option`` otherwise."""
    if text is None:
        return None
    parts = text.replace(" ", "").split(",")
    try:
        az, el = (float(p) for p in parts)
    except ValueError:
        raise RtiRigError(
            f"{option} {text!r}: give azimuth and elevation in degrees as AZ,EL (e.g. 45,30)"
        ) from None
    if not math.isfinite(az):
        raise RtiRigError(f"{option} {text!r}: the azimuth {az:g} is not a finite angle")
    if not 0.0 <= el <= 90.0:
        raise RtiRigError(f"{option} {text!r}: the elevation {el:g}° is outside 0..90°")
    return az, el


def stop_exit_code(signum: signal.Signals) -> int:
    """The exit code of a command stopped by the signal ``signum``: 128 + its number, as a
    shell reports a process the signal ended (SIGTERM 143, Ctrl-C 130). Decided on the signal
    itself, not on the words that name it to the user; a SIGTERM that was a hang-up is
    SIGHUP's 129 (:func:`~rti_rig.core.deferred_signals.as_received`)."""
    return 128 + int(as_received(signum))


#: Libraries whose log records are not for the user's terminal: a command says in words what
#: they found (a damaged file is named by the image reader), so their records are dropped.
QUIET_LIBRARY_LOGGERS = ("tifffile",)
#: Dask's loggers that print a raw traceback of what ``fit --scheduler`` then says in words (a
#: task or result that cannot be read here: "Failed to deserialize ... ModuleNotFoundError").
#: Dask gives its ``distributed`` logger a stderr handler of its own, so a handler that drops
#: their records is not enough: they are also kept from propagating to it.
QUIET_DASK_LOGGERS = ("distributed.protocol.pickle", "distributed.protocol.core")


def quiet_library_logs() -> None:
    """Give each of :data:`QUIET_LIBRARY_LOGGERS` a handler that drops its records.

    Why: the command line configures no logging, so a library's warning reaches Python's
    last-resort handler and is printed raw: a TIFF with damaged tags printed nine
    ``<TiffTag.fromfile> raised TiffFileError(...)`` lines per read, dozens for one ``fit``,
    around rti-rig's own sentences. A program that configures logging itself still receives
    the records (they propagate as before). :data:`QUIET_DASK_LOGGERS` propagate no further
    (Dask's own handler on ``distributed`` printed them): only the command line calls this."""
    import logging

    for name in QUIET_LIBRARY_LOGGERS + QUIET_DASK_LOGGERS:
        logger = logging.getLogger(name)
        if not any(isinstance(h, logging.NullHandler) for h in logger.handlers):
            logger.addHandler(logging.NullHandler())
    for name in QUIET_DASK_LOGGERS:
        logging.getLogger(name).propagate = False
    opencv_warnings_quiet()


def opencv_warnings_quiet() -> None:
    """Keep OpenCV's native warnings off the terminal (its errors still print), unless the
    user set ``OPENCV_LOG_LEVEL`` themselves.

    Why: a UVC camera that did not open printed OpenCV's ``[ WARN:0@0.204] global
    cap_v4l.cpp:914 open VIDEOIO(V4L2:/dev/video0): can't open camera by index`` lines before
    rti-rig's own message, which names the device and what to check. OpenCV's C++ logger
    writes to stderr itself, outside Python's logging; it reads ``OPENCV_LOG_LEVEL`` when it
    first logs, and an OpenCV already imported is told by its own call."""
    if "OPENCV_LOG_LEVEL" in os.environ:
        return
    os.environ["OPENCV_LOG_LEVEL"] = "ERROR"
    cv2 = sys.modules.get("cv2")
    try:
        if cv2 is not None:
            cv2.utils.logging.setLogLevel(cv2.utils.logging.LOG_LEVEL_ERROR)
    except AttributeError:  # a build without the utils module keeps its own level
        pass


#: The logger every rti-rig module logs under (``rti_rig.dome``, ``rti_rig.dynamixel.arm`` …).
PRODUCT_LOGGER = "rti_rig"


def records_as_notes() -> None:
    """Say each rti-rig log record at warning level or above as a note on stderr, in its own
    words, once; records below it (the drivers' diagnostics) stay off the terminal.

    Why: the command line configures no logging, so such a record reached Python's
    last-resort handler and was printed raw ("arm: not at the park pose …", or with a
    ``WARNING:rti_rig.dome:`` prefix under a configured root logger) in the middle of the
    progress bar. A device says what a user must know through its own channel (a dome's or an
    arm's ``listen``); this is the fallback for a record said with no listener, so that none
    is lost and none is printed raw. They propagate no further: a root handler that something
    configured (pyserial's ``socket://…?logging=`` and ``loop://`` URLs call
    ``logging.basicConfig``) had printed them again as ``WARNING:rti_rig.dome:…``. Only the
    command line calls this: a program that configures logging, or a test's ``caplog``,
    receives the records as before."""
    import logging

    logger = logging.getLogger(PRODUCT_LOGGER)
    if any(getattr(h, "_rti_rig_notes", False) for h in logger.handlers):
        return
    said: set[str] = set()

    class AsNotes(logging.Handler):
        _rti_rig_notes = True

        def emit(self, record: logging.LogRecord) -> None:
            try:
                text = record.getMessage()
            except Exception:  # a record whose arguments do not fit its format: said as given
                text = str(record.msg)
            if text not in said:
                said.add(text)
                warning_note(text)

    logger.addHandler(AsNotes(logging.WARNING))
    logger.propagate = False


def warning_note(text: str) -> None:
    """Say a warning's message as a note on stderr (the one form both :func:`warnings_as_notes`
    and the run's verdict use for a warning no command words otherwise)."""
    err.print(f"[yellow]note:[/] {escape(text)}", soft_wrap=True, highlight=False)


def warnings_as_notes() -> None:
    """Any Python warning that reaches the console is said as a note: its message alone, once.

    Why: a warning no command turned into its own words (a library's, or a fit's trust
    warning on a path not yet worded) printed Python's form, with a source file path and line
    (``.../rti_rig/app/usecases/adaptive.py:176: IllConditionedFitWarning: ...``), which
    tells a user nothing they can act on. Set for the console entry only: a caller of the
    app from Python keeps its own warning handling.

    Why this and ``run``'s verdict warnings (``cli.fit._say_verdict_warnings``) both exist:
    this one is the fallback for any warning, said as it is raised, in its own words; the
    verdict catches its fits' warnings to say them after the verdict line, a fit-trust warning
    worded as what it means for the session and what to do (its other warnings go through
    :func:`warning_note`, as here)."""
    import warnings

    said: set[str] = set()

    def as_note(message, category, *_args, **_kwargs):  # type: ignore[no-untyped-def]
        text = str(message)
        if text not in said:
            said.add(text)
            warning_note(text)

    warnings.showwarning = as_note


def unwrapped_when_piped() -> None:
    """Where stdout or stderr is not a terminal (``| grep``, ``> log``, a script's capture),
    each message is printed on one line, however long.

    Why: rich wraps at the terminal's width and, with no terminal, at 80 columns, so a piped
    ``fit`` or ``run`` broke its ``QA verdict: reshoot: image_003 (...)`` over six lines,
    mid-path (``rti-rig run --resume S`` / ``--reshoot-lost``): a script reading the verdict
    line got its first 80 characters, and the ``Rig ... → OUT`` line of a long --out path was
    split in two. A terminal still wraps as before. Set for the console entry only (a test's
    CliRunner, and a caller of the app from Python, keep rich's behaviour)."""
    for console in (out, err):
        if not console.is_terminal:
            console.soft_wrap = True
    if not err.is_terminal:
        _usage_errors_plain()


def _usage_errors_plain() -> None:
    """Say a usage error (an unknown option, a bad value) as click's plain lines, not typer's
    box: where stderr is not a terminal, the box was drawn at 80 columns and its message
    wrapped inside it (``│ Invalid value for '--out': an empty path (a shell variable that
    was not      │`` / ``│ set?) …``), so a log kept the message in pieces between box
    characters. Typer looks its formatter up at each error, so replacing it here is enough;
    a terminal keeps the box."""
    try:  # typer's internals, as the two patches above: a release without it keeps its box
        from typer import rich_utils
    except ImportError:
        return

    def plain(exc) -> None:  # type: ignore[no-untyped-def]
        # through err's stream: a stderr that cannot be written (2>/dev/full) loses the words,
        # not the usage error's exit 2 (click's own stderr raised, and the command exited 1)
        exc.show(file=err.file)

    rich_utils.rich_format_error = plain  # type: ignore[assignment]


def help_styled_as_the_consoles() -> None:
    """Style typer's help and usage errors as :data:`out` and :data:`err` are: no escape codes
    where the stream is not a terminal, unless ``FORCE_COLOR`` or ``TTY_COMPATIBLE=1`` asks
    for them (rich reads both itself), and no colour under ``NO_COLOR`` (rich again).

    Why: typer forces its consoles to be terminals under ``GITHUB_ACTIONS`` or ``PY_COLORS``,
    so ``rti-rig run --help > help.txt`` in a CI job wrote bold, dim and colour codes into the
    file, where every other word of rti-rig is plain text when piped."""
    try:  # typer's internals, as the patches above: a release without them keeps its rule
        from typer import rich_utils
    except ImportError:
        return
    if getattr(rich_utils, "FORCE_TERMINAL", None) is True:
        rich_utils.FORCE_TERMINAL = None


class ReaderGoneTolerant:
    """A console's stream whose reader closing the pipe (``| head -1``, a script that read the
    line it wanted) sends the rest of the command's words to ``/dev/null`` instead of ending
    the command.

    Why: click turns the first ``BrokenPipeError`` into exit 1 without a word, so ``rti-rig run
    ... | head -1`` ended a session that had completed with exit 1 (read as "the rig was not
    made safe or a fault rti-rig did not name"), its summary and verdict unsaid; one broken
    mid-capture would have ended the capture. The words are for people; the session's files
    hold what happened. The stream's file descriptor is pointed at ``/dev/null`` (not merely
    this wrapper), so the interpreter's own flush at exit cannot fail either.

    Any other failed write is taken the same way (a log file whose disk is full, ``EFBIG``, a
    terminal gone with its ssh connection, ``EIO``), said once on stderr where stdout failed:
    ``run … > log`` with the log's disk full had ended with a traceback and exit 1 at its first
    line, and a disk that filled during the capture (a session and its log often share one)
    would have ended the capture at the next progress update, from a print."""

    def __init__(self, stream, said_on=None) -> None:  # type: ignore[no-untyped-def]
        self._stream = stream
        #: where a failure other than a gone reader is said (stdout's: stderr), or nowhere
        self._said_on = said_on

    def write(self, text: str) -> int:
        try:
            return self._stream.write(text)
        except OSError as exc:
            self._reader_gone(exc)
            return len(text)

    def flush(self) -> None:
        try:
            self._stream.flush()
        except OSError as exc:
            self._reader_gone(exc)

    def say_failure_on(self, stream) -> None:  # type: ignore[no-untyped-def]
        """Say a failure on ``stream`` from now on, where one is said at all (stdout's).

        Why: once the words are written by a thread of their own, stdout's failure is noticed
        there, and its note written to stderr's stream went straight to fd 2: during a RAW
        decode, fd 2 is LibRaw's capture for a moment (the note came out later, out of order).
        The console entry gives it the copy of fd 2 its stderr words go to."""
        if self._said_on is not None:
            self._said_on = stream

    def _reader_gone(self, exc: OSError | None = None) -> None:
        if exc is not None and not isinstance(exc, BrokenPipeError) and self._said_on:
            said_on, self._said_on = self._said_on, None  # said once
            try:
                said_on.write(
                    f"note: output could not be written ({exc.strerror or exc}): the rest of "
                    "it is dropped; the exit code and the files written say what happened\n"
                )
                said_on.flush()
            except (OSError, ValueError):
                pass

        devnull = os.open(os.devnull, os.O_WRONLY)
        try:
            os.dup2(devnull, self._stream.fileno())
        finally:
            os.close(devnull)

    def __getattr__(self, name: str):  # type: ignore[no-untyped-def]
        return getattr(self._stream, name)


class WritableWaited(io.RawIOBase):
    """A descriptor opened non-blocking (``O_NONBLOCK``), written as a blocking one is: a write
    the pipe has no room for waits until the reader makes room, then writes what is left.

    Why: a parent that set ``O_NONBLOCK`` on the pipe it reads (node's ``child_process``, some
    CI runners; the flag is on the pipe, shared with the child) made a write to a full pipe
    raise ``BlockingIOError``: taken as output that cannot be written, every word after it was
    dropped. Retrying above Python's text stream cannot work: its buffer forgets how much of
    a failed write went out. Here, below the buffer, the count written is exact. Closing it
    leaves the descriptor open (``RawIOBase.close`` closes none): it is the process's stdout or
    stderr, not ours."""

    def __init__(self, fd: int) -> None:
        super().__init__()
        self._fd = fd

    def writable(self) -> bool:
        return True

    def fileno(self) -> int:
        return self._fd

    def isatty(self) -> bool:
        """A terminal still: a non-blocking terminal keeps its colour and progress bar."""
        return os.isatty(self._fd)

    def write(self, data) -> int:  # type: ignore[no-untyped-def,override]
        import select

        while True:
            try:
                return os.write(self._fd, data)  # a short count: the buffer writes the rest
            except BlockingIOError:
                select.select([], [self._fd], [])  # the reader made room (or left: EPIPE next)


def waiting_when_nonblocking(stream):  # type: ignore[no-untyped-def]
    """``stream`` itself, or, where its descriptor is non-blocking, a text stream of the same
    encoding and buffering that writes through :class:`WritableWaited`."""
    try:
        fd = stream.fileno()
        if os.get_blocking(fd):
            return stream
        stream.flush()  # nothing written yet, as a rule: if something is, in order
    except (AttributeError, OSError, ValueError):  # not a descriptor's stream: as it is
        return stream
    return io.TextIOWrapper(
        io.BufferedWriter(WritableWaited(fd)),
        encoding=stream.encoding,
        errors=stream.errors,
        line_buffering=stream.line_buffering,
        write_through=getattr(stream, "write_through", False),
    )


def reader_gone_tolerated() -> None:
    """Give :data:`out` and :data:`err`, and ``sys.stdout`` and ``sys.stderr`` for everything
    else that writes (click's usage errors, typer's help, the launcher's last line), the
    process's stdout and stderr through :class:`ReaderGoneTolerant`, each waiting for room
    where its pipe is non-blocking (:func:`waiting_when_nonblocking`). The console entry only,
    as :func:`unwrapped_when_piped`.

    Why ``sys.stdout`` and ``sys.stderr`` too: a word written past the consoles to a stream
    that failed raised from wherever it was written: ``run --nope 2>/dev/full`` exited 1 (a
    fault rti-rig did not name), not the usage error's 2."""
    stdout = waiting_when_nonblocking(sys.stdout)
    stderr = waiting_when_nonblocking(sys.stderr)
    sys.stdout = out.file = ReaderGoneTolerant(stdout, said_on=stderr)  # type: ignore[assignment]
    sys.stderr = err.file = ReaderGoneTolerant(stderr)  # type: ignore[assignment]


def main() -> None:
    quiet_library_logs()
    records_as_notes()
    warnings_as_notes()
    unwrapped_when_piped()
    help_styled_as_the_consoles()
    reader_gone_tolerated()
    from rti_rig.cli.unwaited_words import (
        stops_wait_for_the_words,
        words_unwaited,
        words_written,
    )

    words_unwaited((out, err))  # no print waits on the reader while the rig works
    stops_wait_for_the_words()  # nor a word said lost to SIGTERM's or SIGHUP's default action
    ending: object = 0  # the exit the command left with
    try:
        app()
    except SystemExit as exc:
        ending = exc.code
        raise
    finally:
        # a Ctrl-C left words unwritten: a success is not claimed (a stop's or an error's
        # exit stands: the stop is named by the signal that began it)
        if not words_written() and ending in (0, None):
            raise SystemExit(stop_exit_code(signal.SIGINT))
