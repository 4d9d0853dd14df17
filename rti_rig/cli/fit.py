"""`rti-rig fit`: parse, call :func:`rti_rig.app.usecases.fit.run_fit`, print the verdict."""

from __future__ import annotations

import signal
import warnings
from pathlib import Path
from typing import Annotated

import typer
from rich.markup import escape

from rti_rig.cli.app import app, err, fail, out, print_notes, shown_path, stop_exit_code
from rti_rig.cli.stopping import Terminated, sigterm_stops, stop_signal
from rti_rig.core.deferred_signals import stop_words
from rti_rig.core.errors import RtiRigError

#: The --model names, as --help offers them and an unknown name's refusal lists them: one
#: list, as the refusal (the registry's) had left out ``auto`` and named robust PS
#: ``ps-robust (or robust-ps)`` where --help says ``robust-ps``. Each but auto is a registry
#: name (tests/cli/test_fit_model_names.py).
MODEL_CHOICES = (
    "auto (evidence-based choice)",
    "ps",
    "robust-ps (or ps-robust)",
    "lambert",
    "ptm",
    "hsh1",
    "hsh2",
    "hsh3",
)
MODEL_HELP = ", ".join(MODEL_CHOICES)

#: how the normal maps' estimator is named to a user
NORMALS_SHOWN = {
    "ps-robust": "robust photometric stereo (shadows and highlights discarded per pixel)",
    "ps": "least-squares photometric stereo",
    "lambert": "the least-squares Lambert fit (the model used; --model robust-ps for robust "
    "photometric stereo)",
    "ptm": "the PTM's Lambertian reading (the model used; --model robust-ps for robust "
    "photometric stereo)",
}


def print_verdict(session: Path | None) -> None:
    """Last line of ``run``: the QA verdict (never fails the run: it is advice). A Ctrl-C or
    SIGTERM while it is computed is said (the session is complete, and which command gives the
    verdict) and exits as a stop does, 130 or 143 (:class:`typer.Exit`)."""
    if session is None:
        return
    try:  # the import too: a SIGTERM while it loads (slow on a busy machine) is the verdict's
        from rti_rig.app.usecases.fit import verdict_for_session

        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            verdict = verdict_for_session(session)
        out.print(f"QA verdict: {escape(verdict)}")
        _say_verdict_warnings(caught)
    except (RtiRigError, ValueError) as exc:
        err.print(f"[yellow]QA verdict unavailable:[/] {escape(str(exc))}")
    except (KeyboardInterrupt, Terminated) as exc:  # only the advice is cut short
        # said, then the exit the stop has everywhere else (Ctrl-C 130, SIGTERM 143): a
        # Ctrl-C here had exited 0, so ``run && fit`` went on to fit after the user asked to
        # stop, and the two stops of the same moment disagreed. The run's SIGTERM handler
        # for the verdict (``session._verdict_terminable``) raises the stopping module's
        # Terminated, as every command's does: it is the only handler installed while the
        # verdict is computed, so a Terminated here is the verdict's stop
        raise verdict_skipped(exc, session) from None


def verdict_skipped(exc: BaseException, session: Path) -> typer.Exit:
    """Say that the verdict of the complete ``session`` was cut short by the stop ``exc`` (a
    KeyboardInterrupt or Terminated) and which command gives it; the exit that stop has."""
    signum = stop_signal(exc)
    from rti_rig.core.out_folders import fit_beside

    err.print(
        f"[yellow]QA verdict skipped ({stop_words(signum)}):[/] the session is complete; "
        f"{escape(fit_beside(session))} gives the verdict"
    )
    return typer.Exit(code=stop_exit_code(signum))


