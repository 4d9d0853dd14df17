"""`rti-rig run`, `preview` and `export-lp`: sessions, through :mod:`rti_rig.app.usecases.session`.

The commands parse, call the use case and print; what is interactive lives here: the signal
handlers (Ctrl-C, SIGTERM, SIGUSR1), the progress bar and the closing messages.
"""

from __future__ import annotations

import signal
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass, replace
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any

import typer
from rich.markup import escape
from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn

from rti_rig.app.usecases.next_fit import fit_model_for, next_fit, next_step
from rti_rig.cli.app import (
    FILE,
    app,
    err,
    fail,
    option_given,
    out,
    parse_az_el,
    print_note,
    shell_word,
    shown_path,
    stop_exit_code,
)
from rti_rig.cli.stopping import Terminated, sigterm_stops, stamp, stop_signal, written_since
from rti_rig.core.deferred_signals import (
    as_received,
    default_action,
    handlers_settable,
    hangup_as_sigterm,
    put_back,
    signal_handlers,
    stop_words,
    within_after_a_stop,
)
from rti_rig.core.errors import RtiRigError

# the help's figures (numpy-free)
from rti_rig.core.fit_minimums import FIT_MINIMUMS, NORMAL_ERROR_LIMIT_DEG, NORMAL_NOISE
from rti_rig.core.out_folders import file_beside, fit_beside, free_folder_beside, free_name

if TYPE_CHECKING:
    from rti_rig.app.usecases.session import OpenedSession
    from rti_rig.runtime.run_ending import RunEnding

#: ``--max-saturated`` of ``run`` and ``preview``: None when not given (only metering reads it,
#: so it is refused without ``--auto-exposure``: :func:`refuse_unmetered_limit`).
MaxSaturatedOption = Annotated[
    float | None,
    typer.Option(
        "--max-saturated",
        help="With --auto-exposure: the largest fraction of saturated pixels its metering "
        "allows (default 0.001, 0.1 %).",
    ),
]


@app.command()
def run(
    ctx: typer.Context,
    rig_config: Annotated[
        Path | None,
        typer.Argument(
            help="Rig config TOML (see rig_configs/), e.g. rig_configs/simulated_dome.toml, "
            "or a recorded acquisition's .lp with its images beside it, replayed as a rig "
            "(docs/adaptive.md, 'The replay rig'). "
            "Optional with --resume (the session's own config is used)."
        ),
    ] = None,
    out_dir: Annotated[
        Path | None, typer.Option("--out", help="New or empty folder to write the session into.")
    ] = None,
    lights: Annotated[
        int | None,
        typer.Option(
            "--lights",
            help="Number of lights in a homogeneous layout (default: every LED of a dome, "
            "the arm's default_lights, or every image of a recorded acquisition's .lp). At "
            f"least 1; below {FIT_MINIMUMS.rti_file} a note says, before anything "
            "lights, what `rti-rig fit` will not make of them (no fit.ptm or fit.rti; below "
            f"{FIT_MINIMUMS.normal} no fit at all). "
            "A camera-triggered dome (\\[dome.flash_sync]) refuses any number but all of its "
            "LEDs: its firmware lights them in its own order.",
        ),
    ] = None,
    plan: Annotated[
        Path | None,
        typer.Option("--plan", help="Run this plan (.lp from 'rti-rig plan') instead."),
    ] = None,
    min_elevation_deg: Annotated[
        float,
        typer.Option(
            "--min-elevation-deg",
            help="Elevation floor of the lights: of the homogeneous layout, or of every light "
            "an adaptive session (--adaptive/--until-error) may choose.",
        ),
    ] = 0.0,
    max_elevation_deg: Annotated[
        float,
        typer.Option(
            "--max-elevation-deg",
            help="Elevation ceiling of the lights, as --min-elevation-deg (90 = up to the "
            "zenith; 60 keeps lights away from the camera axis, see 'plan "
            "--max-elevation-deg').",
        ),
    ] = 90.0,
    auto_exposure: Annotated[
        bool,
        typer.Option(
            "--auto-exposure",
            help="Before starting, meter at the brightest planned light (a short test series) "
            "and fix the exposure that keeps saturated pixels under --max-saturated. On a dome "
            "with no light calibration applied, whose LEDs may differ, the 6 planned lights a "
            "level object receives most from are checked (one more test shot each at least).",
        ),
    ] = False,
    max_saturated: MaxSaturatedOption = None,
    resume: Annotated[
        Path | None,
        typer.Option(
            "--resume",
            help="Continue an interrupted session folder: verify what is on disk and capture "
            "only the steps not yet done (on the rig the session began on). The options the "
            "session began with (--out DIR, --lights, --plan, --adaptive …) may be given "
            "again: they must be its own. A session already complete, every image intact, "
            "is said so (exit 0).",
        ),
    ] = None,
    accept_rig_change: Annotated[
        bool,
        typer.Option(
            "--accept-rig-change",
            help="With --resume: go on although the rig's lights differ from the session's (a "
            "repaired LED, recalibrated positions); the change is recorded in the manifest. "
            "A change to the images (exposure, gain, size, decoding, camera, a dry run's "
            "scene) is refused.",
        ),
    ] = False,
    reshoot_lost: Annotated[
        bool,
        typer.Option(
            "--reshoot-lost",
            help="With --resume on a session that completed: reshoot exactly the images whose "
            "JPEG or linear TIFF was lost or changed since capture, or whose RAW original "
            "(raw/) was lost or changed (the QA verdict names them), with the object where it "
            "was; their files are set aside in recovered/, never deleted.",
        ),
    ] = False,
    reshoot: Annotated[
        list[str] | None,
        typer.Option(
            "--reshoot",
            metavar="IMAGE",
            help="With --resume on a session that completed: reshoot these images too, their "
            "files intact (those the QA verdict names misfired, wrong light or moved, with the "
            "object where it was): image_006, or several with commas (image_006,image_009); "
            "their files are set aside in recovered/, never deleted. Not for an adaptive "
            "session, whose later lights were chosen from its images.",
            show_default=False,
        ),
    ] = None,
    rebuild_journal: Annotated[
        bool,
        typer.Option(
            "--rebuild-journal",
            help="With --resume on a session whose journal.jsonl is lost or damaged: rebuild it "
            "from manifest.json and the journal's intact lines, taking back only the images "
            "whose files match their recorded checksums and whose light is their step's; the old "
            "journal and every other image file are set aside in recovered/, never deleted. A "
            "completed session is rebuilt without the rig: an image whose files alone are not "
            "as recorded is recorded as lost (its files set aside), for --reshoot-lost.",
        ),
    ] = False,
    adaptive: Annotated[
        bool,
        typer.Option(
            "--adaptive",
            help="Choose each next light from the images captured so far (up to --lights; "
            "docs/adaptive.md).",
        ),
    ] = False,
    until_error: Annotated[
        float | None,
        typer.Option(
            "--until-error",
            help="Adaptive: stop once the upper estimate of the mean normal error (the larger of "
            "the estimate × a factor calibrated on the simulator and a bound from the residuals "
            "of the pixels the fit does not explain, plus 90° × the share of pixels the images "
            "leave unsolved, read at the camera's resolution; lamps near the object "
            "rendered where the config's \\[lamps] or scene puts them, docs/adaptive.md) is at "
            "most this many degrees (with --lights: "
            "whichever comes first). Without --lights the disk must hold its starting lights "
            "(or --min-lights) before it starts; the rest is checked image by image (a "
            "session the disk stops is kept: --resume).",
        ),
    ] = None,
    min_lights: Annotated[
        int | None,
        typer.Option(
            "--min-lights",
            help="With --until-error: shoot at least this many lights before the stop may "
            "claim the target (a PTM needs 6, an HSH fit.rti 5; without it a session "
            "that reaches its target early has a normal map and no RTI). The stop is first "
            "judged after the 4 starting lights, so a minimum holds it from 5 (4 or less is "
            "said to hold nothing).",
        ),
    ] = None,
    objective: Annotated[
        str | None,
        typer.Option(
            "--objective",
            help="Adaptive with --lights N: choose the design for 'normals' (default: the "
            "simulated normal error) or 'relight' (the simulated relighting PSNR on the lights "
            "left out). --until-error is a normals criterion: refused with 'relight'. With "
            "--resume: must be the session's own.",
        ),
    ] = None,
    allow_no_normals: Annotated[
        bool,
        typer.Option(
            "--allow-no-normals",
            help="Capture lights that cannot determine a surface normal (all in one plane "
            "through the object, e.g. one azimuth for raking-light documentation, or bunched "
            f"at the zenith, or normals predicted more than {NORMAL_ERROR_LIMIT_DEG:g}° off at "
            f"{NORMAL_NOISE:.0%} image noise) with a "
            "warning, in place of the refusal. rti-rig fit then writes no normal maps, and "
            "its relighting files are ridge-regularised guesses along the direction the "
            "lights miss.",
        ),
    ] = False,
    no_verdict: Annotated[
        bool, typer.Option("--no-verdict", help="Do not print the QA verdict at the end.")
    ] = False,
) -> None:
    """Run a capture session: a dry run on a simulated or emulated rig or a recorded
    acquisition's .lp, the real rig otherwise.

    Ctrl-C once stops after the current image (before it, its light left off, while a busy
    camera is awaited in the dark); Ctrl-C twice or SIGTERM stops at once (lights off, arm
    stopped, and parked if the config says park_on_emergency_stop = true); during an arm's
    final park, a Ctrl-C or SIGTERM stops the arm where it is, held (torque on; with
    torque_policy = "release_on_close" the close then releases an arm it finds at its park
    pose, and the run says so, as after a park). A stop while the dome connects first
    switches the dome off, once its board has booted (a few seconds; a further Ctrl-C waits
    for it): opening its port may have reset a board that boots lit.
    SIGUSR1 pauses or resumes between images. An interrupted session can be continued with
    --resume. Exit 130 after a Ctrl-C stop, 143 after a SIGTERM, also one that comes while a
    stop or an error is being reported (the report is finished first) or while the QA verdict
    of a complete session is computed (the session stays complete; rti-rig fit gives it).

    Exit codes: 0 the session is complete, whatever its QA verdict (advice: rti-rig fit writes
    it to qa.json); 1 complete, but the rig was not brought to a known safe state, or a fault
    rti-rig did not name; 2 refused (bad input, --out not empty, too little disk, the session
    or the dome's port in use) or an error during the capture (a device fault, a failed
    write: the images so far kept; manifest.json's runner.finish_reason says which); 130 /
    143 stopped; 129 a hang-up (SIGHUP: the terminal or ssh connection closed), stopped as
    by SIGTERM (docs/guide.md, section 11).
    """
    from rti_rig.app.usecases.session import (
        NewSessionRequest,
        ResumeRequest,
        open_new_session,
    )

    if resume is not None:
        from rti_rig.app.usecases.resume_request import StartOptions

        if out_dir is not None and not _same_folder(out_dir, resume):
            raise fail(
                RtiRigError(
                    f"--out {shown_path(out_dir)} and --resume {shown_path(resume)} are two "
                    "folders: a resume continues the session in --resume's; drop --out (or give "
                    "the same folder)"
                )
            )
        given = [
            flag
            for flag, value in (
                ("--plan", plan is not None),
                ("--lights", lights is not None),
                ("--adaptive", adaptive),
                ("--until-error", until_error is not None),
                ("--min-lights", min_lights is not None),
                ("--auto-exposure", auto_exposure),
                ("--max-saturated", max_saturated is not None),
                ("--min-elevation-deg", min_elevation_deg != 0.0),
                ("--max-elevation-deg", max_elevation_deg != 90.0),
                ("--allow-no-normals", allow_no_normals),
            )
            if value
        ]
        # the options that began the session, given again (a script's same line): compared
        # with what its manifest records once the rig config is read (they had been refused
        # outright, "drop --lights", the identical request as much as another)
        start = (
            StartOptions(
                lights=lights,
                plan=plan,
                adaptive=adaptive,
                until_error_deg=until_error,
                min_lights=min_lights,
                auto_exposure=auto_exposure,
                max_saturated=max_saturated,
                min_elevation_deg=min_elevation_deg,
                max_elevation_deg=max_elevation_deg,
                allow_no_normals=allow_no_normals,
                objective=objective,
                given=tuple(given),
            )
            if given
            else None
        )
        resume_request = ResumeRequest(
            resume,
            rig_config,
            accept_rig_change=accept_rig_change,
            objective=objective,
            reshoot_lost=reshoot_lost,
            reshoot=tuple(reshoot or ()),
            rebuild_journal=rebuild_journal,
            start=start,
        )
        if _rebuilt_finished(resume_request):  # a completed session: no rig, nothing to shoot
            return

    # SIGUSR1 said to be ignored from here, not only once the capture is over: one that came
    # while the rig opened (an emulator starting, metering with the rig lit) had ended the
    # process at once, exit 138, no word and no all-off
    def open_new() -> Any:
        if rig_config is None or out_dir is None:
            raise RtiRigError("give a RIG_CONFIG and --out DIR (or --resume SESSION_DIR)")
        if accept_rig_change:
            raise RtiRigError("--accept-rig-change goes with --resume SESSION_DIR only")
        if reshoot_lost:
            raise RtiRigError("--reshoot-lost goes with --resume SESSION_DIR only")
        if reshoot:
            raise RtiRigError("--reshoot goes with --resume SESSION_DIR only")
        if rebuild_journal:
            raise RtiRigError("--rebuild-journal goes with --resume SESSION_DIR only")
        refuse_unmetered_limit(max_saturated, auto_exposure, adaptive or until_error is not None)
        return open_new_session(
            NewSessionRequest(
                rig_config,
                out_dir,
                lights=lights,
                plan=plan,
                min_elevation_deg=min_elevation_deg,
                max_elevation_deg=max_elevation_deg,
                min_elevation_given=option_given(ctx, "min_elevation_deg"),
                max_elevation_given=option_given(ctx, "max_elevation_deg"),
                auto_exposure=auto_exposure,
                **_metering_limit(max_saturated),
                adaptive=adaptive,
                until_error_deg=until_error,
                objective=objective,
                min_lights=min_lights,
                allow_no_normals=allow_no_normals,
            ),
            print_note,
        )

    if resume is not None:
        opening = _Opening(
            lambda: _open_resumed(resume_request, print_note),
            out_dir,
            auto_exposure,
            stopped=lambda why, _exc: (
                f"Stopped ({why}) before the session went on: no new image was captured; "
                f"continue it with {_resume_command(resume_request)}"
            ),
            not_opened=(
                "The session did not go on: no new image was captured; continue it with "
                f"{_resume_command(resume_request)} once this is fixed"
            ),
        )
    else:
        opening = _Opening(
            open_new,
            out_dir,
            auto_exposure,
            stopped=lambda why, _exc: (
                f"Stopped ({why}) before the first image: nothing was captured or written to "
                f"{shown_path(out_dir)}"
            ),
            not_opened=f"Nothing was captured or written to {shown_path(out_dir)}",
        )
    with hangup_as_sigterm(), _late_pause_ignored(), _late_term_held() as late_term:
        with _sigterm_exit_wins(late_term):
            opened, handover = _open_for_capture(opening)
            unsafe = _execute(opened, handover)
        # a SIGTERM held as the summary printed, or a second Ctrl-C once the capture had
        # ended (it stopped no image: the manifest keeps the capture's end, "completed")
        late = late_term[0] if late_term else opened.stopped_once_over
        if late is not None:  # the summary is out; the verdict, not computed, is fit's to give
            _refuse_unsafe_end(unsafe, opened.rig, exit_code=None)
            err.print(
                f"[yellow]Stopped ({stop_words(late)}) once the session had ended: it "
                "is complete; its QA "
                "verdict was not computed:[/] "
                f"{escape(fit_beside(opened.out_dir))} gives it",
                soft_wrap=True,
            )
            raise typer.Exit(code=stop_exit_code(late))
        # the verdict is not computed: the stop asked for no more
        _exit_if_park_stopped(
            opened,
            unsafe,
            "the session",
            "; its QA verdict was not computed:",
            f" {escape(fit_beside(opened.out_dir))} gives it",
        )
        if not no_verdict:
            from rti_rig.cli.fit import print_verdict, verdict_skipped

            try:
                with _verdict_terminable():
                    try:
                        print_verdict(opened.out_dir)
                    except typer.Exit:
                        # a Ctrl-C or SIGTERM said by the verdict: its exit (130 or 143),
                        # after the unsafe end's words, which that exit had skipped
                        _refuse_unsafe_end(unsafe, opened.rig, exit_code=None)
                        raise
                    except Exception as exc:
                        _verdict_failed(exc, opened.out_dir)
            except (KeyboardInterrupt, Terminated) as exc:
                # a stop as the verdict's handlers went in, before its own try (CI met it
                # once: "rti-rig: stopped (Ctrl-C)", the verdict's words unsaid)
                _refuse_unsafe_end(unsafe, opened.rig, exit_code=None)
                raise verdict_skipped(exc, opened.out_dir) from None
        _refuse_unsafe_end(unsafe, opened.rig)
        _say_next(opened.out_dir)


