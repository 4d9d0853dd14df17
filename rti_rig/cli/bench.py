"""`rti-rig bench`: the benchmarks of a checkout (imported lazily: they are not installed)."""

from __future__ import annotations

import signal
from collections.abc import Sequence
from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer
from rich.markup import escape

from rti_rig.cli.app import app, err, fail, out, print_notes, shown_path, stop_exit_code
from rti_rig.cli.stopping import Terminated, sigterm_stops, stop_signal
from rti_rig.core.deferred_signals import stop_words
from rti_rig.core.errors import RtiRigError
from rti_rig.core.out_folders import (
    ensure_writable_folder,
    free_name,
    refuse_a_file_in_the_way,
)
from rti_rig.core.shell_words import shell_word

if TYPE_CHECKING:
    from benchmarks.tradeoff import Row, TradeoffSettings

bench_app = typer.Typer(
    help="Benchmarks: the speed/accuracy trade, on the simulator or on your own acquisition."
)
app.add_typer(bench_app, name="bench")


def _plain(text: str) -> None:
    """Print ``text`` as it is. Why: the trade-off's progress lines and summary carry paths
    (the acquisition's, the --out folder's), and rich's markup took a folder's ``[v2]`` for a
    style tag and dropped it (a ``[/x]`` would have raised MarkupError)."""
    out.print(text, highlight=False, markup=False)


def _find_benchmarks() -> None:
    """Make the checkout's ``benchmarks`` package importable for the installed command.

    The ``rti-rig`` script's ``sys.path`` holds neither the current folder nor the checkout
    (only ``python -m rti_rig`` puts the current folder first), so ``rti-rig bench`` failed
    even when run from the repository as the README shows. An editable install (``pip install
    -e .``, as the README does) runs the package from the checkout: its ``benchmarks/`` folder
    lies next to ``rti_rig/``. The current folder is tried next (a checkout run from there).
    The package's own checkout goes first, so that another importable ``benchmarks`` (an
    unrelated package, a folder the command happens to run in) is not taken for ours."""
    import sys

    import rti_rig

    here = Path(rti_rig.__file__).resolve().parent.parent
    for root in (here, Path.cwd()):
        if (root / "benchmarks" / "tradeoff.py").is_file():
            while str(root) in sys.path:  # first, even if it is already further down
                sys.path.remove(str(root))
            sys.path.insert(0, str(root))
            return


