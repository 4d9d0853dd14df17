"""`rti-rig check` and `rti-rig probe`: a rig's self-test, and which dome firmware answers."""

from __future__ import annotations

import signal
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, NoReturn, Protocol

import typer
from rich.markup import escape

from rti_rig.cli.app import app, err, fail, out, shown_path, stop_exit_code
from rti_rig.core.deferred_signals import hangup_as_sigterm, signal_handlers
from rti_rig.core.errors import RtiRigError

if TYPE_CHECKING:
    from rti_rig.app.usecases.check import CheckStopped
    from rti_rig.app.usecases.probe import ProbeResult


class _Report(Protocol):
    """What a check's, reboot's and park's reports share: their words and whether it ended well."""

    @property
    def ok(self) -> bool: ...

    def lines(self) -> list[str]: ...


@contextmanager
def stop_on_signals() -> Iterator[None]:
    """Ctrl-C or SIGTERM stops a check at once, through its teardown (all-off; lamp off, arm
    stopped): without a handler SIGTERM killed the process with an LED lit and said nothing.
    A further signal while the first is handled only says so: the teardown it would cut short
    is what switches the lights off (``kill -9`` still ends the process)."""
    from rti_rig.cli.unwaited_words import say_unwaited
    from rti_rig.runtime.controller import EmergencyStop

    phase = "checking"  # then "stopping" (first signal), "done" (handlers being restored)

    def on_signal(signum, frame):  # type: ignore[no-untyped-def]
        nonlocal phase
        if phase == "stopping":
            # never waiting on stderr's reader: this interrupts the teardown it describes
            say_unwaited("Still stopping: making the rig safe first (lights, lamp, arm)...\n")
        if phase != "checking":
            return  # never raised mid-teardown, nor mid-restore
        phase = "stopping"
        raise EmergencyStop(signal.Signals(signum))

    with (
        signal_handlers({signal.SIGINT: on_signal, signal.SIGTERM: on_signal}),
        hangup_as_sigterm(),
    ):
        try:
            yield
        finally:
            phase = "done"