def _say_next(session: Path) -> None:
    """The last line of a finished run: the fit that makes its normal map, ``.ptm`` and
    ``.rti``, as a command that pastes.

    Why: a finished run ended on its QA verdict with no next step, while a resume of the
    same complete session, and every stop of one, named the fit. A session whose labels are
    not verified (a camera-triggered dome's run without its end-of-run proof) gets none: fit
    refuses it, and the run's own words said why."""
    from rti_rig.runtime.disowned import MARKER

    if (session / MARKER).exists():
        return
    out.print(
        f"Next: {escape(next_step(session))}",
        soft_wrap=True,
        highlight=False,
    )


def _same_folder(a: Path, b: Path) -> bool:
    """Whether ``a`` and ``b`` name one folder (``--out S --resume ./S``)."""
    try:
        return a.resolve() == b.resolve()
    except OSError:
        return False


def _rebuilt_finished(req: Any) -> bool:
    """``run --resume DIR --rebuild-journal`` of a session that completed: its journal rebuilt
    with no rig opened (:func:`~rti_rig.app.usecases.session.rebuild_finished_session`), what
    was done said, and the next command named. False when the request is no such rebuild (the
    resume goes on as ever).

    Why: a completed session whose journal was lost (a copy that skipped it) was refused ("for a
    session that did not finish"), with no way to make it whole again. A Ctrl-C or SIGTERM
    while the images are checked leaves the folder as it was; one while the journal is written
    is acted on once it is, and said so."""
    from rti_rig.app.usecases.session import Note, rebuild_finished_session
    from rti_rig.runtime.session import JOURNAL, lost_since_capture_said

    folder = _arg(req.session_dir)

    def stopped(why: str, exc: BaseException) -> str:
        done = getattr(exc, "journal_rebuild", None)
        if not done:
            return (
                f"Stopped ({why}) before {JOURNAL} was rebuilt: nothing in {folder} was "
                f"changed; run rti-rig run --resume {folder} --rebuild-journal again"
            )
        for line in done:
            print_note(Note(line, "warning"))
        lost = lost_since_capture_said(req.session_dir)
        return f"Stopped ({why}) once {JOURNAL} was rebuilt: " + (
            f"the session is whole again; {fit_beside(req.session_dir)} fits it "
            "and gives its QA verdict"
            if lost is None
            else f"{lost}; meanwhile {fit_beside(req.session_dir)} fits the rest"
        )

    # the opening's answers, shared with run and preview: this third copy had lacked the one
    # to a fault no part of rti-rig named, which reached the user as a traceback
    notes, _ = _open_for_capture(
        _Opening(
            lambda: rebuild_finished_session(req),
            req.session_dir,
            False,
            stopped,
            not_opened=(
                f"The rebuild of {JOURNAL} in {folder} stopped on that fault; run rti-rig run "
                f"--resume {folder} --rebuild-journal again once it is fixed"
            ),
            capture=False,
        )
    )
    if notes is None:
        return False
    for line in notes:
        print_note(Note(line, "warning"))
    lost = lost_since_capture_said(req.session_dir)
    if lost is not None:  # recorded as lost: said with the command that reshoots it
        out.print(
            f"{shown_path(req.session_dir)}: {JOURNAL} rebuilt from every image it could prove (no "
            f"rig was opened, nothing was shot), but the session is not whole: {lost}; meanwhile "
            f"{fit_beside(req.session_dir)} fits it, its QA verdict naming what is lost",
            highlight=False,
            markup=False,
        )
        return True
    out.print(
        f"{shown_path(req.session_dir)}: {JOURNAL} rebuilt; the session is complete and whole "
        f"again (no rig was opened, nothing was shot). Next: {next_fit(req.session_dir)} "
        "fits it and gives its QA verdict",
        highlight=False,
        markup=False,
    )
    return True


def _metering_limit(max_saturated: float | None) -> dict[str, float]:
    """The request's ``max_saturated`` where the option was given (else its default)."""
    return {} if max_saturated is None else {"max_saturated": max_saturated}


def refuse_unmetered_limit(
    max_saturated: float | None, auto_exposure: bool, adaptive: bool = False
) -> None:
    """``--max-saturated`` without ``--auto-exposure`` is refused: only metering reads it, so
    it had been accepted and ignored, the config's exposure used as it is (an option that
    does nothing must not look as if it did). In an adaptive session (``adaptive``), which
    cannot meter, the remedy is to drop it: "add --auto-exposure" led to a second refusal."""
    if max_saturated is not None and not auto_exposure:
        if adaptive:
            raise RtiRigError(
                f"--max-saturated {max_saturated:g} sets how much --auto-exposure's metering "
                "lets clip, and an adaptive session cannot meter (its lights are chosen as the "
                "images arrive): the config's exposure is used as it is; drop --max-saturated"
            )
        raise RtiRigError(
            f"--max-saturated {max_saturated:g} sets how much --auto-exposure's metering lets "
            "clip; without --auto-exposure the config's exposure is used as it is: add "
            "--auto-exposure, or drop --max-saturated"
        )


def _opening_failed(exc: RtiRigError, out_dir: Path | None) -> typer.Exit:
    """The exit for an error while the rig opened (before any image): where metering had lit
    the rig, the lights' state is said first, with nothing captured or written."""
    state = exc.lights_state
    if state is not None:
        err.print(
            f"{_sentence(state)}; nothing was captured or written to {shown_path(out_dir)}.",
            markup=False,
        )
    return fail(exc)


def _stopped_while_opening(
    exc: BaseException, why: str, said: str, auto_exposure: bool
) -> typer.Exit:
    """Say a stop (Ctrl-C, SIGTERM) that came while the session opened, and what metering's
    teardown established of the lights if it was metering; the exit a stop by ``why`` asks."""
    from rti_rig.app.usecases.safe_state import lights_state_of

    _print_metering_failures(exc)
    state = lights_state_of(exc)
    if state is not None:  # stopped while metering: what its teardown established
        said += f"; metering was stopped, and then: {state}"
    elif auto_exposure:
        said += (
            "; metering, if it had begun, attempted an all-off on its way out: check the rig's "
            "lights"
        )
    err.print(f"[yellow]{escape(said)}.[/]")
    return typer.Exit(code=stop_exit_code(stop_signal(exc)))


def _print_metering_failures(exc: BaseException) -> None:
    """What metering's teardown could not do, carried by the error or stop that ended it: each
    that leaves the lights in doubt as a teardown problem; a port that did not close cleanly
    (said as it happened, by the dome's own line) as being in no record, which it is: the
    session's record is written only once the capture begins (it had been said as a teardown
    problem, or not kept at all)."""
    from rti_rig.runtime.exposure_policy import teardown_failures_of
    from rti_rig.runtime.lighting import unsafe_failures

    failures = teardown_failures_of(exc)
    unsafe = unsafe_failures(failures)
    # those the error names itself (metering that could not make the rig safe) said once
    _print_failures([f for f in unsafe if str(f) not in str(exc)])
    if len(unsafe) < len(failures):
        _unrecorded_port_close("metering ended before the session began, so none was written")


def _unrecorded_port_close(why: str) -> None:
    """Say that the port's close failure said above is kept in no session record (``why``:
    how that came about), rather than make up a record for it."""
    err.print(f"[yellow]note:[/] the port's close failure above is in no session record: {why}.")


@dataclass(frozen=True)
class _Opening:
    """How ``run`` or ``preview`` opens its session (``open``, which returns it) and what it
    says when the opening does not end in a session: ``stopped(why, exc)`` for a Ctrl-C or
    SIGTERM, ``not_opened`` for a fault no part of rti-rig named. ``capture``: a capture
    follows, which answers a stop from the end of the opening on (False for the rebuild of a
    finished session's journal: nothing follows it to answer one)."""

    open: Callable[[], Any]
    out_dir: Path | None
    auto_exposure: bool
    stopped: Callable[[str, BaseException], str]
    not_opened: str
    capture: bool = True


def _open_for_capture(opening: _Opening) -> tuple[Any, HandOver]:
    """Open the session with a SIGTERM answered as a stop, then hold stops for the capture;
    whatever ends the opening instead is said (metering's teardown failures and the lights'
    state with it) and becomes the command's exit, never a traceback.

    One place for ``run`` and ``preview``: they had two copies of this, and the preview's
    lacked two of the run's answers (an unnamed fault while it opened reached the user as a
    traceback, and metering's teardown failures went unsaid on an error)."""
    from rti_rig.app.usecases.safe_state import lights_state_of
    from rti_rig.runtime.controller import EmergencyStop
    from rti_rig.runtime.session import SessionComplete

    try:
        with _terminable_while_opening() as handover:
            opened = opening.open()
            if opening.capture:
                handover.hold()  # a stop from here on: the capture answers it
    except SessionComplete as exc:
        # a resume of a complete, intact session (a script's same line after a run that did
        # finish): no error, and the next step said (it had been exit 2, with none)
        model = fit_model_for(exc.root) if exc.root is not None else ""
        out.print(f"{exc}. Next: {exc.next_step}{model}", markup=False)
        raise typer.Exit(code=0) from None
    except RtiRigError as exc:
        _print_metering_failures(exc)
        raise _opening_failed(exc, opening.out_dir) from None
    except (KeyboardInterrupt, EmergencyStop) as exc:
        # while the rig opens (an emulator starting, a dome's handshake, metering): the exit
        # had been 130 with no word at all (a SIGTERM's 143, with no all-off either)
        why = "Ctrl-C" if isinstance(exc, KeyboardInterrupt) else str(exc)
        said = opening.stopped(why, exc)
        raise _stopped_while_opening(exc, why, said, opening.auto_exposure) from None
    except Exception as exc:  # no part of rti-rig named it: said, not a traceback
        _print_metering_failures(exc)
        said = opening.not_opened
        state = lights_state_of(exc)
        if state is not None:  # metering failed: what its teardown established
            said += f"; metering failed, and then: {state}"
        elif opening.auto_exposure:
            said += (
                "; metering, if it had begun, attempted an all-off on its way out: check the "
                "rig's lights"
            )
        err.print(f"{said}.", markup=False)
        raise _unexpected(exc, "") from None
    return opened, handover