def _say_verdict_warnings(caught: list[warnings.WarningMessage]) -> None:
    """What the verdict's fits warned of, said once each as a note in the run's words.

    Why: a session whose lights leave the normals poorly determined (``run --adaptive
    --max-elevation-deg 10`` on the simulated arm: all lights within 10° of the horizon)
    printed a raw ``IllConditionedFitWarning`` with the QA module's file path and line under
    the verdict; the user was told neither what it meant for the session nor what to do.

    Why not left to :func:`~rti_rig.cli.app.warnings_as_notes` (which says any warning, as it
    is raised, in its own words): these are caught so as to be said after the verdict line
    they qualify, and a fit-trust warning needs the run's advice (the elevation band), which
    the generic note cannot give; the others are said as it says them (:func:`warning_note`).
    """
    from rti_rig.cli.app import warning_note
    from rti_rig.reconstruct.errors import FitTrustWarning

    said: set[str] = set()
    for w in caught:
        text = str(w.message)
        if text in said:
            continue
        said.add(text)
        if issubclass(w.category, FitTrustWarning):
            err.print(
                "[yellow]note:[/] this session's lights leave its surface normals poorly "
                f"determined ({escape(text)}): its normal map, and relighting away from its "
                "lights, are noisy whatever the verdict says of the images. To capture it "
                "again with normals to trust, widen the elevation band "
                "(--min-elevation-deg/--max-elevation-deg) or add lights at other elevations",
                soft_wrap=True,
            )
        else:
            warning_note(text)


def _stopped(
    signum: signal.Signals, out_dir: Path, batch: bool, written: bool, cluster: bool = False
) -> typer.Exit:
    """Say what a stopped fit left (``written``: the stop came after every output was
    written, while they were being reported; ``cluster``: a batch whose sessions are tasks on
    Dask workers), and the exit a shell expects for that signal."""
    from rti_rig.cli.app import stop_exit_code

    why = stop_words(signum)
    if written:
        said = f"Stopped ({why}) after the fit had written its outputs to {shown_path(out_dir)}"
    elif batch and cluster:
        # Dask cannot interrupt a task a worker is running: a session already started goes on
        # there and is renamed into place when it finishes. "The one being fitted was
        # discarded" had been said, and the sessions appeared in --out minutes later.
        said = (
            f"Stopped ({why}): the sessions finished are kept in {shown_path(out_dir)}; those "
            "already running on the Dask workers cannot be stopped from here and go on there, each "
            f"appearing in {shown_path(out_dir)} when it finishes (the ones not yet started were "
            "cancelled); run the same command again to fit the rest (finished ones are "
            "skipped)"
        )
    elif batch:
        said = (
            f"Stopped ({why}): the sessions finished are kept in {shown_path(out_dir)}, the one "
            "being fitted was discarded; run the same command again to fit the rest (finished ones "
            "are skipped)"
        )
    else:
        said = (
            f"Stopped ({why}) before the fit finished: nothing it wrote was left in "
            f"{shown_path(out_dir)}; run the same command again"
        )
    err.print(f"[yellow]{escape(said)}.[/]")
    return typer.Exit(code=stop_exit_code(signum))