@app.command()
def check(
    rig_config: Annotated[
        Path,
        typer.Argument(
            help="Rig config TOML to check, or a recorded acquisition's .lp (its images are "
            "checked: present, undamaged, readable, of one size and kind; a session another "
            "rti-rig run is still capturing is refused until that run ends)."
        ),
    ],
    intensity: Annotated[
        float | None,
        typer.Option(
            "--intensity",
            help="LED drive level for a dome's walk, in (0, 1] (default 0.2). Refused where "
            "nothing can be lit at a chosen level: a replay rig, an arm (its lamp is only "
            "switched on and off), a camera-triggered dome (rti-rig lights none of its LEDs) "
            "and, below 1, a dome whose firmware cannot dim an LED (it lights each fully on).",
        ),
    ] = None,
    reboot_faulted: Annotated[
        bool,
        typer.Option(
            "--reboot-faulted",
            help="Instead of the walk: reboot the arm's servos whose Hardware Error Status is "
            "set (overload …) and whose torque is off, and read their status back. Nothing "
            "moves and no torque is switched on; run check again afterwards.",
        ),
    ] = False,
    park_only: Annotated[
        bool,
        typer.Option(
            "--park-only",
            help="Instead of the walk: connect the arm, switch its lamp off, move it to the "
            "config's park pose and close it as its torque_policy says; nothing else moves. "
            "Ctrl-C stops the park and holds the arm where it is (torque_policy = "
            '"release_on_close": released all the same if it stopped at its park pose). '
            "Refused for a dome or a replay (no park pose).",
        ),
    ] = False,
    auto_exposure: Annotated[
        bool,
        typer.Option(
            "--auto-exposure",
            help="Check the rig for `run --auto-exposure`: \\[camera] exposure_s is then only "
            "where the metering starts, judged as the metering takes it (rounded down to a "
            "UVC camera's whole exposure units; a DSLR starts at its nearest shutter speed), "
            "and a rig that run refuses to meter (a watched folder, a replay, a "
            "camera-triggered dome) is refused.",
        ),
    ] = False,
) -> None:
    """Self-test the rig: a dome lights each LED in turn and reports what answered; an arm
    visits poses spanning its band (checking where it really got to), flashes the lamp at each
    if it hangs on a servo's LED output (lamp = "servo_led"; a "software" lamp is not switched)
    and parks; then the camera is opened and released (no image taken; a tethered DSLR takes
    one test shot, its RAW decoded, so that a RAW the installed LibRaw cannot read is found
    before a session lights anything). A recorded
    acquisition's .lp (a replay rig) has no device: its images are checked instead.

    Exit codes: 0 passed (or RESULT: SENT, NOT VERIFIED, a dome that cannot answer); 1
    RESULT: FAIL; 2 refused or an error; 130 / 143 / 129 stopped by Ctrl-C / SIGTERM / a
    hang-up (SIGHUP: the terminal or ssh connection closed; torn down as for SIGTERM)."""
    from rti_rig.app.usecases.check import CheckRequest, CheckStopped, check_rig
    from rti_rig.runtime.controller import EmergencyStop

    if park_only:
        from rti_rig.app.usecases.park import refuse_park_only_with

        given = [
            words
            for words, on in (
                (["--reboot-faulted"], reboot_faulted),
                (["--intensity", str(intensity)], intensity is not None),
                (["--auto-exposure"], auto_exposure),
            )
            if on
        ]
        if given:
            try:
                refuse_park_only_with(rig_config, given)
            except RtiRigError as exc:
                raise fail(exc) from None
        _park_only(rig_config)
        return
    if reboot_faulted:
        _reboot_faulted(rig_config)
        return

    def announce() -> None:
        out.print(f"Checking {escape(shown_path(rig_config))} (Ctrl-C stops the check at once)…")

    try:
        with stop_on_signals():
            report = check_rig(
                CheckRequest(rig_config, intensity, auto_exposure),
                announce,
                # a dome's lost port, reopened during the walk: said as it happens
                lambda text: err.print(text, markup=False, highlight=False),
            )
    except CheckStopped as exc:
        _said_stopped("Check", exc)
    except EmergencyStop as exc:  # stopped outside a self-test (loading, a camera's check)
        err.print(f"[red]Check stopped ({escape(str(exc))}):[/] check the rig's lights.")
        raise typer.Exit(code=stop_exit_code(exc.signum)) from None
    except RtiRigError as exc:
        raise fail(exc) from None
    _said_report(report)


def _reboot_faulted(rig_config: Path) -> None:
    """``check --reboot-faulted``: print what the reboot established; exit 1 if a fault is
    left."""
    from rti_rig.app.usecases.check import reboot_faulted

    def looking() -> None:
        shown = escape(shown_path(rig_config))
        out.print(f"Looking for faulted servos on {shown}'s arm (nothing moves)…")

    try:
        report = reboot_faulted(rig_config, on_start=looking)
    except RtiRigError as exc:
        raise fail(exc) from None
    _said_report(report)


def _park_only(rig_config: Path) -> None:
    """``check --park-only``: park the arm, say where it was left (read back); exit 1 unless
    it parked, as a stop's code after a Ctrl-C or SIGTERM."""
    from rti_rig.app.usecases.park import ParkStopped, park_arm
    from rti_rig.runtime.controller import EmergencyStop

    def parking() -> None:
        shown = escape(shown_path(rig_config))
        out.print(f"Parking {shown}'s arm (Ctrl-C stops it where it is)…")

    try:
        with stop_on_signals():
            report = park_arm(rig_config, on_start=parking)
    except ParkStopped as exc:
        _said_stopped("Park", exc)
    except EmergencyStop as exc:  # before anything was built (loading the config)
        err.print(f"[red]Park stopped ({escape(str(exc))}):[/] nothing was sent to the arm.")
        raise typer.Exit(code=stop_exit_code(exc.signum)) from None
    except RtiRigError as exc:
        raise fail(exc) from None
    _said_report(report)


def _said_report(report: _Report) -> None:
    """Print a check's, reboot's or park's report line by line, as written (a message may quote
    ``[a.table]``, which rich markup would eat), and exit 1 unless it ended well."""
    for line in report.lines():
        out.print(line, highlight=False, markup=False)
    if not report.ok:
        raise typer.Exit(code=1)