@contextmanager
def _terminable_while_opening() -> Iterator[None]:
    """A SIGTERM while the session opens raises :class:`~rti_rig.runtime.controller.
    EmergencyStop`, which the opening's own teardown (metering's all-off, the rig's close)
    answers as it answers a Ctrl-C; the command then says so and exits 143.

    Why: SIGTERM (a service manager, ``timeout``, a lab's scheduler) while an emulator started,
    a dome handshook or metering had an LED lit met the default action: the process ended at
    once, exit 143, no word and no all-off, though ``run --help`` promises "SIGTERM stops at
    once (lights off ...)". The capture installs its own handler (:func:`_run_and_report`)."""
    from rti_rig.runtime.controller import EmergencyStop

    if not handlers_settable():
        yield HandOver()
        return

    def terminated(signum, frame) -> None:  # type: ignore[no-untyped-def]
        raise EmergencyStop(signal.SIGTERM)

    previous = signal.signal(signal.SIGTERM, terminated)
    handover = HandOver({signal.SIGTERM: previous})
    try:
        yield handover
    finally:
        if not handover.holding:
            put_back({signal.SIGTERM: previous})


class HandOver:
    """A SIGTERM or Ctrl-C between the session's opening and its capture: held (recorded),
    not acted on, until the capture's own handlers are in place; the capture then stops the
    session before its first image, the rig closed, and says so.

    Why: the opening's handler was taken away before the capture's were set, and a signal in
    between met the default action: SIGTERM ended the process at once (exit 143), Ctrl-C with
    exit 130, both with no word (a resume had just set unverified files aside in recovered/)
    and the rig never closed."""

    def __init__(self, originals: dict[int, Any] | None = None) -> None:
        #: the handlers before the opening's, by signal (what the capture puts back at its end)
        self.originals: dict[int, Any] = dict(originals or {})
        self.holding = False
        self.held: list[int] = []

    def hold(self) -> None:
        """From now on SIGTERM and SIGINT are recorded, for the capture to act on (main
        thread only)."""
        if not handlers_settable():
            return
        for sig in (signal.SIGINT, signal.SIGTERM):
            # as received: a hang-up answered as a SIGTERM is kept as SIGHUP, named so later
            before = signal.signal(sig, lambda signum, frame: self.held.append(as_received(signum)))
            self.originals.setdefault(sig, before)
        self.holding = True

    def stop(self) -> signal.Signals:
        """The held stop's signal: the first SIGTERM or hang-up (SIGHUP) that came, else
        SIGINT (called once one came)."""
        return next((signal.Signals(s) for s in self.held if s != signal.SIGINT), signal.SIGINT)


@contextmanager
def _verdict_terminable() -> Iterator[None]:
    """A SIGTERM while the QA verdict is computed raises :class:`~rti_rig.cli.stopping.
    Terminated`, which the verdict says as it says a Ctrl-C (the session is complete) before
    exiting 143; it had ended the process with no word. A SIGINT inherited ignored is
    answered as a Ctrl-C, as the capture answers it. (It had its own class, fit's
    ``VerdictTerminated``, a copy of Terminated: the same base, fields and signal kept as
    received; which stop it is follows from the handler installed, not the class.)"""

    def terminated(signum, frame) -> None:  # type: ignore[no-untyped-def]
        raise Terminated(as_received(signum))  # a hang-up's: SIGHUP

    stopped: list[int] = []

    def interrupted(signum, frame) -> None:  # type: ignore[no-untyped-def]
        # once: a second SIGINT while the first is said (a script's repeated kill -INT) had
        # cut the words short with a bare "stopped (Ctrl-C)"
        if not stopped:
            stopped.append(signum)
            raise KeyboardInterrupt

    handlers: dict[int, Any] = {signal.SIGTERM: terminated}
    if handlers_settable() and signal.getsignal(signal.SIGINT) == signal.SIG_IGN:
        # a run started with SIGINT ignored (a script's `run … &`) is stopped by one while it
        # captures, as every run is; the verdict had ignored it, so a `kill -INT` that stopped
        # a capture went unanswered in the seconds of QA that follow. Now it ends the verdict
        # as a Ctrl-C does (exit 130, the command that gives the verdict said); a handler of
        # a caller's own (run called from Python) is left to answer as it chooses
        handlers[signal.SIGINT] = interrupted
    with signal_handlers(handlers):
        yield


@contextmanager
def _late_term_held() -> Iterator[list[signal.Signals]]:
    """A SIGTERM once the capture is over, while its summary prints, recorded (in the list
    yielded, as received: SIGHUP for a hang-up answered as one, so that a real SIGTERM after a
    hang-up is named SIGTERM) rather than acted on at once; a second one ends the process as
    the default would.

    Why: the capture's handlers were undone before its summary printed, and a SIGTERM then (a
    scheduler's ``timeout``) met the default action: exit 143 with no word of the images kept,
    the session's time, the lights' state or how to get the QA verdict, of a session that had
    completed. The summary takes milliseconds; ``run`` then says the verdict was not computed
    and which command gives it, and exits 143. This is the handler every later restore puts
    back (installed before the opening's), so it holds from the capture's end to the run's."""
    held: list[signal.Signals] = []

    def late(signum, frame) -> None:  # type: ignore[no-untyped-def]
        received = as_received(signum)  # a hang-up's: SIGHUP
        if held:  # asked twice: stop now (a summary that hangs must not outlive a stop)
            # the capture's handlers are the ones in place while the rig works: this one
            # answers before the opening or after the teardown, so the words may be waited on
            default_action(received)
        held.append(received)

    with signal_handlers({signal.SIGTERM: late}):
        yield held


@contextmanager
def _sigterm_exit_wins(late_term: list[signal.Signals]) -> Iterator[None]:
    """A run that ends with its own exit (a Ctrl-C stop's 130, an error's 2, an unsafe end's
    1) after a SIGTERM was held while that end was said (``late_term``, from
    :func:`_late_term_held`) exits 143 instead, once what it was saying is out, and says so.

    Why: a SIGTERM in the window where the run reports how its capture ended (the ``except``
    and ``finally`` clauses after a Ctrl-C, a failure's report) was recorded and then lost:
    the run exited 130 or 2, and a service manager or ``timeout`` that sent the SIGTERM was
    told the run had ended on a Ctrl-C or an error of its own. The SIGTERM is the last thing
    asked of the run, so its exit is the one a SIGTERM has everywhere else (143); the stop's
    or the error's words, printed above, still say what happened."""
    try:
        yield
    except typer.Exit as exc:
        late = late_term[0] if late_term else signal.SIGTERM  # SIGTERM, or a hang-up's SIGHUP
        if not late_term or exc.exit_code == stop_exit_code(late):
            raise
        err.print(
            f"[yellow]{stop_words(late)} while the run's end was being said: what is "
            f"said above stands; exit {stop_exit_code(late)} for the "
            f"{stop_words(late)} (not {exc.exit_code}).[/]",
            soft_wrap=True,
        )
        raise typer.Exit(code=stop_exit_code(late)) from None


@contextmanager
def _late_pause_ignored() -> Iterator[None]:
    """SIGUSR1 ignored (and said to be) outside the capture, until the run's last line.

    A SIGUSR1 meant to pause that arrived once the capture was over (while the QA verdict was
    computed) met the default action: the process ended at once, exit 138, the verdict unsaid.
    The capture's own handler (:func:`_run_and_report`) pauses; this one is what it restores."""
    usr1 = getattr(signal, "SIGUSR1", None)
    if usr1 is None:
        yield
        return

    def nothing_to_pause(signum, frame) -> None:  # type: ignore[no-untyped-def]
        err.print("[yellow]SIGUSR1 ignored: a session pauses only while it captures.[/]")

    with signal_handlers({usr1: nothing_to_pause}):
        yield


def _verdict_failed(exc: Exception, session: Path) -> None:
    """A QA verdict that failed in a way the fit did not name (a MemoryError loading a large
    session's images, an OSError from a disk that went away, a fault in the QA), said in one
    line after a session that is complete; the run's exit is left to its end (the verdict is
    advice). Why: such an error escaped ``run`` as a traceback and exit 1 after "6 image(s) in
    the session … lights are off", read as a failed capture of a complete session."""
    what = type(exc).__name__ + (f": {exc}" if str(exc) else "")
    err.print(
        f"[yellow]QA verdict unavailable:[/] unexpected {escape(what)} (a fault that rti-rig "
        "should have named: please report it); the "
        f"session is complete: {escape(fit_beside(session))} gives the "
        "verdict",
        highlight=False,
        soft_wrap=True,
    )


def _unexpected(exc: Exception, report: str) -> typer.Exit:
    """An exception no part of rti-rig named, said in one line (never a traceback), exit 1."""
    err.print(
        f"[bold red]error:[/] unexpected {escape(type(exc).__name__)}: {escape(str(exc))} (a "
        "fault that rti-rig or one of its device drivers should have named: please report it"
        f"{escape(', with ' + report) if report else ''})",
        highlight=False,
        soft_wrap=True,
    )
    return typer.Exit(code=1)


def _resume_command(req: Any) -> str:
    """The ``run --resume`` command of ``req`` (a ResumeRequest) to give again, with the rig
    config and flags it was given.

    Why: a resume stopped before it went on (a Ctrl-C while it checked the images, a rig that
    did not answer) was told to continue with a plain ``rti-rig run --resume DIR``; for a
    journal that needs ``--rebuild-journal``, or a completed session's ``--reshoot-lost``, that
    command is refused, and a rig change not yet accepted would be refused again."""
    words = ["rti-rig run"]
    if req.rig_config is not None:
        words.append(_arg(req.rig_config))
    words.append(f"--resume {_arg(req.session_dir)}")
    if req.accept_rig_change:
        words.append("--accept-rig-change")
    if req.objective is not None:
        words.append(f"--objective {_arg(req.objective)}")
    if req.reshoot_lost:
        words.append("--reshoot-lost")
    if req.reshoot:
        words.append(f"--reshoot {_arg(','.join(req.reshoot))}")
    if req.rebuild_journal:
        words.append("--rebuild-journal")
    return " ".join(words)


def _arg(path: Path | str) -> str:
    """``path`` as one shell word, for a command the user is told to run: a session folder
    with a space in its name ("Object 12 recto") had been printed bare, so the resume hint
    pasted into a shell ran ``--resume Object`` with "12" and "recto" as other arguments."""
    return shell_word(path)  # and as $'...' where a stream cannot print it (shell_word)


def _sentence(text: str) -> str:
    """``text`` with its first letter a capital (a state clause printed as a sentence)."""
    return text[:1].upper() + text[1:]


def _with_min_lights(opened, minimum: int) -> str:  # type: ignore[no-untyped-def]
    """The ``rti-rig run`` that starts this adaptive session again with ``--min-lights
    minimum``: its rig config and the options it began with (the manifest's record, as a
    refused resume repeats them), into a folder beside it that is free now."""
    from rti_rig.app.usecases.replay_advice import session_options

    manifest = dict(opened.folder.manifest)
    manifest["adaptive"] = {**(manifest.get("adaptive") or {}), "min_lights": minimum}
    more = free_folder_beside(Path(opened.out_dir), "more")
    return f"rti-rig run {_arg(opened.rig.loaded.path)} --out {_arg(more)}" + session_options(
        manifest
    )


def _without_lights(opened) -> str:  # type: ignore[no-untyped-def]
    """The ``rti-rig run`` that starts this adaptive session again without its ``--lights``
    (the rig's own maximum), its other options as it began (the manifest's record), into a
    folder beside it that is free now."""
    from rti_rig.app.usecases.replay_advice import session_options

    manifest = dict(opened.folder.manifest)
    manifest["adaptive"] = {**(manifest.get("adaptive") or {}), "design_lights": None}
    more = free_folder_beside(Path(opened.out_dir), "more")
    return f"rti-rig run {_arg(opened.rig.loaded.path)} --out {_arg(more)}" + session_options(
        manifest
    )


def _cannot_resume(opened) -> str | None:  # type: ignore[no-untyped-def]
    """What is said instead of "continue with --resume" of a session this rig cannot resume
    (None: it can): a camera-triggered dome, whose own count went on, or an image-sequence
    camera, read from its first file again by every run (a stopped dry run had been told to
    resume, and the resume gave the remaining lights the pictures of the first ones); it
    shoots again into a folder beside the session that does not exist yet."""
    from rti_rig.runtime.flash_sync import CameraTriggeredLighting
    from rti_rig.runtime.session import image_sequence_restarts

    rig = opened.rig
    again = _arg(free_folder_beside(Path(opened.out_dir), "again"))
    if isinstance(rig.lighting, CameraTriggeredLighting):  # by type, not a getattr probe
        return rig.lighting.resume_hint(_arg(rig.loaded.path), again)
    why = image_sequence_restarts(rig.loaded.config.camera.device, _arg(rig.loaded.path), again)
    return None if why is None else f"It cannot be resumed: {why}."


def _dead_led_hint(opened, exc: BaseException) -> str | None:  # type: ignore[no-untyped-def]
    """How to go on from a stop at an LED the board refused as dead (None: another error).
    A resume lights that LED first and stops there again, so "Continue with: rti-rig run
    --resume" had followed the driver's own "its resume stops there again"."""
    from rti_rig.app.dead_led import dead_led_advice, dead_led_of

    led = dead_led_of(exc)
    if led is None or _cannot_resume(opened):
        return None
    adaptive = opened.source is not None  # its schedule is only its first design
    return dead_led_advice(opened.rig.loaded, opened.schedule, opened.out_dir, led, adaptive)


def _write_failed_said(exc: RtiRigError, opened) -> RtiRigError:  # type: ignore[no-untyped-def]
    """A file the capture could not write, said as the run's last line with what happened to
    the images and the next command; any other error as it is.

    Why: a full disk on a step's record file ended the run with a bare ``error: cannot write
    …/records/image_003.json``, as if the image were lost, though its journal line (which
    commits a step whose record file cannot be written) was on disk; the resume command was
    said only lines above it."""
    from rti_rig.runtime.session import RECORDS_DIR, SessionWriteError, SourceReadError

    kept = opened.folder.images_kept
    if not isinstance(exc, SessionWriteError) or _cannot_resume(opened):
        return exc
    if isinstance(exc, SourceReadError):
        return _source_unread_said(exc, kept, opened)
    if not kept:
        return _first_write_failed_said(exc, opened)
    shot = ""
    if exc.shot:
        # the camera's file(s) of the step the disk refused: whatever of them reached the
        # session is moved to recovered/ by the resume (never deleted), and the light reshot
        shot = (
            f"; this light's shot ({', '.join(exc.shot)}) is not recorded: the resume moves "
            "whatever of it reached the session to its recovered/ folder and shoots this light "
            "again"
        )
    if exc.path.parent.name == RECORDS_DIR:
        what = (
            f"{exc.path.stem} is kept all the same (its journal line, which commits it in "
            "place of that file, was written)"
        )
    else:
        what = f"{kept} image(s) are kept"
    return RtiRigError(
        f"{exc}: the session stopped there; {what}{shot}; {_disk_fix(exc.errno_name)}, then "
        f"continue with {_continue_command(opened)}"
    )