@app.command()
def fit(
    sources: Annotated[
        list[Path],
        typer.Argument(
            help="Session folder(s), or .lp file(s) with their images beside them. With more "
            "than one, a resumable batch: each goes to OUT/<session folder name> "
            "(OUT/<folder>-<stem> for an .lp), finished ones are skipped unless their session "
            "changed since (resumed, reshot, lights moved; not a copy without timestamps or "
            "an .lp rewritten with fewer decimals): those are refitted, the earlier fit "
            "replaced once the new one is complete."
        ),
    ],
    out_dir: Annotated[
        Path,
        typer.Option("--out", help="New or empty folder for outputs, outside any session folder."),
    ],
    model: Annotated[
        str,
        typer.Option(
            "--model",
            help=f"{MODEL_HELP}.",
        ),
    ] = "auto",
    no_qa: Annotated[
        bool,
        typer.Option(
            "--no-qa",
            help="Skip the QA verdict (still said: fit.ptm or fit.rti where fewer images hold "
            "signal, not black or saturated throughout, than the model has coefficients; the "
            "normal maps where those images cannot determine a normal).",
        ),
    ] = False,
    no_ptm: Annotated[bool, typer.Option("--no-ptm", help="Do not write fit.ptm.")] = False,
    no_hsh: Annotated[bool, typer.Option("--no-hsh", help="Do not write fit.rti.")] = False,
    no_normals: Annotated[
        bool, typer.Option("--no-normals", help="Do not fit normal and albedo maps.")
    ] = False,
    export_encoding: Annotated[
        str,
        typer.Option(
            "--export-encoding",
            help="What fit.ptm and fit.rti hold: srgb (the photographs' JPEG values, as "
            "RTIBuilder writes them: what RTIViewer and relight show as they are) or linear "
            "(the linear light the normals are fitted to; darker in a viewer).",
        ),
    ] = "srgb",
    hsh_order: Annotated[
        int | None,
        typer.Option(
            "--hsh-order",
            help="The HSH order of fit.rti: 1 (4 terms), 2 (9) or 3 (16). Default: the lowest "
            "order within 5% of the best held-out error (5-fold cross-validation over the "
            "lights), with clipped highlights kept in that evidence; an HSH --model is written "
            "as named.",
        ),
    ] = None,
    white_level: Annotated[
        int | None,
        typer.Option(
            "--white-level",
            help="The code 16-bit images saturate at (their full scale), where it is not 65535: "
            "4095 for a 12-bit camera's data stored unscaled. Default: 65535, or read from an "
            "imported acquisition's images (clipped at one value, shifted up, or never above "
            "a 10- or 12-bit top), as the fit says; --white-level 65535 keeps 65535.",
        ),
    ] = None,
    scheduler: Annotated[
        str | None,
        typer.Option(
            "--scheduler",
            help="Fit on Dask: 'threads' (this machine's cores, nothing to set up) or the "
            "address of a Dask scheduler (tcp://host:8786; its workers must see the session "
            "files at the same paths, and run this same rti-rig, imported since its last "
            "change: restart them after editing an editable install). On a cluster, a batch "
            "runs its sessions as parallel tasks.",
        ),
    ] = None,
) -> None:
    """Fit a session: normal map, albedo, .ptm, .rti, relight .dome and a QA verdict.

    Exit codes: 0 every fit is written (a batch: each session done, refitted, skipped as
    finished earlier, or finished on a Dask worker); 1 every fit is in place but a session
    changed while it was fitted, so its fit is of the session as it was read (a batch: run
    the same command again to refit it; one session: fit it again into a new --out); 2 an
    error (a batch: a session failed, the others fitted); 130 / 143 / 129 stopped by Ctrl-C /
    SIGTERM / a hang-up (SIGHUP)."""
    from rti_rig.app.usecases.fit_memory import use_one_heap

    # One malloc heap for this process, before any decode or reader thread starts: it is
    # process-wide and permanent, so the command (one fit or one batch per process) sets it,
    # not the use case, which a Dask worker or a test process also runs (fit_memory).
    use_one_heap()

    written: list[bool] = []  # set once every output is written (what a stop then says)
    cluster = scheduler not in (None, "threads")  # the fit_dask.THREADS value, not imported
    try:
        # a SIGTERM (timeout, a scheduler) stops a fit as Ctrl-C does, through its clean-up:
        # without it the process ended at once, leaving half-written outputs (fit.ptm.part, a
        # normal map without its QA) in --out, and the same command was refused: "not empty"
        with sigterm_stops():
            _fit_command(
                written,
                sources,
                out_dir,
                model,
                no_qa,
                no_ptm,
                no_hsh,
                no_normals,
                export_encoding,
                hsh_order,
                white_level,
                scheduler,
            )
    except (KeyboardInterrupt, Terminated) as exc:
        signum = stop_signal(exc)
        raise _stopped(signum, out_dir, len(sources) > 1, bool(written), cluster) from None