@bench_app.command("tradeoff")
def bench_tradeoff(
    out_dir: Annotated[
        Path | None,
        typer.Option(
            "--out",
            help="Folder to write results.csv, the plots and summary.md into (the repository's "
            "committed results are docs/research/tradeoff). Without it the summary is only "
            "printed.",
        ),
    ] = None,
    quick: Annotated[
        bool,
        typer.Option(
            "--quick", help="Fewer scenes, light counts and pixels (minutes; not with --from)."
        ),
    ] = False,
    from_lp: Annotated[
        Path | None,
        typer.Option(
            "--from",
            help="A dense acquisition of your own (an .lp with its images beside it): the trade "
            "for uniform, optimal and adaptive against all its lights.",
        ),
    ] = None,
    force: Annotated[
        bool,
        typer.Option(
            "--force",
            help="Write into an --out folder that is not empty (replacing results); never "
            "into a session's folder or the --from acquisition's own.",
        ),
    ] = False,
    rig: Annotated[
        Path | None,
        typer.Option(
            "--rig",
            help="With --from: your dome's rig config, whose \\[timing] and \\[camera] "
            "exposure_s give the session time, or its firmware's own hold window where that "
            "is longer (RTIPy's); else the replayed dome's defaults, 1.17 s a light. The "
            "advice names no session of more lights than that dome has LEDs.",
        ),
    ] = None,
    target_deg: Annotated[
        list[float] | None,
        typer.Option(
            "--target-deg",
            help="With --from: a mean normal error (degrees) to find the fewest lights for; "
            "repeat for several (default 1, 2 and 3).",
        ),
    ] = None,
    target_db: Annotated[
        list[float] | None,
        typer.Option(
            "--target-db",
            help="With --from: a relighting loss (dB below every light's fit.rti) to find the "
            "fewest lights for; repeat for several (default 0.5, 1 and 2).",
        ),
    ] = None,
) -> None:
    """Error against number of lights and session time, for every planner, on simulated scenes
    (or on your own acquisition with --from).

    Nothing is written unless --out is given, so a quick run never replaces the committed
    full-run results. The benchmarks live in the repository's benchmarks/ folder (they are not
    installed): run this from a checkout."""
    _find_benchmarks()
    try:
        import benchmarks.tradeoff  # found: _tradeoff imports from it
        import benchmarks.tradeoff_from  # noqa: F401
    except ImportError:
        raise fail(
            RtiRigError(
                "rti-rig bench runs the benchmarks of a checkout of the rti-rig repository "
                "(they are not installed): install rti-rig from a checkout with 'pip install "
                "-e .', or run it from the repository's folder"
            )
        ) from None
    # the fits' trust warnings (a layout too sparse for HSH3 ...) are information about a cell
    # of the table: shown as notes, not as Python warnings with a source line and file path,
    # each said once, and as the sentence it is (they had led with the warning's class name,
    # "RegularisedFitWarning: hsh1 fit ridge-regularised ...", the same note twice in a row)
    import warnings

    said: set[str] = set()

    def _as_note(message, category, *_args, **_kwargs):  # type: ignore[no-untyped-def]
        text = str(message)
        if text not in said:
            said.add(text)
            err.print(f"[yellow]note:[/] {escape(text)}", soft_wrap=True)

    with warnings.catch_warnings():  # restored after: the CLI may run inside a test process
        warnings.showwarning = _as_note
        _tradeoff(out_dir, quick, from_lp, force, rig, (target_deg or [], target_db or []))


def _acquisition_lp(given: Path, notes: list[str] | None = None) -> Path:
    """The ``.lp`` of ``--from``: the file, a session's ``lights.lp``, or a folder's only
    ``.lp``, as ``rti-rig fit`` takes a folder ("Is a directory" had been the answer).

    A session folder (rti-rig's manifest beside its ``lights.lp``) is read from its
    ``lights.lp`` whatever other ``.lp`` lies beside it, as ``fit`` reads it: one written into
    it by ``export-lp --linear`` (``demo_linear.lp``) had the session refused as "a folder with
    2 .lp files", though its own lights are never in doubt. The others are named in a note
    (``notes``). Any other folder with several ``.lp`` stays refused: which lists the
    acquisition cannot be told.

    A file not named ``.lp`` is refused by name, as ``fit`` and ``run`` refuse it: read as an
    ``.lp``, an image had been told its "line 1 holds NUL bytes" (save it again as UTF-8 text)
    and a rig config "line 4: expected 'name x y z'"."""
    if not given.is_dir():
        if given.exists() and given.suffix.lower() != ".lp":
            raise RtiRigError(
                f"--from {shown_path(given)}: not an .lp file; give the .lp that lists the "
                "acquisition's images, with the images beside it (or a session folder: its "
                "lights.lp)"
            )
        return given
    from rti_rig.core.lp_format import acquisition_lp_files, lp_name_from
    from rti_rig.runtime.session import LP_NAME, MANIFEST

    found = acquisition_lp_files(given)  # an RTIBuilder project's in its assembly-files/
    own = given / LP_NAME
    if (given / MANIFEST).is_file() and own.is_file():
        others = [p for p in found if p.resolve() != own.resolve()]
        if others and notes is not None:
            names = ", ".join(lp_name_from(given, p) for p in others[:5])
            notes.append(
                f"--from {shown_path(given)} is an rti-rig session: its {LP_NAME} is read, not "
                f"the other .lp beside it ({names}" + (", …)" if len(others) > 5 else ")") + "; "
                "give one of those instead of the folder to trade on it"
            )
        return own
    if len(found) == 1:
        return found[0]
    names = ", ".join(lp_name_from(given, p) for p in found[:5])
    raise RtiRigError(
        f"--from {shown_path(given)}: a folder with "
        + (
            f"{len(found)} .lp files ({names}" + (", …)" if len(found) > 5 else ")")
            if found
            else "no .lp file"
        )
        + "; give the .lp of the acquisition itself"
    )