def _source_unread_said(exc: Any, kept: int, opened) -> RtiRigError:  # type: ignore[no-untyped-def]
    """A camera file to keep that could not be read (``exc`` a ``SourceReadError``: a
    replay's acquisition on a drive unplugged mid-run, a file moved or deleted), said with what
    is kept and the resume that takes it up once the file is back.

    Why: it had been said as a failed write of the session's copy ("cannot write
    …/raw/image_003.jpg … check that disk"): the session's disk was fine, and the file that
    could not be read went unnamed."""
    from rti_rig.runtime.session import holds_no_image

    if not kept and holds_no_image(Path(opened.out_dir)):
        # as the stop's own line says of it: the folder is used again by the same command
        return RtiRigError(
            f"{exc}: the session stopped before any image was kept; re-attach the drive that "
            f"holds {shown_path(exc.source)} (or put the file back there), then run the same "
            f"command again ({_arg(opened.out_dir)} holds no image and may be used again)"
        )
    shot = (
        f"; this light's shot ({', '.join(exc.shot)}) is not recorded and the resume shoots "
        "this light again"
        if exc.shot
        else ""
    )
    return RtiRigError(
        f"{exc}: the session stopped there; {kept} image(s) are kept, nothing captured is "
        f"lost{shot}; re-attach the drive that holds {shown_path(exc.source)} (or put the file "
        f"back there), then continue with {_continue_command(opened)}"
    )


def _first_write_failed_said(exc: Any, opened) -> RtiRigError:  # type: ignore[no-untyped-def]
    """A session write the disk refused before any image was kept (``exc`` a
    :class:`SessionWriteError`), said with the disk, its free space, where this light's shot
    is and what the resume does.

    Why: at a later image this was said with what is kept and the shot reshot; at the first
    it ended with a bare ``error: cannot write …/linear/image_001.tif: No space left on
    device``: not on which disk, how much room it had, that the camera's file is still in
    the watched folder, nor that the resume sets aside the copy that reached the session and
    shoots this light again."""
    import shutil

    where = Path(exc.path).parent
    while not where.exists() and where != where.parent:
        where = where.parent
    mount = where.resolve()
    while not mount.is_mount() and mount != mount.parent:
        mount = mount.parent
    try:
        room = shutil.disk_usage(where).free
        size = f"{room / 1e9:.1f} GB" if room >= 1e9 else f"{room / 1e6:.0f} MB"
        free = f"{size} free now"
    except OSError:
        free = "its free space could not be read"
    disk = f"the disk of {_arg(opened.out_dir)} (mounted at {mount}; {free})"
    shot = ""
    if exc.shot:
        names = ", ".join(exc.shot)
        device = opened.rig.loaded.config.camera.device or {}
        folder = device.get("folder") if device.get("kind") == "folder_watch" else None
        watched = Path(str(folder)).expanduser() if folder else None
        still = [n for n in exc.shot if watched is not None and (watched / n).is_file()]
        held = (
            f"; this light's shot ({names}) is not recorded"
            if watched is None
            else f"; this light's shot ({names}) is not recorded; "
            + (
                f"{', '.join(still)} {'is' if len(still) == 1 else 'are'} still in the watched "
                f"folder {watched}, but the resume will not use "
                f"{'it' if len(still) == 1 else 'them'} (a file already in the folder when a "
                "run starts is never taken as a light's image)"
                if still
                else f"it is no longer in the watched folder {watched}"
            )
        )
        shot = (
            f"{held}: the resume moves whatever of it reached the session to its recovered/ "
            "folder and shoots this light again"
        )
    from rti_rig.runtime.session import holds_no_image

    # a folder left holding no image (no camera file reached it) is used again by the same
    # command, as the stop's own line says of it; a camera file that reached it is the
    # resume's to set aside in recovered/
    reused = f"{_arg(opened.out_dir)} holds no image and may be used again"
    then = (
        f"run the same command again ({reused})"
        if not exc.shot and holds_no_image(Path(opened.out_dir))
        else f"continue with {_continue_command(opened)}"
    )
    return RtiRigError(
        f"{exc}: the session stopped before any image was kept, on {disk}{shot}; "
        f"{_disk_fix(exc.errno_name)}, then {then}"
    )


def _disk_fix(errno_name: str) -> str:
    """What to do about a session write the disk refused, by the system's reason."""
    if errno_name in ("ENOSPC", "EFBIG", "EDQUOT"):
        return "free space on that disk (or lift the file-size limit or quota)"
    if errno_name == "EROFS":
        return (
            "make that disk writable again (or copy the session folder to a writable disk and "
            "resume the copy)"
        )
    if errno_name in ("EACCES", "EPERM"):
        # a permission, not the disk: "check that disk" had been said of a session folder
        # another user owns (QA, 2026-12-05)
        return (
            "check that you may write to the session folder and its files (ls -l shows "
            "their owner; run as that user, or copy the folder and resume the copy)"
        )
    return "check that disk"


def _open_resumed(req: Any, on_note: Any) -> Any:
    """Open ``req`` (a ResumeRequest) for capture; a write the disk refuses while it opens is
    said with what to do.

    Why: the resume rewrites ``lights.lp`` (and its journal) as it opens, so a session on
    read-only media (a card or disk mounted read-only, a copy on a DVD) ended with a bare
    ``cannot write …/lights.lp: Read-only file system (EROFS)``: nothing was lost, but the
    user was told neither that nor what to do. A disk too small for the images left is said
    with the command to continue with (it had been told to "choose another --out", which a
    resume refuses)."""
    from rti_rig.app.usecases.session import open_resumed_session
    from rti_rig.runtime.session import NoSpaceError, SessionWriteError

    try:
        return open_resumed_session(req, on_note)
    except NoSpaceError as exc:  # its figures and the images kept, said by the use case
        raise RtiRigError(f"{exc}; then continue with: {_resume_command(req)}") from None
    except SessionWriteError as exc:
        raise RtiRigError(
            f"{exc}: the session did not go on and nothing captured is lost; "
            f"{_disk_fix(exc.errno_name)}, then continue with {_resume_command(req)}"
        ) from None


@dataclass(frozen=True)
class _Stop:
    """A stopped run as its stop wording reads it: the folder's facts (read once, by
    :func:`rti_rig.runtime.run_ending.read_run_ending`) and the run's own (resumed? can this
    rig resume? the resume hint).

    Why: the ~10 outcomes had each read the folder inline inside one long function; each is
    now one row of :data:`_STOP_SAID`, a condition over these facts and its sentence."""

    ending: RunEnding
    out_dir: Path
    resumed: bool
    #: what is said instead of a resume of a session this rig cannot resume (None: it can)
    cannot: str | None
    resume_hint: str

    @property
    def kept(self) -> str:
        """The images kept and where: every stop's wording begins with them, so the user
        knows what is on disk before being told what to do with it."""
        return f"{self.ending.images_kept} image(s) kept in {shown_path(self.out_dir)}"

    @property
    def lp(self) -> str:
        """The session's .lp file name, named where the stop says which lights the images
        are labelled with."""
        # imported here, not at the top: rti_rig.runtime.session loads numpy (through
        # rti_rig.core.image_files), which `rti-rig --help` and the parsing stay free of; no
        # import cycle
        from rti_rig.runtime.session import LP_NAME

        return LP_NAME

    @property
    def unrecorded(self) -> str:
        """What a session whose images are all in has not recorded of its end."""
        if self.ending.adaptive_outcome_unrecorded:
            return "its end and its adaptive outcome (why it stopped, its error estimate)"
        return "its end"

    @property
    def fit_it(self) -> str:
        """The command that fits the images as they are: offered where a resume is not
        possible or not needed, so the user is not left without a next step."""
        return f"`{fit_beside(self.out_dir)}` fits the images as they are"


def _said_disowned(s: _Stop) -> str:
    # a camera-triggered dome's run stopped once its last image was in, before its
    # end-of-run proof frame, was told "the session is complete, nothing is left to resume.
    # Next: rti-rig fit", and fit then refused it as labelled with unverified lights
    return (
        f"{s.kept}, listed in {s.lp}, their labels NOT verified: {s.ending.labels_disowned} says "
        f"why (fit and export-lp refuse this session). {s.resume_hint}"
    )


def _said_end_unrecorded(s: _Stop) -> str:
    # a stop as the last image was committed (its journal line written, the run's end not yet
    # recorded) was told "the session is complete, nothing is left to resume", while its
    # manifest recorded an emergency stop (a stop later, in the teardown or an arm's final
    # park, records "completed" and is not this case): `rti-rig fit` then called it "not
    # finished … continue it with rti-rig run --resume", and an adaptive session's outcome
    # was recorded only by that resume
    head = (
        f"{s.kept}, listed in {s.lp}: every image is in, but the stop came before the run "
        f"recorded {s.unrecorded}, so `rti-rig fit` calls it not finished"
    )
    if s.cannot:  # an image sequence: it had been said complete, fit contradicting
        return f"{head}; {s.fit_it}. {s.cannot}"
    return (
        f"{head}. `rti-rig run --resume {_arg(s.out_dir)}` records it complete without "
        f"shooting anything again; {s.fit_it}"
    )


def _said_stopping_rule(s: _Stop) -> str:
    # an adaptive session that stopped itself short of its maximum (its estimate met
    # --until-error) and was then stopped during its teardown (a second Ctrl-C) was told to
    # "Continue with: rti-rig run --resume", its images counted against the maximum
    n = s.ending.images_kept
    return (
        f"{s.kept}, listed in {s.lp}: the session is complete (its stopping rule ended it at {n} "
        f"of at most {s.ending.total_steps} lights), nothing is left to resume. Next: "
        f"{next_fit(s.out_dir)}"
    )


def _said_complete(s: _Stop) -> str:
    # a SIGTERM or a park stopped in the teardown: "Continue with: rti-rig run --resume" had
    # been said of a complete session, which the resume refused as "already completed"
    return (
        f"{s.kept}, listed in {s.lp}: the session is complete, nothing is left to resume. "
        f"Next: {next_fit(s.out_dir)}"
    )


def _said_lp_unwritten(s: _Stop) -> str:
    # its write failed (a full disk): "listed in lights.lp" had been said of a lights.lp that
    # was missing, or listed fewer images than the folder holds
    listed = s.ending.lp_listed
    state = f"lists only {listed} of them" if listed else "is missing"
    if s.cannot:
        from rti_rig.runtime.session import LP_NAME

        # a file not there yet: the session's own lights.lp where it is missing, else a file
        # beside the session folder (a session's lights.lp is never replaced). It had been
        # lights-2.lp inside the session: relight-cli given the folder reads the first .lp by
        # name, case ignored (export._relight_reads), lights-2.lp before lights.lp, while fit and
        # RTIBuilder read lights.lp: one folder, two listings. '--out FILE.lp' had been
        # printed before that, which pasted wrote a file named FILE.lp
        own = s.out_dir / LP_NAME
        missing = not own.exists()
        lp = _arg(own if missing else file_beside(s.out_dir, ".lp"))
        remedy = f"`rti-rig export-lp {_arg(s.out_dir)} --out {lp}` writes one from the journal"
        if not missing:
            remedy += (
                f", beside the session: its own {LP_NAME} is never replaced, and lights-2.lp "
                "inside it would be the .lp relight-cli reads first"
            )
    else:
        remedy = "the resume writes it again"
    return (
        f"{s.kept}, each journaled with its checksum, but its {s.lp} could not be written and "
        f"{state}: do not open the folder in relight or RTIBuilder before it is whole again "
        f"({remedy}). {s.resume_hint}"
    )


#: What a stopped run says, the first row whose condition holds (the order matters: a
#: complete session's rows come before a merely listed one's). Never a resume hint for
#: nothing: a session with every image in is told what is left (fit, or recording its end).
_STOP_SAID: tuple[tuple[Callable[[_Stop], object], Callable[[_Stop], str]], ...] = (
    (lambda s: s.ending.every_image_in and s.ending.labels_disowned is not None, _said_disowned),
    (lambda s: s.ending.every_image_in and not s.ending.end_recorded, _said_end_unrecorded),
    (lambda s: s.ending.every_image_in and s.ending.stopped_short, _said_stopping_rule),
    (lambda s: s.ending.every_image_in, _said_complete),
    (
        lambda s: s.ending.images_kept and s.ending.lp_whole,
        lambda s: f"{s.kept}, listed in {s.lp}. {s.resume_hint}",
    ),
    (lambda s: s.ending.images_kept, _said_lp_unwritten),
    (lambda s: s.resumed, lambda s: f"No new image was captured. {s.resume_hint}"),
    (
        lambda s: not s.ending.begun,
        lambda s: f"Nothing was captured and nothing was written to {shown_path(s.out_dir)}.",
    ),
    (
        lambda s: s.ending.holds_no_image,
        lambda s: (
            f"Nothing was captured: {shown_path(s.out_dir)} holds no image and may be used again."
        ),
    ),
    # e.g. a camera's file downloaded for a step that then failed: kept, never deleted
    (
        lambda s: True,
        lambda s: (
            f"No image was completed, but {shown_path(s.out_dir)} holds files of the camera. "
            f"{s.resume_hint}"
        ),
    ),
)