def _fit_command(  # type: ignore[no-untyped-def]
    written: list[bool],
    sources: list[Path],
    out_dir: Path,
    model: str,
    no_qa: bool,
    no_ptm: bool,
    no_hsh: bool,
    no_normals: bool,
    export_encoding: str,
    hsh_order: int | None,
    white_level: int | None,
    scheduler: str | None,
) -> None:
    """The body of :func:`fit`, run under its stop handling (``written`` gets True once every
    output is written)."""
    from rti_rig.app.usecases.fit import FitRequest, run_fit
    from rti_rig.app.usecases.fit_batch import Outcome, changed_while_fitted, run_batch
    from rti_rig.reconstruct.registry import model_spec

    try:
        if export_encoding not in ("srgb", "linear"):
            raise RtiRigError(
                f"--export-encoding {export_encoding!r}: choose srgb (what viewers expect) or "
                "linear"
            )
        if hsh_order is not None and hsh_order not in (1, 2, 3):
            raise RtiRigError(f"--hsh-order {hsh_order}: choose 1, 2 or 3")
        if hsh_order is not None and no_hsh:  # it had been accepted and ignored
            raise RtiRigError("--hsh-order sets fit.rti's order, which --no-hsh does not write")
        if model != "auto":
            try:
                spec = model_spec(model)
            except ValueError:
                raise RtiRigError(f"--model {model!r} is not known; choose {MODEL_HELP}") from None
            if (
                hsh_order is not None
                and spec.name.startswith("hsh")
                and spec.name != f"hsh{hsh_order}"
            ):
                # fit.rti was written at the order asked, the model named in no file, with
                # "Model: hsh2: chosen by --model" above "fit.rti: hsh1: asked for"
                raise RtiRigError(
                    f"--model {model} and --hsh-order {hsh_order} disagree: an HSH --model is "
                    "the fit.rti written; give one of them (--model "
                    f"{spec.name} for order {spec.name[3:]}, or --hsh-order {hsh_order} with "
                    "another --model)"
                )
        request = FitRequest(
            sources[0],
            out_dir,
            model=model,
            qa=not no_qa,
            write_ptm=not no_ptm,
            write_hsh=not no_hsh,
            write_normals=not no_normals,
            export_encoding=export_encoding,
            hsh_order=hsh_order,
            white_level=white_level,
        )
        if len(sources) > 1:
            if scheduler is None:
                items = run_batch(sources, out_dir, request)
            else:
                from rti_rig.app.usecases.fit_dask import run_batch_dask

                items = run_batch_dask(sources, out_dir, request, scheduler)
            written.append(True)
            for item in items:
                line = f"{shown_path(item.source)}: {item.status}"
                if item.verdict:
                    line += f"; QA verdict: {item.verdict}"
                out.print(escape(line))
                said = [("note", t) for t in item.notes] + [("warning", t) for t in item.warnings]
                for kind, text in said:
                    line = f"  [yellow]{kind}:[/] {escape(text)}"
                    err.print(line, highlight=False, soft_wrap=True)
            if any(i.outcome is Outcome.FAILED for i in items):
                raise typer.Exit(code=2)
            stale = [i for i in items if i.stale]
            if stale:
                # each fit is in place, but not of the session there now: a script chaining
                # batches had exit 0 and only the session's line to tell it
                err.print(
                    f"[yellow]{len(stale)} of {len(items)} fit(s) are of their session as it "
                    "was read, not as it is now (it changed while it was fitted):[/] run the "
                    "same command again once the session is no longer being changed (exit 1)",
                    soft_wrap=True,
                )
                raise typer.Exit(code=1)
            return
        if scheduler is None:
            result = run_fit(request)
        else:
            from rti_rig.app.usecases.fit_dask import run_fit_dask

            result = run_fit_dask(request, scheduler)
        written.append(True)
        # as a batch does for each session: the fit's record was taken before its images
        # were read, so a resume (or a replaced image) while it ran is seen here; a single
        # fit had exited 0 with a fit of fewer images than its session now holds
        moved_on = changed_while_fitted(out_dir, request.source)
    except RtiRigError as exc:
        raise fail(exc) from None
    print_notes(result.notes)
    out.print(f"Model: {escape(result.reason)}")
    if result.rti:
        out.print(f"fit.rti: {escape(result.rti)}")
    if result.normals_from:
        out.print(f"Normals: {NORMALS_SHOWN.get(result.normals_from, result.normals_from)}")
    for text in result.warnings:
        err.print(f"[yellow]warning:[/] {escape(text)}")
    out.print(
        f"Wrote {len(result.files)} files to {escape(shown_path(out_dir))} "
        f"in {result.seconds:.1f} s"
    )
    if result.qa is not None:
        from rti_rig.app.usecases.fit import reshoot_in_place

        source = Path(request.source)
        command = reshoot_in_place(source, result.qa) if source.is_dir() else None
        again = f"; {command}" if command else ""
        out.print(f"QA verdict: {escape(result.qa.verdict + again)}")
    if moved_on is not None:
        err.print(
            f"[yellow]warning:[/] {escape(shown_path(request.source))} changed while it was "
            f"being fitted ({escape(moved_on)}): the fit in {escape(shown_path(out_dir))} is of "
            "the session as it was read, not as it is now; once the session is no longer being "
            "changed, fit it again into a new --out (exit 1)",
            soft_wrap=True,
        )
        raise typer.Exit(code=1)