def _in_assembly_files(lp: Path) -> bool:
    """Whether ``lp`` is an RTIBuilder project's, in its ``assembly-files/`` folder."""
    from rti_rig.core.lp_format import ASSEMBLY_FILES

    return lp.resolve().parent.name.casefold() == ASSEMBLY_FILES


def _check_out_folder(
    out_dir: Path, force: bool, acquisition: Sequence[Path] = (), given: Sequence[Path] = ()
) -> None:
    """Refuse, before minutes of computing, a folder whose files the results would replace.

    A session folder (or one inside it) is refused even with ``--force``: nothing captured is
    ever overwritten; so is a folder of the ``--from`` acquisition (``acquisition``: its .lp
    and image files), where ``--force`` had put results.csv, summary.md and four PNG plots
    among the recorded images (RTIBuilder imports a jpeg-exports folder's images whole). A
    new folder inside it is written as ``run`` and ``fit`` write one. Any other folder that
    is not empty needs ``--force`` (a user's own summary.md had been replaced without a
    word)."""
    from rti_rig.runtime.session import MANIFEST

    # first, as it says a file given for a folder, or a folder the user may not look into
    # (``--out /root/x`` for another user), by name: the session check below had raised
    # that PermissionError as a traceback
    refuse_a_file_in_the_way(out_dir)
    for folder in (out_dir.resolve(), *out_dir.resolve().parents):
        if (folder / MANIFEST).is_file():
            raise RtiRigError(
                f"--out {shown_path(out_dir)} is inside the session in {shown_path(folder)}; a "
                "session's folder is never written into: choose another folder"
            )
    # the folder an image is listed in, and the one its file is in when it is a link (images
    # linked into a project's jpeg-exports/ from a card's copy resolve to the card's folder)
    held = {p.parent.resolve() for p in acquisition} | {p.resolve().parent for p in acquisition}
    # and the folder given as --from, and an RTIBuilder project's own (its .lp is in
    # assembly-files/, its images in jpeg-exports/): `--out PROJ --force` had put the results
    # beside those two folders, where only they had been refused
    held |= {f.resolve() for f in given if f.is_dir()}
    held |= {p.resolve().parent.parent for p in acquisition[:1] if _in_assembly_files(p)}
    if out_dir.resolve() in held:
        raise RtiRigError(
            f"--out {shown_path(out_dir)} holds the acquisition --from reads (its .lp or images): "
            "its folder is never written into, even with --force; choose another folder (a new "
            "one inside it will do)"
        )
    if out_dir.is_dir() and any(out_dir.iterdir()) and not force:
        raise RtiRigError(
            f"--out {shown_path(out_dir)} is not empty: its results.csv, summary.md and plots "
            "would be replaced; choose an empty or new folder, or give --force"
        )
    ensure_writable_folder(out_dir)


def _first_missing(folder: Path) -> Path | None:
    """The outermost of ``folder`` and its parents that does not exist yet (None if it
    exists): what :func:`_check_out_folder` will create."""
    missing = None
    for path in (folder.absolute(), *folder.absolute().parents):
        try:
            if path.exists() or path.is_symlink():
                break
        except OSError:  # a folder not to be looked into: nothing here is this run's to remove
            return None
        missing = path
    return missing


def _unmake(folder: Path | None, made: Path | None) -> None:
    """Remove the folders this run created for ``--out`` (``folder`` up to ``made``) while
    they are still empty. Why: a trade stopped or refused before its results were written
    said "nothing written to OUT" and left OUT behind, empty, so the same command run again
    met a folder it had made itself; a folder that was there before, or holds anything, is
    never touched."""
    if folder is None or made is None:
        return
    path = folder.absolute()
    while True:
        try:
            path.rmdir()  # only an empty folder goes
        except OSError:
            return
        if path == made:
            return
        path = path.parent