def _after_stop(opened, resume_hint: str) -> str:  # type: ignore[no-untyped-def]
    """What a stopped session left on disk and how to go on (never a resume hint for nothing):
    the first row of :data:`_STOP_SAID` that the folder's facts meet."""
    from rti_rig.runtime.run_ending import read_run_ending

    ending = read_run_ending(opened.folder, opened.total_steps)
    cannot = _cannot_resume(opened)
    if _reshoot_not_begun(opened, ending, cannot):
        resume_hint = f"Continue with: {_resume_before_begin(opened, ending)}"
    if opened.folder.put_back:  # a reshoot that never shot: the session as it was
        from rti_rig.app.usecases.session import put_back_said

        return (
            f"{put_back_said(opened.folder.put_back)} To reshoot, once what stopped it is put "
            f"right, the same command: {_resume_before_begin(opened, ending)}"
        )
    stop = _Stop(ending, opened.out_dir, opened.resumed, cannot, resume_hint)
    return next(said(stop) for holds, said in _STOP_SAID if holds(stop))


def _reshoot_not_begun(opened: Any, ending: RunEnding, cannot: str | None) -> bool:
    """Whether ``opened`` is a resume of a completed session (a --reshoot-lost) stopped before
    it wrote anything (``ending``: its folder's facts; ``cannot``: :func:`_cannot_resume`):
    the session is still the completed one, which a plain --resume refuses."""
    if not opened.resumed or ending.begun or cannot:
        return False
    return ending.last_run_completed


def _resume_before_begin(opened: Any, ending: RunEnding | None = None) -> str:
    """The resume command for a resume stopped before it wrote anything: the one the user
    gave (:func:`_resume_command`), or with --reshoot-lost when the session is a completed
    one (:func:`_reshoot_not_begun`; ``ending``: the folder's facts if read already).

    Why: a --reshoot-lost stopped as the capture took over from the opening was told a plain
    ``rti-rig run --resume S``, which refuses a completed session; then ``--resume S
    --reshoot-lost``, without the rig config, --accept-rig-change or --rebuild-journal given
    with it, each of which the resume needs again."""
    from rti_rig.runtime.run_ending import read_run_ending

    if opened.request is not None:
        return _resume_command(opened.request)
    if ending is None:
        ending = read_run_ending(opened.folder, opened.total_steps)
    tail = " --reshoot-lost" if _reshoot_not_begun(opened, ending, _cannot_resume(opened)) else ""
    return f"rti-rig run --resume {_arg(opened.out_dir)}{tail}"


def _continue_command(opened) -> str:  # type: ignore[no-untyped-def]
    """The command to continue ``opened`` with after a stop or failure: a resume's own request
    (its rig config and flags) while this run has written nothing, else its rig config,
    --accept-rig-change and --objective (--reshoot-lost and --rebuild-journal did their work
    once this run began writing); ``--resume DIR`` alone for a new session, whose manifest
    names its config.

    Why: a resume given a rig config (``rti-rig run RIG.toml --resume S``) that failed (an arm
    that did not connect) was told "Continue with: rti-rig run --resume S", without it: the
    manifest's config, not the one the user chose, or a refusal if that one had moved."""
    req = opened.request
    if req is None:
        return f"rti-rig run --resume {_arg(opened.out_dir)}"
    if not opened.folder.begun:
        return _resume_command(req)
    return _resume_command(replace(req, reshoot_lost=False, reshoot=(), rebuild_journal=False))


def _print_teardown_failures(  # type: ignore[no-untyped-def]
    folder, said_below: BaseException | None = None
) -> bool:
    """What could not be made safe when this run stopped early (the controller hands it to the
    folder's ``finish``, not the manifest's, which a resume that never connected leaves with
    the previous run's; the lights' state line that follows refers to it); True if any.
    ``said_below``: the session's error, printed in full after these lines."""
    from rti_rig.runtime.lighting import unsafe_failures

    # a port's close failure was said as it happened (see :func:`_summarise`)
    failures = unsafe_failures((folder.run_end or {}).get("teardown_failures"))
    return _print_failures(failures, said_below)


def _print_stop_failures(  # type: ignore[no-untyped-def]
    opened, said_below: BaseException | None = None
) -> bool:
    """What could not be made safe when this run stopped early, from whichever took the rig
    down: the controller's teardown (:func:`_print_teardown_failures`), or the session's close
    where it made the rig safe in the teardown's place (a stop or a failure before the
    controller's ``try``, :func:`_close_left_open`); True if any. Printed above the lights'
    line that points at them; ``said_below`` as for :func:`_print_failures`.

    Why one helper: every way a capture ends (a stop, a session error, an unexpected fault)
    must say both, in this order; each ``except`` clause had joined them on its own."""
    teardown = _print_teardown_failures(opened.folder, said_below)
    return _print_failures(_close_left_open(opened), said_below) or teardown


def _print_failures(  # type: ignore[no-untyped-def]
    failures, said_below: BaseException | None = None
) -> bool:
    """Each teardown failure on its own line; True if there was any. The explanation of
    ``said_below`` (the error printed after them) is pointed to, not repeated: an arm's servo
    fault met again by the teardown's stop had its paragraph of what to do printed twice, in
    the stop's failure and in the error (the manifest keeps both in full)."""
    from rti_rig.runtime.arm_check import said_once

    detail = getattr(said_below, "message", None)
    for failure in failures or ():
        said = said_once(str(failure), detail, "as in the error below")
        err.print(f"[red]teardown problem:[/] {escape(said)}")
    return bool(failures)


def _metering(manifest: dict) -> dict | None:  # type: ignore[type-arg]
    """The exposure metering's evidence (``schedule.provenance.exposure``) where the session's
    exposure was metered before it began (``--auto-exposure``), else None."""
    evidence = ((manifest.get("schedule") or {}).get("provenance") or {}).get("exposure")
    return evidence if isinstance(evidence, dict) and "metering_shots" in evidence else None


def _time_line(folder, result, dry: bool) -> str:  # type: ignore[no-untyped-def]
    """The session's time on the real rig: a resumed session's is the sum of its runs (the
    manifest's), not this run's alone, and a metered one's includes the metering's test shots
    (their time on the rig's clock, which the manifest's exposure evidence records). It had
    left them out: 7 test shots, 8.4 s, on the emulated card dome (57.2 s said for 65.6 s)."""
    manifest = folder.manifest or {}
    timing = manifest.get("timing") or {}
    runs = int(timing.get("runs") or 1)
    metering = _metering(manifest)
    metering_s = None if metering is None else metering.get("rig_time_s")
    wall = result.wall_time_s
    if metering is not None and runs == 1:  # this run metered: its dry run took that too
        wall += float(metering.get("wall_time_s") or 0.0)
    beside = [f"simulated in {wall:.1f} s"] if dry else []
    total = result.rig_time_s
    at_least = ""
    if runs > 1:
        total = float(timing["rig_time_s"])
        beside.insert(0, f"this run {result.rig_time_s:.1f} s")
        # a run killed outright (kill -9, power) recorded no time: the sum leaves it out
        untimed_runs = [r for r in folder.manifest.get("runs") or [] if r.get("rig_time_s") is None]
        untimed = len(untimed_runs)
        # a run a stop cut before it recorded its end says so on disk (its ``end_cut``): only
        # the others were killed (SIGKILL, a power cut); all had been said "killed"
        cut = sum(1 for r in untimed_runs if r.get("end_cut"))
        if untimed:
            # the journal still times every image the killed run committed ("at least 0.0 s"
            # had been said for 15 images shot in 17.5 s)
            from rti_rig.runtime.session import journal_rig_time

            at_least = "at least "
            total = max(total, journal_rig_time(folder.root))
            ended = [
                *([f"{cut} run(s) stopped"] if cut else []),
                # a kill, a power cut or a disk too full for the end record: which, it did
                # not say (a full disk's run had been said "killed")
                *(
                    [f"{untimed - cut} run(s) killed, powered off or out of disk"]
                    if untimed - cut
                    else []
                ),
            ]
            beside.append(
                f"{' and '.join(ended)} before recording their time, counted from their "
                "images' times"
            )
    over = f" over {runs} runs" if runs > 1 else ""
    metered = ""
    if metering is not None:
        shots = int(metering["metering_shots"])
        if metering_s is None:  # metered before its time was recorded (an older session)
            metered = f", not counting {shots} metering shots"
        else:
            total += float(metering_s)
            metered = f" including {shots} metering shots"
            beside.insert(1 if runs > 1 else 0, f"metering {float(metering_s):.1f} s")
    return f"Session time on the real rig: {at_least}{total:.1f} s{over}{metered}" + (
        f" ({', '.join(beside)})" if beside else ""
    )


def _duty_clause(rig) -> str:  # type: ignore[no-untyped-def]
    """For a dome whose thermal guard made an LED wait before lighting again (its duty limit,
    ``[dome.serial.thermal] max_duty``), the time this run's LEDs waited dark to cool, and
    why; "" when none did. Why: the guard waited (up to a minute a light) and said it only in
    a debug log: a metered run on a duty-limited dome spent 180 s of its 256 s cooling LEDs,
    the rig sat still with no word, and the time line read as slow metering."""
    from rti_rig.runtime.lighting import DomeLighting

    if not isinstance(rig.lighting, DomeLighting):
        return ""
    wait = rig.lighting.duty_wait()
    if wait is None or wait.waited_s < 0.05:
        return ""
    thermal = wait.limits
    earlier = ""
    if wait.for_earlier_s >= 0.05:
        # the guard counts an earlier command's lightings (the duty ledger): a wait at the
        # start of a run right after another is theirs, not this run's
        earlier = f", {wait.for_earlier_s:.1f} s of it for LEDs an earlier command left hot"
    return (
        f"; of which LEDs waited dark {wait.waited_s:.1f} s to cool{earlier}, as the dome's "
        f"duty limit asks ([dome.serial.thermal] max_duty = {thermal.max_duty:g} over "
        f"duty_window_s = {thermal.duty_window_s:g} s): no LED was driven past it"
    )


def _moving_clause(rig, folder) -> str:  # type: ignore[no-untyped-def]
    """For an arm, the part of the session's time spent moving it: the sum of its images'
    ``light_s`` (from a step's start until its lamp is on, i.e. the move and the lamp-on; all
    runs' images), then this run's park at its end as timed on the rig's clock; "" for a
    dome. Why: only the total was said, and on an arm the moves are the part a faster profile
    or a better light order would cut.

    "(and switching its lamp on)" is said only of a lamp rti-rig switches (a simulated arm's,
    or ``lamp = "servo_led"``): it had been said of a ``lamp = "software"`` lamp, whose switch
    is outside the servo bus and which no command of rti-rig reaches."""
    from rti_rig.app.usecases.safe_state import software_lamp
    from rti_rig.runtime.lighting import ArmLighting

    if not isinstance(rig.lighting, ArmLighting) or not folder.committed:
        return ""
    moving = sum(float(r.light_s) for r in folder.committed.values())
    # the park at the end is a move too, and in the session's time: unsaid, a 2 s park on a
    # 21 s session was time a user could not find (this run's only: an earlier run's park
    # is in no record)
    park = rig.lighting.park_s
    runs = len(folder.manifest.get("runs") or [])
    # a park stopped or failed part-way took its seconds too, but is not said as "parking it"
    # (the arm's own line says where it was left)
    what = "parking it" if rig.lighting.park_finished else "its park, cut short,"
    parked = (
        ""
        if park is None
        else f", and {what} {park:.1f} s"
        if runs <= 1
        else f", and {what} at this run's end {park:.1f} s"
    )
    lamp = "" if software_lamp(rig.lighting) else " (and switching its lamp on)"
    return f"; of which moving the arm{lamp} {moving:.1f} s{parked}"


def _execute(opened, handover: HandOver | None = None) -> bool:  # type: ignore[no-untyped-def]
    """Run with a progress bar and signal handling; print what happened and how to go on.
    True when the session completed but its teardown failed (see :func:`_refuse_unsafe_end`).

    The handlers in place before are back only once the summary is printed: a second Ctrl-C
    meant as "stop at once", arriving just after the session stopped on the first, had cut
    the summary and its resume hint off (exit 130, no word). Off the main thread none is set,
    so none is put back (``signal.signal`` would raise ValueError there)."""
    handover = handover or HandOver()
    previous: dict[int, Any] = {}
    if handlers_settable():
        previous = {sig: signal.getsignal(sig) for sig in _HANDLED}
        previous.update(handover.originals)  # not the hand-over's holds
    try:
        return _run_and_report(opened, handover)
    finally:
        try:
            _print_failures(_close_left_open(opened))  # a stop the capture never answered
        finally:
            put_back(previous)


def _close_left_open(opened) -> list[str]:  # type: ignore[no-untyped-def]
    """Close the rig if the capture's ``with`` did not, and take what the close could not do
    in making it safe (see :meth:`~rti_rig.app.usecases.session.OpenedSession.close`), for
    the caller to say.

    Why: ``run`` counted the capture as begun (``started = True``) before it called it, and
    the controller's teardown takes the rig only once the capture runs: a stop in between
    skipped both, and the emulated dome, held open after ``--auto-exposure``, was neither
    switched off nor closed. Called from :func:`_execute`'s ``finally``, so it holds from the
    moment the opened rig is handed over, whatever ends the command; the close's own failures
    are taken here too when the capture's ``with`` closed the rig (a stop inside it, before
    the controller's ``try``)."""
    from rti_rig.runtime.lighting import unsafe_failures

    failures: list[str] = []
    if not opened.closed:
        try:
            opened.close()
        except Exception as exc:  # closing what the opening opened: said, never a traceback
            failures.append(f"closing the rig failed: {exc}")
    taken = opened.take_close_failures()
    unsafe = unsafe_failures(taken)
    if len(unsafe) < len(taken) and not opened.close_recorded:
        # a port that did not close cleanly was said as it happened, by the dome's own line;
        # where this run wrote no record to keep it in, that is said rather than a record
        # made up for it
        _unrecorded_port_close(
            "this run had not begun, so it wrote none"
            if not opened.folder.begun
            else "the run's manifest was not written with it"
        )
    return [*unsafe, *failures]