def _said_stopped(what: str, exc: CheckStopped) -> NoReturn:
    """Say a stopped check's or park's end (``what``: ``Check``, ``Park``) and exit as the stop
    does: what the walk had verified before it (a check stopped at pose 6 of 8 had said only
    that it had stopped), the teardown's failures, what is known of the lights, and the
    command that parks an arm left unparked."""
    for line in exc.walk:
        out.print(line, highlight=False, markup=False)
    for failure in exc.teardown_failures:
        err.print(f"[red]teardown problem:[/] {escape(failure)}")
    err.print(f"[red]{what} stopped ({escape(exc.why)}):[/] {escape(exc.lights)}.")
    if exc.todo:
        err.print(exc.todo + ".", highlight=False, markup=False)
    raise typer.Exit(code=stop_exit_code(exc.signum)) from None


def _probe_stopped(why: str, signum: signal.Signals, result: ProbeResult) -> NoReturn:
    """Say what a stopped probe heard and found and what is known of the lights (the stop
    named by ``why``); exit as a stop by ``signum`` does."""
    for line in result.heard_lines():
        out.print(line, highlight=False, markup=False)
    if result.profile is not None:
        out.print(f"Found: {result.profile}. Rig-config lines to use:", highlight=False)
        for line in result.config_lines():
            out.print("  " + line, highlight=False, markup=False)
    err.print(f"[red]Probe stopped ({escape(why)}):[/] {escape(result.lights)}.", highlight=False)
    raise typer.Exit(code=stop_exit_code(signum)) from None


@app.command()
def probe(
    port: Annotated[str, typer.Argument(help="Serial port of the dome, e.g. /dev/ttyACM0.")],
    rig: Annotated[
        Path | None,
        typer.Option(
            "--rig",
            help="The rig config you will put the printed lines in: what to do next is then "
            "said as a check command of it, to paste (nothing is read from it or written).",
        ),
    ] = None,
) -> None:
    """Identify which known dome firmware answers on PORT (least intrusive probes first; none
    lights an LED, and a dome that boots lit is switched off, or you are told it could not be
    and the probe exits 1) and print the rig-config lines to use. Ctrl-C stops the probe after
    switching off a dome that booted lit, and says what is known of the lights. Exits 1 too
    when the firmware found cannot be used as it is (a banner rti-rig refuses), as its check
    would fail."""
    from rti_rig.app.usecases.probe import ProbeRequest, ProbeResult, ProbeStopped
    from rti_rig.app.usecases.probe import probe as run_probe
    from rti_rig.runtime.controller import EmergencyStop

    # filled by the probe: what it established, whenever a stop lands
    result = ProbeResult(port, rig=None if rig is None else str(rig))

    def trying(what: str, tries: str) -> None:
        # on stderr as it goes: a port where nothing answers takes over 20 s, which the
        # command had spent in silence
        err.print(f"Trying {tries or what} ({what})…", highlight=False, markup=False)

    result.on_try = trying
    try:
        with stop_on_signals():
            run_probe(ProbeRequest(port), result=result)
    except ProbeStopped as exc:
        _probe_stopped(exc.why, exc.signum, exc.result)
    except EmergencyStop as exc:
        # after the probe returned (its teardown done, its lights said in the result), or
        # before it began (nothing opened): it had said "look at the dome's lights" even after
        # an all-off the board acknowledged
        _probe_stopped(str(exc), exc.signum, result)
    for line in result.heard_lines():
        out.print(line, highlight=False, markup=False)
    if result.error is not None:
        # on stderr, unwrapped, as every other command says an error (it had gone to stdout,
        # wrapped mid-message when piped)
        said = escape(str(result.error))
        err.print(f"[bold red]error:[/] {said}", highlight=False, soft_wrap=True)
    for line in result.conclusion_lines():
        out.print(line, highlight=False, markup=False)
    if result.profile is None or result.error is not None or result.unusable is not None:
        # a port that failed after the firmware was found (a Nab board whose all-off could
        # not be sent, possibly fully lit) had exited 0, as a probe that succeeded
        raise typer.Exit(code=1)