def _nothing_written(options: str) -> str:
    """What is said after a trade-off run without ``--out``: the same command with a folder not
    there yet (``options``: its own, as shell words). Why: "give --out DIR" pasted as printed
    wrote the results into a folder named DIR (a second time, refused as not empty). The
    command ends the line: closed by a parenthesis, its last word selected to the line's end
    read ``tradeoff)``, which a shell refuses."""
    keep = shell_word(free_name(Path("tradeoff"), folder=True))
    return (
        "nothing written; to keep the results, run it with --out: rti-rig bench tradeoff"
        f"{options} --out {keep}"
    )


def _stopped_midway(
    rows: list[Row],
    settings: TradeoffSettings,
    out_dir: Path | None,
    command: str,
    seconds: float,
    signum: signal.Signals,
) -> None:
    """A stopped simulated trade-off: the scenes measured whole (``rows``) written and said as
    a partial table, the scene cut short and those not begun named. Why whole scenes only: a
    scene's verdicts compare its plans across every N, which a cut-short scene lacks."""
    from benchmarks.tradeoff import plot, summarise, write_csv

    why = stop_words(signum)
    measured = tuple(dict.fromkeys(r.scene for r in rows))
    missing = [s for s in settings.scenes if s not in measured]
    if not measured:
        where = "" if out_dir is None else f" to {shown_path(out_dir)}"
        err.print(
            f"Stopped ({why}) before a scene was measured whole: nothing written{where}",
            markup=False,
            highlight=False,
            soft_wrap=True,
        )
        return
    said = (
        f"Stopped ({why}): {len(measured)} of {len(settings.scenes)} scenes measured whole "
        f"({', '.join(measured)}); not measured: {', '.join(missing)}"
    )
    text = summarise(rows, replace(settings, scenes=measured), seconds, command, said)
    # a folder given with --force that holds a run's results keeps them: a whole run's table
    # is not replaced by a part of one
    held = out_dir is not None and any(
        (out_dir / name).exists() for name in ("results.csv", "summary.md")
    )
    if out_dir is not None and not held:
        out_dir.mkdir(parents=True, exist_ok=True)
        write_csv(rows, out_dir / "results.csv")
        plot(rows, out_dir)
        (out_dir / "summary.md").write_text(text, encoding="utf-8")
    _plain(text)
    kept = (
        "nothing written"
        if out_dir is None
        else f"the results already in {shown_path(out_dir)} are left as they were (the partial "
        "table is printed above)"
        if held
        else f"the partial results are in {shown_path(out_dir)} (summary.md says it is partial)"
    )
    err.print(f"{said}; {kept}", markup=False, highlight=False, soft_wrap=True)