def _stopped_before_capture(  # type: ignore[no-untyped-def]
    opened, why: str, signum: signal.Signals
) -> typer.Exit:
    """Close a session stopped after it opened and before its capture began, say so (the stop
    named by ``why``) as a stop while opening is said, and give the exit a stop by ``signum``
    asks (the capture's own teardown never ran: the rig is made safe and closed here).

    What the close established about the lights is said, as every other stop says it (this
    one had said only that nothing was captured, though the close had sent the all-off)."""
    from rti_rig.app.usecases.safe_state import lights_state

    failed = _print_failures(_close_left_open(opened))
    lights = lights_state(opened.rig, failed)
    if opened.folder.put_back is not None:  # the close put a reshoot's images back
        from rti_rig.app.usecases.session import put_back_said

        said = (
            f"Stopped ({why}) before the session went on: {lights}. "
            f"{put_back_said(opened.folder.put_back)} To reshoot, the same command: "
            f"{_resume_before_begin(opened)}"
        )
        err.print(f"[yellow]{escape(said)}[/]")
        return typer.Exit(code=stop_exit_code(signum))
    if opened.resumed:
        said = (
            f"Stopped ({why}) before the session went on: no new image was captured; {lights}; "
            f"continue it with {_resume_before_begin(opened)}"
        )
    else:
        said = f"Stopped ({why}) before the first image: nothing was captured"
        if not opened.folder.begun:
            said += f" or written to {shown_path(opened.out_dir)}"
        said += f"; {lights}"
    err.print(f"[yellow]{escape(said)}.[/]")
    return typer.Exit(code=stop_exit_code(signum))


def _refuse_unsafe_end(unsafe: bool, rig: Any, exit_code: int | None = 1) -> None:
    """Exit 1 after a complete session whose teardown failed or left the lights unsure (said,
    with no exit, when ``exit_code`` is None: a stop that comes with its own exit).

    Why: the images are all there, but the rig was not brought to a known safe state (a final
    all-off not sent or unanswered, a lamp or stop refused). The run had exited 0, so a script
    chaining ``run && fit`` or a lab's batch took it for a clean end while the dome might be
    lit. An arm's user is told of its joints too: "switch the dome or lamp off" had been all
    they were told of an arm whose servo had faulted limp over the object.
    """
    if unsafe:
        from rti_rig.runtime.lighting import ArmLighting, park_check

        if isinstance(rig.lighting, ArmLighting):
            by_hand = (
                "switch the lamp off and support the arm, a joint of which may be limp; once "
                f"its fault is cleared, {park_check(rig.lighting.config)} parks it"
            )
        else:
            by_hand = "switch the dome off"
        err.print(
            "[red]The session is complete, but the rig was not brought to a known safe state "
            f"(above):[/] make it safe by hand ({escape(by_hand)}) before taking the object out."
        )
        if exit_code is not None:
            raise typer.Exit(code=exit_code)


_HANDLED = (signal.SIGINT, signal.SIGTERM) + (
    (signal.SIGUSR1,) if hasattr(signal, "SIGUSR1") else ()
)


def _paused_lights(rig) -> str:  # type: ignore[no-untyped-def]
    """What is known of the lights while a session is paused (after the last image's off).

    The pause had said "lights off" for every rig, also for a firmware that never acknowledges
    its all-off and for one that has no all-off (its LED goes off by itself)."""
    from rti_rig.app.usecases.safe_state import lights_state
    from rti_rig.runtime.lighting import ArmLighting

    if isinstance(rig.lighting, ArmLighting):  # no lamp reports back: what was asked, no more
        return "lamp off requested after the last image"
    return lights_state(rig)


def _light_off_for_camera(event) -> str:  # type: ignore[no-untyped-def]
    """What the user is told when a step's light goes off while a busy camera is awaited."""
    light = f"LED {event.led}" if event.led is not None else "the light"
    off = {
        "acknowledged": "switched off, acknowledged by the dome",
        "sent-no-ack": "all-off sent (this firmware never acknowledges)",
        "self-timed": "gone dark by itself at the end of its window (this firmware has no all-off)",
    }.get(event.off or "", "all-off sent")
    cool = (
        f" and {event.cool_s:.1f} s more for its duty limit (max_duty) to let it light again"
        if event.cool_s >= 0.05
        else ""
    )
    # the limit said is what sets it: max_on_s, or a timed firmware's own window (RTIPy)
    limit = event.limit or f"max_on_s = {event.max_on_s:g} s"
    return (
        f"Image {event.index + 1}: the camera is still busy (writing its previous shot?) and "
        f"its next try, in {event.wait_s:g} s, would keep {light} (lit {event.lit_s:.1f} s) on "
        f"past {limit}: {off}; it is lit again for the shot after that wait{cool}."
    )


def _run_and_report(opened, handover: HandOver) -> bool:  # type: ignore[no-untyped-def]
    from rti_rig.app.usecases.session import run_opened_session
    from rti_rig.runtime.controller import (
        CancelToken,
        DeviceSays,
        EmergencyStop,
        LightOffForCamera,
        Paused,
        Preparing,
        StepCompleted,
        StepStarted,
    )

    cancel = CancelToken()
    #: the capture has returned or raised, or will never begin: from then on a stop has
    #: nothing left to stop at once, and a signal handler that raised would do so in this
    #: function's except or finally clauses, where nothing catches it (see ``on_sigint``)
    ended = False
    late_said = False
    #: the stop's line of what the teardown did (the lights) is out: a Ctrl-C after it is
    #: pointed above, not below
    teardown_said = False
    #: the signal of the emergency stop a handler here raised (SIGTERM, SIGHUP for a hang-up,
    #: SIGINT for a second Ctrl-C), None before one
    stopping: signal.Signals | None = None
    #: a step of this run has begun (its light set): before it the rig is still being
    #: connected (an arm's baud scan can take 10 s), and no image is under way to stop after
    stepped = False
    #: what the run is doing before its first step (a :class:`Preparing` phase, or "paused"),
    #: said by a first Ctrl-C there; None until the controller says (the rig's opening)
    before_first: str | None = None

    def on_sigint(signum, frame):  # type: ignore[no-untyped-def]
        nonlocal ended, late_said, stopping
        if ended:
            # a second Ctrl-C meant as "stop at once", landing as the session's end is
            # reported (its except or finally clauses, before the ignore is set) had raised
            # EmergencyStop where nothing caught it: a traceback, the summary and resume unsaid.
            # After a first Ctrl-C it is the second, as one a moment earlier in the teardown:
            # the run stops after its summary (it had been said, then forgotten: the verdict
            # computed, exit 0). A stopped capture's own exit stands; a park's stop says itself
            if started and cancel.cancelled and _park_stopped_by(opened.rig) is None:
                opened.stopped_once_over = signal.SIGINT
            if not late_said:
                late_said = True
                closing = _CLOSING_RESUME_CTRL_C if opened.resumed else _CLOSING_CTRL_C
                late = _LATE_CTRL_C_SAID_ABOVE if teardown_said else _LATE_CTRL_C
                err.print(f"[yellow]{late if started else closing}[/]")
            return
        if stopping is not None:
            # a stop is under way (a SIGTERM's, a hang-up's, a second Ctrl-C's): a Ctrl-C now
            # had raised "second Ctrl-C" as the teardown's hold ended, which replaced the stop
            # (said, recorded and exited as a Ctrl-C's, 130, not the SIGTERM's 143), or was
            # dropped unsaid when the same hold delivered another stop first; and a first
            # Ctrl-C there had been told "Stopping after this image". The teardown is already
            # the "stop at once" a Ctrl-C asks for (all-off, a park cut short as it is held):
            # said in one line, the first stop goes on. While the teardown reopens a port
            # (after_a_stop) the Ctrl-C escalates: it ends an opening that may hang, and its
            # words name both (the exit code stays the first stop's)
            began = "second Ctrl-C" if stopping == signal.SIGINT else stop_words(stopping)
            if within_after_a_stop():
                escalated = began if stopping == signal.SIGINT else f"{began}, then Ctrl-C"
                raise EmergencyStop(stopping, escalated)
            err.print(
                f"[yellow]Ctrl-C also arrived: the stop ({began}) is already under way "
                "(switching the lights off, writing its records).[/]"
            )
            return
        if cancel.cancelled and cancel.over and not within_after_a_stop():
            # a second Ctrl-C once the capture has ended (held by the teardown, delivered once
            # it is done) stops no image: the manifest keeps how the capture ended ("cancelled"
            # after the first's image, or "completed") and the teardown ran as that end's, not
            # an emergency's. Raised here, it had been said "Emergency stop (second Ctrl-C)"
            # above that manifest: said in one line, the stop that began it stands; a complete
            # session stops before its verdict, as for a late SIGTERM (``run``: exit 130, "it
            # is complete"). A park it cut short is said by the arm's line; while the teardown
            # reopens a port (after_a_stop) it still escalates, below
            if _park_stopped_by(opened.rig) is None:
                opened.stopped_once_over = signal.SIGINT
                if not late_said:
                    late_said = True
                    err.print(f"[yellow]{_LATE_CTRL_C}[/]")
            return
        if cancel.cancelled:
            ended = not started  # stopped before the capture began: it never will
            stopping = signal.SIGINT  # a SIGTERM in its teardown is said, not raised
            raise EmergencyStop(signal.SIGINT, "second Ctrl-C")
        cancel.cancel()
        if _park_stopped_by(opened.rig) is not None:  # delivered after the teardown it stopped:
            return  # no image is left to stop after; the arm's line and the summary say it
        if cancel.over:  # held by the teardown (no park due, or after it) and delivered now
            # not "no image was left to stop after": after a capture an error or a SIGTERM
            # ended part-way, that read as if every image were in, above a resume hint
            late_said = True
            err.print(f"[yellow]{_LATE_CTRL_C}[/]")
            return
        if opened.folder.images_kept >= opened.total_steps:
            # the last image is committed, the capture not yet over (its last writes, an end
            # check): "Stopping after this image" read as if one were still to come, and asked
            # for a second Ctrl-C (a Ctrl-C in the teardown is the branch above)
            err.print("[yellow]Every image is in: finishing the session (lights off, records)…[/]")
            return
        if not stepped:
            # "Stopping after this image" had been said while the rig was being connected,
            # no image under way (an arm's connect, its baud scan), the connect going on; a
            # resumed run's images already there are no "any image" still to take
            kept = len(opened.folder.done)
            what = (
                f"image {_first_new_image(opened)} is taken (the {kept} already in the "
                "session are kept)"
                if kept
                else "any image is taken"
            )
            err.print(
                f"[yellow]Stopping before {what}: {_preparing(opened, before_first)} "
                "(Ctrl-C again to stop at once)…[/]"
            )
            return
        err.print("[yellow]Stopping after this image (Ctrl-C again to stop at once)…[/]")

    def on_sigterm(signum, frame):  # type: ignore[no-untyped-def]
        nonlocal stopping
        if ended:  # as for Ctrl-C: nothing left to stop; the handler from before answers it
            _as_before(previous.get(signal.SIGTERM), signum, frame)
            return
        if stopping is not None and not within_after_a_stop():
            # a stop is under way (its teardown, or the except clauses before it): a second
            # EmergencyStop raised there had replaced the first (said and exited as itself,
            # recorded as neither) or cut the teardown; said in one line, the first one goes
            # on. Not while the teardown reopens a port (after_a_stop): there a further stop
            # still ends an opening that may hang
            err.print(
                f"[yellow]{stop_words(as_received(signum))} also arrived: the stop "
                f"({stop_words(stopping)}) is already under way (switching the lights off, "
                "writing its records).[/]"
            )
            return
        stopping = as_received(signum)
        raise EmergencyStop(signal.SIGTERM)

    def on_sigusr1(signum, frame):  # type: ignore[no-untyped-def]
        if ended:  # as the session's end is reported: "Pausing after this image" had been said
            err.print("[yellow]SIGUSR1 ignored: a session pauses only while it captures.[/]")
            return
        if stopping is not None:  # not held as stops are: "Pausing after this image" had
            # been said in a stop's teardown, of a run that was ending
            err.print(
                f"[yellow]SIGUSR1 ignored: the stop ({stop_words(stopping)}) is under way "
                "(switching the lights off, writing its records).[/]"
            )
            return
        if cancel.paused:
            cancel.resume()
            err.print("[green]Resuming.[/]")
        elif not stepped:  # no image under way to pause after: the rig is still connecting
            cancel.pause()
            first = _first_new_image(opened)
            err.print(
                f"[yellow]Pausing before image {first} is taken: "
                f"{_preparing(opened, before_first)}; SIGUSR1 again resumes.[/]"
            )
        else:
            cancel.pause()
            err.print("[yellow]Pausing after this image; SIGUSR1 again resumes.[/]")

    # not signal_handlers(): SIGTERM is set later than the others, and what is put back is the
    # hand-over's originals, not its holds
    settable = handlers_settable()  # off the main thread: none set, none put back
    previous: dict[int, Any] = {}
    if settable:
        handlers = {signal.SIGINT: on_sigint}
        if hasattr(signal, "SIGUSR1"):
            handlers[signal.SIGUSR1] = on_sigusr1
        previous = {sig: signal.signal(sig, h) for sig, h in handlers.items()}
        # SIGTERM stays held (the hand-over's) until the try below, which answers it
        previous[signal.SIGTERM] = signal.getsignal(signal.SIGTERM)
        previous.update(handover.originals)  # not the hand-over's holds
    started = False  # whether the capture (which tears the rig down itself) has begun
    over = False  # whether it returned (its summary follows)
    rig, folder, out_dir = opened.rig, opened.folder, opened.out_dir
    dry = " (dry run)" if opened.dry_run else ""
    adaptive = " at most, adaptive" if opened.source is not None else ""
    # "24 of 24 lights" for --lights 24 on a 48-LED dome read as if the dome had 24: a new
    # session says its count, a resumed one what is left of it
    todo, total = opened.steps_to_do, opened.total_steps
    # the noun agrees with the total it follows: "1 of 4 light left" had been said
    noun = "light" if total == 1 else "lights"
    count = f"{todo} {noun}" if todo == total else f"{todo} of {total} {noun} left"
    shown = escape(shown_path(out_dir))
    out.print(f"Rig [bold]{escape(rig.name)}[/]{dry}: {count}{adaptive} → {shown}")

    def resume_hint() -> str:  # said once the run stopped: what it wrote decides the command
        return _cannot_resume(opened) or f"Continue with: {_continue_command(opened)}"

    try:
        if settable:
            signal.signal(signal.SIGTERM, on_sigterm)
        if handover.held:  # a SIGTERM or Ctrl-C while the capture took over from the opening
            ended = True  # the capture will not begin: a Ctrl-C as the rig closes stops nothing
            raise EmergencyStop(handover.stop())
        with Progress(
            TextColumn("[progress.description]{task.description}"),
            BarColumn(),
            MofNCompleteColumn(),
            TimeElapsedColumn(),
            console=out,
        ) as progress:
            task = progress.add_task(
                "capturing", total=opened.total_steps, completed=len(folder.done)
            )

            def on_event(event):  # type: ignore[no-untyped-def]
                nonlocal stepped, before_first
                if isinstance(event, StepStarted):
                    stepped = True
                elif isinstance(event, Preparing):
                    before_first = event.phase
                elif isinstance(event, Paused) and not stepped:
                    before_first = "paused"
                if isinstance(event, StepCompleted):
                    progress.advance(task)
                elif isinstance(event, Paused):
                    progress.update(task, description="paused")
                    err.print(
                        f"Paused before image {event.index + 1}: {_paused_lights(rig)}. "
                        "SIGUSR1 resumes.",
                        markup=False,
                    )
                elif isinstance(event, StepStarted):  # after a pause: capturing again
                    progress.update(task, description="capturing")
                elif isinstance(event, LightOffForCamera):
                    # said as it happens: the bar would stand still for the whole wait
                    err.print(_light_off_for_camera(event), markup=False)
                elif isinstance(event, DeviceSays):
                    err.print(event.text, markup=False)

            def capture():  # type: ignore[no-untyped-def]
                # ``ended`` is set in here: a stop raised before it is raised inside the try
                # below, whose except clauses say it; once set, none is raised
                nonlocal ended
                try:
                    return run_opened_session(opened, cancel, on_event)
                except BaseException:
                    # a run that ends before its first image (a dome that could not be
                    # connected) leaves no bar: an empty "capturing 0/6" had stood above
                    # "Nothing was captured", and a resume's "capturing 4/6" (the images of
                    # earlier runs) above "Nothing was commanded", as if this run took them
                    if not stepped:
                        progress.update(task, visible=False)
                    raise
                finally:
                    ended = True

            started = True
            result = capture()
            over = True
    except (EmergencyStop, KeyboardInterrupt) as exc:
        from rti_rig.app.usecases.safe_state import lights_state

        why = "Ctrl-C" if isinstance(exc, KeyboardInterrupt) else str(exc)
        # before the capture began, or before the controller took the rig (its teardown
        # records the run's end whatever happens): nothing was lit or written by it. Not a
        # teardown that a stop cut before it could begin (run_end unset, the session's close
        # made the rig safe) after this run committed images: "before the first image:
        # nothing was captured" had been said of 6 images on disk, with no resume hint
        if not started or (
            not opened.teardown_ran and folder.images_kept == opened.steps_done_before
        ):
            raise _stopped_before_capture(opened, why, stop_signal(exc)) from None

        failed = _print_stop_failures(opened)
        err.print(f"[red]Emergency stop ({escape(why)}):[/] {escape(lights_state(rig, failed))}.")
        teardown_said = True
        err.print(_after_stop(opened, resume_hint()), markup=False, soft_wrap=True)
        raise typer.Exit(code=stop_exit_code(stop_signal(exc))) from None
    except RtiRigError as exc:
        from rti_rig.app.usecases.safe_state import lights_state

        state = lights_state(rig, _print_stop_failures(opened, said_below=exc))
        said = _write_failed_said(exc, opened)
        # a write the disk refused ends with the resume command, after the fix it needs: said
        # there once (this line had said "Continue with: …" too, just above it)
        hint = _dead_led_hint(opened, exc) or ("" if said is not exc else resume_hint())
        err.print(f"{_sentence(state)}. {_after_stop(opened, hint)}".rstrip(), markup=False)
        raise fail(said) from None
    except Exception as exc:
        # a fault no driver named (an OSError, a library's own exception): the controller has
        # torn down and kept the images all the same, but this had been a Python traceback,
        # with nothing said of the lights, of the images kept or of the resume
        from rti_rig.app.usecases.safe_state import lights_state

        state = lights_state(rig, _print_stop_failures(opened))
        err.print(f"{_sentence(state)}. {_after_stop(opened, resume_hint())}", markup=False)
        raise _unexpected(exc, f"{shown_path(out_dir)}/manifest.json") from None
    finally:
        if over and settable and previous.get(signal.SIGINT) is not None:
            # the session is over (stopped or done): a late Ctrl-C must not cut the summary.
            # Ignored before the handlers are put back, not after: in between, the handler
            # from before (Python's KeyboardInterrupt) was in place, and a Ctrl-C there
            # escaped ``run`` with the summary unsaid
            put_back({signal.SIGINT: signal.SIG_IGN})
            put_back({sig: h for sig, h in previous.items() if sig != signal.SIGINT})
        else:
            put_back(previous)
    with _ctrl_c_ignored(previous.get(signal.SIGINT) if over else None):
        return _summarise(opened, result, resume_hint(), dry)


#: What a first Ctrl-C or SIGUSR1 before the run's first step is told is under way, by the
#: controller's :class:`~rti_rig.runtime.controller.Preparing` phase ("paused": a SIGUSR1
#: pause before it); ``{first}`` is the run's first image (:func:`_preparing`).
#: Why: "the rig is being connected" had been said of every wait there alike.
_BEFORE_FIRST_STEP = {
    "lights": "the rig is being connected",
    "camera": "the camera is being connected",
    "card": "the camera's card is being listed",
    "ready": "the rig is connected, {first} about to begin",
    "paused": "the capture is paused before {first}",
}


def _first_new_image(opened: OpenedSession) -> int:
    """The number (1-based) of the first image this run takes: a resumed session's first step
    not yet on disk, a new one's 1."""
    done = opened.folder.done
    return next((i + 1 for i in range(opened.total_steps) if i not in done), 1)


def _preparing(opened: OpenedSession, phase: str | None) -> str:
    """What is under way before this run's first step, in :data:`_BEFORE_FIRST_STEP`'s words.
    A resumed run's first image is named by its number: "its first image" had been said of a
    session that held images."""
    first = f"image {_first_new_image(opened)}" if opened.folder.done else "its first image"
    said = _BEFORE_FIRST_STEP.get(phase or "", _BEFORE_FIRST_STEP["lights"])
    return said.format(first=first)


#: What a Ctrl-C once the capture has ended (returned, raised or been stopped) is told.
_LATE_CTRL_C_WORDS = (
    "Ctrl-C after the capture had ended: there was nothing left to stop, and the rig's "
    "teardown has run (what it did is said {where})."
)
_LATE_CTRL_C = _LATE_CTRL_C_WORDS.format(where="below")
#: The same once the stop has said what the teardown did: "said below" had pointed at the
#: images kept and the resume, under the line of the lights. (Filled in, not a replace of the
#: other's words: a rewording that dropped "said below" would have left both alike.)
_LATE_CTRL_C_SAID_ABOVE = _LATE_CTRL_C_WORDS.format(where="above")
#: What a Ctrl-C is told while a session stopped before its capture began closes its rig, a
#: new one's and a resumed one's (which has images: "before its first image" had been said of
#: it too, above "Stopped (Ctrl-C) before the session went on").
_CLOSING_CTRL_C = (
    "Ctrl-C while the session stopped before its first image: the rig is being closed (said below)."
)
_CLOSING_RESUME_CTRL_C = (
    "Ctrl-C while the resumed session stopped before it went on: the rig is being closed (said "
    "below)."
)


def _as_before(handler: Any, signum: int, frame: Any) -> None:
    """Answer ``signum`` as ``handler`` (what was in place before the capture's) would have:
    call it, ignore the signal, or take the default action (for SIGTERM, the process ends).

    Why: the capture's SIGTERM handler raises an emergency stop, which once the capture has
    ended would be raised where nothing catches it (a traceback); the run's own late handler
    (:func:`_late_term_held`) is what answers a SIGTERM after the capture."""
    if callable(handler):
        handler(signum, frame)
    elif handler != signal.SIG_IGN:  # the default action (or one set outside Python)
        received = as_received(signum)  # a hang-up answered as a SIGTERM ends as SIGHUP
        default_action(received)  # called once the capture (and its teardown) has ended


@contextmanager
def _ctrl_c_ignored(then: Any = None) -> Iterator[None]:
    """SIGINT ignored for the block, the handler before (or ``then``, the one to end with
    when the caller has already set the ignore in its place) put back however it ends (a
    return, an error, a ``typer.Exit``).

    Why: the summary of a session that is over must not be cut by a late Ctrl-C (a second one
    meant as "stop at once"), but the ignore had been set and left to the caller to undo:
    ``run`` called in-process (CliRunner, or anyone calling the app from Python) was one
    restore away from leaving its caller deaf to Ctrl-C, and every process it started after
    would inherit the ignored signal."""
    try:
        with signal_handlers({signal.SIGINT: signal.SIG_IGN}):
            yield
    finally:
        if then is not None:
            put_back({signal.SIGINT: then})


def _summarise(opened, result, resume_hint: str, dry: str) -> bool:  # type: ignore[no-untyped-def]
    """What a session that is over says: its images, time, notes, lights and how to go on;
    True when it completed but its teardown failed (see :func:`_refuse_unsafe_end`)."""
    from rti_rig.runtime.controller import FinishReason
    from rti_rig.runtime.disowned import MARKER
    from rti_rig.runtime.lighting import ArmLighting, unsafe_failures
    from rti_rig.runtime.session import LP_NAME

    rig, folder = opened.rig, opened.folder

    unsafe = unsafe_failures(result.teardown_failures)
    if result.finish_reason is FinishReason.CANCELLED:
        from rti_rig.app.usecases.safe_state import lights_state

        # what the teardown established, as a stop says it (a cancel had said nothing of the
        # lights: not even "sent but not acknowledged" on a firmware that never confirms)
        lights = _sentence(lights_state(rig, bool(unsafe))) + "."
    if result.finish_reason is FinishReason.CANCELLED and not folder.images_kept:
        # stopped before the first image: no lights.lp to speak of, no resume for nothing
        err.print(
            f"[yellow]Session cancelled.[/] {escape(lights)} "
            f"{escape(_after_stop(opened, resume_hint))}"
        )
        raise typer.Exit(code=stop_exit_code(signal.SIGINT))
    marker = folder.root / MARKER
    labels = (
        f"{LP_NAME} lists the lights that fired."
        if not marker.is_file()
        # the marker's path as a shell word, through rich escaped: a session folder named
        # 'scan [v2]' had lost its '[v2]' to rich's markup (a '[/x]' ended in a MarkupError)
        else f"{LP_NAME} lists the lights the images are labelled with, NOT verified: "
        f"{escape(shown_path(marker))} says why (fit and export-lp refuse this session)."
    )
    out.print(
        f"{folder.images_kept} image(s) in the session; {labels}\n"
        + _time_line(folder, result, dry)
        + _moving_clause(rig, folder)
        + escape(_duty_clause(rig))
    )
    for note in folder.manifest.get("notices") or []:
        err.print(f"[yellow]note:[/] {escape(str(note))}")
    for note in result.notes:
        err.print(f"[yellow]note:[/] {escape(str(note))}")
    # (a port that did not close cleanly was said as it happened, by the dome's own line: the
    # manifest keeps it among the teardown failures, it is not said twice nor taken as unsafe)
    for failure in unsafe:
        err.print(f"[red]teardown problem:[/] {escape(str(failure))}")
    if result.finish_reason is not FinishReason.CANCELLED and (
        getattr(rig.loaded.config, "backend", None) in ("hardware", "emulated")
        or isinstance(rig.lighting, ArmLighting)  # a simulated arm: where it was left
    ):
        from rti_rig.app.usecases.safe_state import lights_state

        # a finished session on a rig with devices says what its teardown established, as a
        # stop does (it had said nothing: the user took the object out not told whether the
        # dome had acknowledged its all-off, or that a firmware with none switches itself off)
        out.print(
            _sentence(lights_state(rig, bool(unsafe))) + ".",
            markup=False,
            highlight=False,
        )
    adaptive_result = opened.extra.get("adaptive_result")
    if adaptive_result is not None:
        from rti_rig.app.usecases.adaptive import (
            ARM_MAX_LIGHTS,
            claim_caveat,
            estimate_phrase,
            few_lights_note,
            header_band,
            short_of_target_note,
        )

        chosen_for = adaptive_result.get("objective", "normals")
        reason = adaptive_result["stop"]["reason"]
        estimates = estimate_phrase(adaptive_result, reason)  # what the reason did not say
        out.print(
            ("Adaptive" if chosen_for == "normals" else f"Adaptive (designs for {chosen_for})")
            + f": {adaptive_result['lights_used']} lights; stopped: {reason}"
            + (f"; {estimates}" if estimates else ""),
            highlight=False,
        )
        header = opened.folder.manifest.get("adaptive") or {}
        # the lamps the estimate rendered, as the result records them (a session resumed from
        # before the key was recorded is judged with the rig's, which its settings do not say)
        lamps = adaptive_result.get("lamps", header.get("lamps"))
        backend = opened.rig.loaded.config.backend
        simulated = backend in ("simulated", "emulated")
        caveat = claim_caveat(
            adaptive_result, header_band(header), lamps, simulated, backend == "replay"
        )
        if caveat is not None:  # one line, as the notes below
            err.print(f"[yellow]note:[/] {escape(caveat)}", highlight=False, soft_wrap=True)
        short = few_lights_note(adaptive_result, lambda m: _with_min_lights(opened, m))
        if short is not None:  # one line: the command it ends with pastes whole
            err.print(f"[yellow]note:[/] {escape(short)}", highlight=False, soft_wrap=True)
        offered = int((opened.folder.manifest.get("adaptive") or {}).get("candidates") or 0)
        most = ARM_MAX_LIGHTS if opened.rig.loaded.config.arm is not None else None
        unreached = short_of_target_note(
            adaptive_result, offered, lambda: _without_lights(opened), most
        )
        if unreached is not None:  # one line, as the note above
            err.print(f"[yellow]note:[/] {escape(unreached)}", highlight=False, soft_wrap=True)
    if result.finish_reason is FinishReason.CANCELLED:
        err.print(
            f"[yellow]Session cancelled; the images captured so far are kept.[/] "
            f"{escape(lights)} {escape(resume_hint)}"
        )
        raise typer.Exit(code=stop_exit_code(signal.SIGINT))
    from rti_rig.app.usecases.safe_state import safe_state_unsure

    return bool(unsafe) or safe_state_unsure(rig)