def _tradeoff(
    out_dir: Path | None,
    quick: bool,
    from_lp: Path | None,
    force: bool,
    rig: Path | None = None,
    given_targets: tuple[Sequence[float], Sequence[float]] = ((), ()),
) -> None:
    """The body of ``bench tradeoff``, once the command has found the benchmarks;
    ``given_targets``: ``--target-deg`` and ``--target-db`` as given."""
    import time

    from benchmarks.tradeoff import TradeoffSettings, plot, run_tradeoff, summarise, write_csv
    from benchmarks.tradeoff_from import (
        bench_from,
        check_acquisition,
        checked_targets,
        rig_facts,
    )

    if any(given_targets) and from_lp is None:  # accepted and ignored, they would change nothing
        raise fail(
            RtiRigError(
                "--target-deg and --target-db set the advice of the trade on your own "
                "acquisition: they go with --from ACQ/dirs.lp (the simulated trade gives no "
                "advice)"
            )
        )
    try:  # before minutes of computing, not after
        targets = checked_targets(*given_targets)
    except RtiRigError as exc:
        raise fail(exc) from None

    per_light: tuple[float, str] | None = None  # the rig's time per light, read once
    rig_lights: int | None = None  # and its LEDs, from the same reading
    if rig is not None:  # its config read before minutes of computing, not after
        if from_lp is None:
            raise fail(
                RtiRigError(
                    "--rig gives the session time of the trade on your acquisition: it goes "
                    "with --from ACQ/dirs.lp (the simulated trade times the rigs it runs)"
                )
            )
        try:
            per_light, rig_lights = rig_facts(rig)
        except RtiRigError as exc:
            raise fail(exc) from None

    if from_lp is not None and quick:  # accepted and ignored, it had changed nothing
        raise fail(
            RtiRigError(
                "--quick has no effect with --from (the trade is measured on every light of "
                "your acquisition): drop --quick"
            )
        )
    acquisition: list[Path] = []  # the --from .lp and its images: never written among
    given_from = [] if from_lp is None else [from_lp]  # as given: a folder, before its .lp
    if from_lp is not None:
        # its images before the --out folder is made: a refused acquisition had left an
        # empty --out folder behind
        try:
            notes: list[str] = []
            from_lp = _acquisition_lp(from_lp, notes)
            acquisition = [from_lp, *check_acquisition(from_lp, notes)]
        except RtiRigError as exc:
            print_notes(notes)  # what the reader noted, said with the refusal as on a pass
            raise fail(exc) from None
        print_notes(notes)
    made: Path | None = None  # the first folder of --out this run creates, if any
    if out_dir is not None:  # before minutes of computing, not after
        made = _first_missing(out_dir)
        try:
            _check_out_folder(out_dir, force, acquisition, given_from)
        except RtiRigError as exc:
            _unmake(out_dir, made)
            raise fail(exc) from None
    if from_lp is not None:
        try:
            with sigterm_stops():
                text = bench_from(
                    from_lp,
                    out_dir,
                    _plain,
                    force=force,
                    rig=rig,
                    per_light=per_light,
                    targets=targets,
                    rig_lights=rig_lights,
                )
        except (KeyboardInterrupt, Terminated) as exc:
            _unmake(out_dir, made)
            # said, with what is on disk (only "stopped (Ctrl-C)" had been, an --out folder
            # left empty without a word): the trade on an acquisition is written at its end
            signum = stop_signal(exc)
            where = "" if out_dir is None else f" to {shown_path(out_dir)}"
            err.print(
                f"Stopped ({stop_words(signum)}) during the trade on {shown_path(from_lp)}: "
                f"nothing written{where} (its results are written once every layout is "
                "measured)",
                markup=False,
                highlight=False,
                soft_wrap=True,
            )
            raise typer.Exit(code=stop_exit_code(signum)) from None
        except RtiRigError as exc:
            _unmake(out_dir, made)
            raise fail(exc) from None
        except ValueError as exc:
            _unmake(out_dir, made)
            raise fail(RtiRigError(str(exc))) from None
        _plain(text)
        if out_dir is None:
            again = f" --from {shell_word(from_lp)}"
            if rig is not None:
                again += f" --rig {shell_word(rig)}"
            again += targets.options()
            _plain(_nothing_written(again))
        return

    settings = TradeoffSettings.quick() if quick else TradeoffSettings()
    t0 = time.perf_counter()
    rows: list[Row] = []
    command = "rti-rig bench tradeoff" + (" --quick" if quick else "")
    if out_dir is not None:
        # one shell word, as the command is pasted from summary.md (a folder with a space had
        # been written bare, and pasted ran into two arguments)
        command += f" --out {shell_word(out_dir)}" + (" --force" if force else "")
    try:
        with sigterm_stops():
            run_tradeoff(settings, progress=_plain, done=rows)
    except (KeyboardInterrupt, Terminated) as exc:
        # the scenes measured whole are kept and said (a Ctrl-C after minutes had said only
        # "stopped (Ctrl-C)": every scene measured was lost, --out left empty)
        signum = stop_signal(exc)
        _stopped_midway(rows, settings, out_dir, command, time.perf_counter() - t0, signum)
        _unmake(out_dir, made)  # only if nothing was written into it
        raise typer.Exit(code=stop_exit_code(signum)) from None
    text = summarise(rows, settings, time.perf_counter() - t0, command)
    if out_dir is not None:
        out_dir.mkdir(parents=True, exist_ok=True)
        write_csv(rows, out_dir / "results.csv")
        plot(rows, out_dir)
        (out_dir / "summary.md").write_text(text, encoding="utf-8")
    _plain(text)
    if out_dir is None:
        _plain(_nothing_written(" --quick" if quick else ""))