def _park_stopped_by(rig) -> int | None:  # type: ignore[no-untyped-def]
    """The signal (SIGINT, SIGTERM) that stopped the arm's final park, None if none did (or
    the rig has no arm): a stop during the teardown's park holds the arm where it stands
    (:meth:`rti_rig.runtime.lighting.ArmLighting.safe`). Asked of an arm by type: a
    ``getattr`` had answered "none" for a renamed attribute."""
    from rti_rig.runtime.lighting import ArmLighting

    lighting = rig.lighting
    return lighting.stopped_by if isinstance(lighting, ArmLighting) else None


def _exit_if_park_stopped(  # type: ignore[no-untyped-def]
    opened, unsafe: bool, what: str, head: str, tail: str
) -> None:
    """Exit 130 once the summary is out if a Ctrl-C stopped the arm's final park (an
    interrupted command's exit, as a late SIGTERM's), saying ``what`` is complete, ``head``
    (highlighted) and ``tail`` what to do. Said by each command after its own summary, not
    in :func:`_summarise`: a preview's had told the user of a QA verdict and ``rti-rig fit``,
    and lost its plan hint."""
    if _park_stopped_by(opened.rig) != signal.SIGINT:
        return
    _refuse_unsafe_end(unsafe, opened.rig, exit_code=None)
    err.print(
        f"[yellow]Stopped (Ctrl-C) during the arm's park, once {what} had ended: it is "
        f"complete{head}[/]{tail}",
        soft_wrap=True,
    )
    raise typer.Exit(code=stop_exit_code(signal.SIGINT))


@app.command()
def preview(
    rig_config: Annotated[
        Path,
        typer.Argument(
            help="Rig config TOML, e.g. rig_configs/simulated_dome.toml, or a recorded "
            "acquisition's .lp with its images beside it (the preview is its image nearest "
            "the light asked)."
        ),
    ],
    out_dir: Annotated[
        Path, typer.Option("--out", help="New or empty folder to write the one-image session.")
    ],
    light: Annotated[
        str | None,
        typer.Option(
            "--light",
            help="Azimuth,elevation of the preview light in degrees (frame of the .lp files; "
            "default 135,50: top left, in the paper's 45–60° band). A dome uses its nearest LED "
            "(by default the nearest in that band, if it has LEDs there).",
        ),
    ] = None,
    min_elevation_deg: Annotated[
        float,
        typer.Option(
            "--min-elevation-deg",
            help="Lowest elevation allowed (degrees), as for 'plan' and 'run': the default "
            "light is chosen within the band, a --light outside it is refused.",
        ),
    ] = 0.0,
    max_elevation_deg: Annotated[
        float,
        typer.Option(
            "--max-elevation-deg",
            help="Highest elevation allowed (degrees; 90 = up to the zenith), as for 'plan' "
            "and 'run': give the ceiling you will plan with (e.g. 45 for gilding) so the "
            "preview is not shot above it.",
        ),
    ] = 90.0,
    auto_exposure: Annotated[
        bool,
        typer.Option(
            "--auto-exposure",
            help="Meter first (a short test series) so the preview is not saturated.",
        ),
    ] = False,
    max_saturated: MaxSaturatedOption = None,
) -> None:
    """Shoot the planner's preview: one image under one light, as a session of one image.

    The session records the light that fired, so `rti-rig plan OUT_DIR --rig RIG ...` plans from
    its linear image with that light (no --preview-light needed).
    """
    from rti_rig.app.usecases.session import PreviewRequest, open_preview_session

    def open_preview() -> Any:
        refuse_unmetered_limit(max_saturated, auto_exposure)
        return open_preview_session(
            PreviewRequest(
                rig_config,
                out_dir,
                parse_az_el(light, "--light"),
                auto_exposure=auto_exposure,
                **_metering_limit(max_saturated),
                min_elevation_deg=min_elevation_deg,
                max_elevation_deg=max_elevation_deg,
            ),
            print_note,
        )

    # metering for the preview lights the rig: a Ctrl-C had said only "rti-rig: stopped", a
    # SIGTERM nothing at all (and sent no all-off)
    opening = _Opening(
        open_preview,
        out_dir,
        auto_exposure,
        stopped=lambda why, _exc: (
            f"Stopped ({why}) before the preview image: nothing was captured or written to "
            f"{shown_path(out_dir)}"
        ),
        not_opened=f"Nothing was captured or written to {shown_path(out_dir)}",
    )
    # a SIGTERM once the capture is over: the summary and the plan hint finish first. A
    # hang-up (SIGHUP) is answered as SIGTERM is: the preview lights the dome, and SIGHUP had
    # ended it at once with the LED lit (no all-off), exit 129 and no word
    with hangup_as_sigterm(), _late_term_held() as late_term:
        with _sigterm_exit_wins(late_term):
            opened, handover = _open_for_capture(opening)
            unsafe = _execute(opened, handover)
        # the band given here is the one to plan in: said in the command to copy
        band = "".join(
            f" {flag} {value:g}"
            for flag, value, given in (
                ("--min-elevation-deg", min_elevation_deg, min_elevation_deg != 0.0),
                ("--max-elevation-deg", max_elevation_deg, max_elevation_deg != 90.0),
            )
            if given
        )
        from rti_rig.core.rig_geometry import hint_light_count  # numpy: not at import

        plan_lp = free_name(Path("plan.lp"))
        # a flash-synced dome's and a replayed .lp's geometry too
        lights = hint_light_count(opened.rig.geometry, min_elevation_deg, max_elevation_deg)
        out.print(
            f"Plan from it: rti-rig plan {_arg(out_dir)} --rig "
            f"{_arg(rig_config)} --lights {lights}{band} --out {_arg(plan_lp)}",
            highlight=False,
            markup=False,
            soft_wrap=True,
        )
        metered = _metered_apart(opened) if auto_exposure else None
        if metered is not None:
            # the limit the preview metered with, or the run meters at the default 0.1 %
            limit = f" --max-saturated {max_saturated:g}" if max_saturated is not None else ""
            out.print(
                f"Then: rti-rig run {_arg(rig_config)} --plan {_arg(plan_lp)} --out "
                f"{_arg(free_name(out_dir.parent / 'planned', folder=True))} "
                f"--auto-exposure{limit} (this preview was metered at {metered[0]:.4g} s; without "
                f"--auto-exposure the run uses the config's exposure_s = {metered[1]:g} s)",
                highlight=False,
                markup=False,
                soft_wrap=True,
            )
        # a SIGTERM held as the summary printed, or a second Ctrl-C once the capture had
        # ended (it stopped no image), as ``run`` says them: the second Ctrl-C had ended a
        # complete preview with exit 0, where it had been 130 (said "Emergency stop")
        late = late_term[0] if late_term else opened.stopped_once_over
        if late is not None:  # the preview and its summary are out; the run's word on the stop
            _refuse_unsafe_end(unsafe, opened.rig, exit_code=None)
            err.print(
                f"[yellow]Stopped ({stop_words(late)}) once the preview was taken: it "
                "is complete in "
                f"{escape(_arg(out_dir))}[/] (plan from it as above)",
                soft_wrap=True,
            )
            raise typer.Exit(code=stop_exit_code(late))
        _exit_if_park_stopped(
            opened,
            unsafe,
            "the preview",
            f" in {escape(_arg(out_dir))}",
            " (plan from it as above)",
        )
        _refuse_unsafe_end(unsafe, opened.rig)


def _metered_apart(opened) -> tuple[float, float] | None:  # type: ignore[no-untyped-def]
    """(the exposure the preview was metered at, the config's) when they differ by more than
    1 %: the run a plan leads to uses the config's exposure unless it meters again, and the
    preview's metering is not carried over (a plan holds lights, not an exposure). Said after
    a metered preview: on the emulated dome a run at the config's 0.05 s after a preview
    metered at 0.0074 s had clipped, and its verdict said reshoot."""
    steps = opened.schedule.steps
    chosen = steps[0].exposure_s if steps else None
    config = opened.rig.camera_config.exposure_s
    if chosen is None or abs(chosen - config) <= 0.01 * config:
        return None
    return float(chosen), float(config)


@app.command("export-lp")
def export_lp(
    session_dir: Annotated[Path, typer.Argument(help="A session folder written by 'rti-rig run'.")],
    out_file: Annotated[
        Path,
        typer.Option(
            "--out",
            metavar=FILE,
            help="The .lp file to write. A name that does not end in .lp is still written, "
            "with a note to rename it: relight, RTIBuilder and rti-rig fit only read files "
            "ending in .lp.",
        ),
    ],
    linear: Annotated[
        bool,
        typer.Option("--linear", help="Name the 16-bit linear TIFFs instead of the JPEGs."),
    ] = False,
    force: Annotated[bool, typer.Option("--force", help="Overwrite an existing file.")] = False,
) -> None:
    """Write the .lp of a session from its verified journal: the lights that actually fired,
    for every image on disk as captured (an interrupted session's too). A session whose run
    stopped before adding its last committed image to lights.lp has it added there too."""
    from rti_rig.app.usecases.export import ExportLpRequest, relight_move_advice
    from rti_rig.app.usecases.export import export_lp as write_session_lp
    from rti_rig.runtime.session import JOURNAL

    before = stamp(out_file)  # a file there already (--force) is not one this export wrote
    try:
        # SIGTERM (and a hang-up) as Ctrl-C: without a handler one ended the export at once,
        # mid-write, leaving its hidden temporary file beside the .lp asked for, and said
        # nothing; raised, the writer removes it (the .lp itself is only ever renamed whole)
        with sigterm_stops():
            done = write_session_lp(ExportLpRequest(session_dir, out_file, linear, force))
    except RtiRigError as exc:
        raise fail(exc) from None
    except (KeyboardInterrupt, Terminated) as exc:
        signum = stop_signal(exc)
        state = (
            f"{shown_path(out_file)} is written whole"
            if written_since(out_file, before)
            else f"no .lp was written to {shown_path(out_file)}"
            + ("" if before is None else " (the file already there is as it was)")
        )
        err.print(f"Stopped ({stop_words(signum)}): {state}.", markup=False, soft_wrap=True)
        raise typer.Exit(code=stop_exit_code(signum)) from None
    if done.left_out:
        err.print(
            f"[yellow]note:[/] left out, missing or changed since they were captured: "
            f"{escape(', '.join(done.left_out))}"
            + (f"; {escape(done.renamed)}" if done.renamed else "")
            + (f"; {escape(done.left_out_advice)}" if done.left_out_advice else ""),
            soft_wrap=True,
        )
    if done.raw_lost:
        err.print(f"[yellow]note:[/] {escape(done.raw_lost)}", soft_wrap=True)
    if done.mosaic:
        err.print(f"[yellow]note:[/] {escape(done.mosaic)}", soft_wrap=True)
    if done.relisted:
        err.print(f"[yellow]note:[/] {escape(done.relisted)}", soft_wrap=True)
    if done.misnamed:
        err.print(f"[yellow]note:[/] {escape(done.misnamed)}", soft_wrap=True)
    if done.in_session:
        err.print(f"[yellow]note:[/] {escape(done.in_session)}", soft_wrap=True)
    if done.unchecked:
        err.print(
            f"[yellow]note:[/] left out, not verifiable as captured "
            f"({escape(done.unchecked_why)}): {escape(', '.join(done.unchecked))}"
            + (
                f"; restore {JOURNAL} from a backup copy{escape(done.rebuild)}"
                if done.rebuild
                else ""
            ),
            soft_wrap=True,
        )
    if done.outside_session:
        err.print(
            f"[yellow]note:[/] its image names are relative to {escape(shown_path(session_dir))}, "
            "and tools (relight, RTIBuilder, rti-rig fit) read them beside the .lp: move "
            f"{escape(_arg(out_file))} into {escape(_arg(session_dir))} to use it; "
            + escape(relight_move_advice(session_dir, out_file.name)),
            soft_wrap=True,
        )
    # escaped: a file in a folder named 'coin [draft]' had been said as 'coin .lp' (rich read
    # '[draft]' as markup)
    n = len(done.entries)
    lights = f"{n} light{'' if n == 1 else 's'}"
    if done.written:
        out.print(f"{lights} → {escape(shown_path(out_file))}")
    else:  # the session's own lights.lp, already the journal's listing (said above)
        out.print(f"{lights}, as {escape(shown_path(out_file))} already lists them")
