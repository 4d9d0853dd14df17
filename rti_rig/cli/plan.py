"""`rti-rig plan`: parse, call :func:`rti_rig.app.usecases.plan.plan_lights`, print the report."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any

import typer
from rich.markup import escape

from rti_rig.cli.app import (
    FILE,
    app,
    err,
    fail,
    option_given,
    out,
    parse_az_el,
    print_notes,
    shown_path,
    stop_exit_code,
)
from rti_rig.cli.stopping import Stamp, Terminated, sigterm_stops, stamp, stop_signal, written_since
from rti_rig.core.deferred_signals import stop_words
from rti_rig.core.errors import RtiRigError

# the help's figures (numpy-free): a plan's minimum is the normal's (planner.make_plan)
from rti_rig.core.fit_minimums import (
    FIT_MINIMUMS,
    NORMAL_ERROR_LIMIT_DEG,
    NORMAL_MIN_LIGHTS,
    NORMAL_NOISE,
    PLAN_DEFAULT_LIGHTS,
)

if TYPE_CHECKING:
    from rti_rig.app.usecases.plan import PlanLightsRequest


@app.command()
def plan(
    ctx: typer.Context,
    preview: Annotated[
        Path | None,
        typer.Argument(
            help="One preview image of the object (8-bit JPEG/PNG/TIFF = sRGB, 16-bit "
            "PNG/TIFF = linear, as 'rti-rig run' writes them; a camera RAW file - DNG, CR2, "
            "NEF, ARW... - is decoded linearly, its light taken from --preview-light, the "
            "rti-rig session it was captured in, or a --rig .lp that lists it), or the "
            "session folder "
            "'rti-rig preview' wrote. "
            "Needed by 'kmeans'; without it 'optimal' plans for a level surface (matte unless "
            "--material glossy)."
        ),
    ] = None,
    rig: Annotated[
        Path | None,
        typer.Option(
            "--rig",
            help="Rig config TOML, or a bare .lp meaning 'a dome with exactly these lights' "
            "(default: the rig config the preview's rti-rig session records, with a note; "
            "else the simulated 48-LED dome shipped with rti-rig, with a note).",
        ),
    ] = None,
    lights: Annotated[
        int,
        typer.Option(
            "--lights",
            help=f"Number of lights to plan: at least {NORMAL_MIN_LIGHTS}; below "
            f"{FIT_MINIMUMS.rti_file} a note says what `rti-rig fit` will not make of them.",
        ),
    ] = PLAN_DEFAULT_LIGHTS,
    method: Annotated[
        str | None,
        typer.Option(
            "--method",
            help="uniform (homogeneous, no preview), kmeans (the paper's: k-means on the "
            "preview's normals) or optimal (least expected error for the objective). "
            "Default: optimal with a preview, uniform without.",
        ),
    ] = None,
    objective: Annotated[
        str | None,
        typer.Option(
            "--objective",
            help="What the session is for: normals (surface inspection, normal maps; default) "
            "or relight (interactive relighting with PTM/HSH).",
        ),
    ] = None,
    preview_light: Annotated[
        str | None,
        typer.Option(
            "--preview-light",
            help="Azimuth,elevation of the preview's light in degrees (frame of the .lp files). "
            "When omitted: the light the preview's rti-rig session recorded, or the line of "
            "the bare .lp given as --rig that lists the image, else estimated from the image's "
            "shading (its error not known: 17–59° on a real icon's previews, 106° on another "
            "real image). Given, it is "
            "used, with a note when it is more than 1° from the light recorded.",
        ),
    ] = None,
    depth_model: Annotated[
        Path | None,
        typer.Option(
            "--depth-model",
            help="A monocular depth network (.onnx, MiDaS / Depth Anything / LeReS style) to "
            "estimate the relief; without it, shape from shading is used.",
        ),
    ] = None,
    min_elevation_deg: Annotated[
        float, typer.Option("--min-elevation-deg", help="Lowest elevation allowed (degrees).")
    ] = 0.0,
    max_elevation_deg: Annotated[
        float,
        typer.Option(
            "--max-elevation-deg",
            help="Highest elevation allowed (degrees; 90 = up to the zenith). Lights near the "
            "camera axis put mirror highlights on a level glossy object: 60 helped on gilding, "
            "varnish and polished metal in the tests and cost on brushed steel at 20-30 lights "
            "and on a steeply tilted object (docs/research/planner.md).",
        ),
    ] = 90.0,
    signal_noise: Annotated[
        float | None,
        typer.Option(
            "--signal-noise",
            help="Image noise proportional to the signal, as a fraction (normals objective): "
            "0.05 models 8-bit JPEG captures on a dome without LED intensity calibration "
            "(docs/research/planner.md); 0 models additive noise only. Default: the rig config's "
            # escaped: rich help reads a bare [camera] as markup and drops it
            "\\[camera] signal_noise (0 if absent, and for a bare .lp).",
        ),
    ] = None,
    material: Annotated[
        str,
        typer.Option(
            "--material",
            help="What you know of the surface: auto (highlights read from the preview; "
            "default), matte, or glossy (polished metal, gilding, varnish: one preview of a "
            "flat glossy object does not show its gloss; docs/research/planner.md).",
        ),
    ] = "auto",
    out_file: Annotated[
        Path,
        typer.Option(
            "--out",
            metavar=FILE,
            help="Plan file to write (.lp). A name that does not end in .lp is still written, "
            "with a note to rename it: relight, RTIBuilder and rti-rig fit only read files "
            "ending in .lp (rti-rig run --plan reads it as it is).",
        ),
    ] = Path("plan.lp"),
    figure: Annotated[
        Path | None,
        typer.Option(
            "--figure",
            metavar=FILE,
            help="Also draw the plan as a map (.png, .svg or .pdf): the lights seen from above, "
            "numbered in firing order, on the dome's LEDs or the arm's reach.",
        ),
    ] = None,
    force: Annotated[
        bool, typer.Option("--force", help="Overwrite an existing plan file (and --figure).")
    ] = False,
    allow_no_normals: Annotated[
        bool,
        typer.Option(
            "--allow-no-normals",
            help="Plan lights that cannot determine a surface normal (all in one plane "
            "through the object, e.g. one ring of low lights for a relightable PTM/HSH, or "
            f"bunched at the zenith, or normals predicted more than {NORMAL_ERROR_LIMIT_DEG:g}° "
            f"off at {NORMAL_NOISE:.0%} image noise) "
            "with a warning, in place of the refusal. rti-rig fit then writes no normal maps, "
            "and its relighting files are ridge-regularised guesses along the direction the "
            "lights miss; run the plan with rti-rig run RIG.toml --plan "
            "PLAN.lp --out DIR --allow-no-normals (the warning names your rig and plan).",
        ),
    ] = False,
) -> None:
    """Plan an ordered set of lights from one preview shot and write it as an .lp file.

    Without PREVIEW: `uniform` (the default then) or `optimal`, which plans for a level surface,
    matte unless `--material glossy` (on the benchmarks in docs/research/planner.md it did as
    well as with a preview).

    The plan's lights are the rig's own (a dome's LEDs, used once each; an arm's reachable
    directions, ordered for the least move time: of its servos when the config has
    \\[arm.dynamixel], of the simulated arm's \\[arm] speed and limits otherwise, never wrapping
    the azimuth past its stop); `rti-rig run RIG --plan PLAN.lp` runs it.
    """
    # the arm's order as rti_rig.app.compose.arm_order_for gives it (tests/cli/test_plan_help.py)
    from rti_rig.app.config import default_config_path
    from rti_rig.app.usecases.plan import PlanLightsRequest

    try:
        request = PlanLightsRequest(
            rig=rig or default_config_path(),
            # without --rig, a preview's rti-rig session says which rig it was shot on
            rig_given=rig is not None,
            out_file=out_file,
            lights=lights,
            # the default had been refused as if asked for ("asked for 12 lights but the dome
            # has only 8 LEDs") on the shipped 8-LED configs
            lights_given=option_given(ctx, "lights"),
            preview=preview,
            method=method,
            objective=objective,
            preview_light=parse_az_el(preview_light),
            depth_model=depth_model,
            min_elevation_deg=min_elevation_deg,
            max_elevation_deg=max_elevation_deg,
            min_elevation_given=option_given(ctx, "min_elevation_deg"),
            max_elevation_given=option_given(ctx, "max_elevation_deg"),
            signal_noise=signal_noise,
            material=material,
            figure=figure,
            force=force,
            allow_no_normals=allow_no_normals,
        )
    except RtiRigError as exc:
        raise fail(exc) from None
    before = stamp(out_file)  # a file there already (--force) is not one this plan wrote
    done: dict[str, Any] = {}
    try:
        # SIGTERM as Ctrl-C: without a handler it ended the plan mid-write, leaving a hidden
        # .map.partial.png (or .plan.lp.tmp) beside the file asked for, and said nothing
        with sigterm_stops():
            _plan_and_report(request, done)
    except (KeyboardInterrupt, Terminated) as exc:
        signum = stop_signal(exc)
        why = stop_words(signum)
        err.print(
            _stopped(why, request, before, done),
            markup=False,
            highlight=False,
            soft_wrap=True,
        )
        raise typer.Exit(code=stop_exit_code(signum)) from None


def _plan_and_report(request: PlanLightsRequest, done: dict[str, Any]) -> None:
    """Plan, write and report (and draw the map): the body of :func:`plan`, run under its stop
    handling; ``done`` gets ``planned`` once the plan is written and ``drawn`` once the map is.
    """
    from rti_rig.app.usecases.plan import draw_plan_figure, next_run_command, plan_lights

    try:
        planned = done["planned"] = _plan_showing_progress(request, plan_lights)
    except RtiRigError as exc:
        raise fail(exc) from None
    print_notes(planned.notes)
    for line in planned.report.lines():
        out.print(line, highlight=False, markup=False)
    out.print(  # the path as it is: a folder named "coin [draft]" is no markup
        f"Planned {len(planned.schedule)} lights ({_how_planned(planned)}) → "
        f"{shown_path(request.out_file)}",
        markup=False,
        highlight=False,
    )
    out.print(f"Next: {escape(next_run_command(planned))}", highlight=False, soft_wrap=True)
    if request.figure is not None:
        # after the report: a map that cannot be drawn must not hide a plan that was written
        try:
            draw_plan_figure(request, planned)
        except RtiRigError as exc:
            raise fail(exc) from None
        done["drawn"] = True
        out.print(f"Map of the plan → {escape(shown_path(request.figure))}")


def _plan_showing_progress(request: PlanLightsRequest, plan_lights: Any) -> Any:
    """``plan_lights(request)`` with a progress bar (on stderr, left as it ended) for an arm's
    stop-order search, shown from its first step: none for a dome, or an arm's order solved
    exactly (a few ms).

    Why: ``plan --rig rig_configs/simulated_arm.toml --lights 1000`` searched for over a
    minute with nothing on screen; the run's capture has had a bar, the plan had none."""
    from dataclasses import replace

    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn

    bar = Progress(
        TextColumn("{task.description}"),
        BarColumn(),
        MofNCompleteColumn(),
        TimeElapsedColumn(),
        console=err,
    )
    task: Any = None

    def told(done: int, total: int) -> None:
        nonlocal task
        if task is None:
            bar.start()
            task = bar.add_task("ordering the arm's stops for the least move time", total=total)
        bar.update(task, completed=done, total=total)

    try:
        return plan_lights(replace(request, order_progress=told))
    finally:
        if task is not None:
            bar.stop()


def _how_planned(planned: Any) -> str:
    """The method and objective as the summary says them, or, where the method kept its start
    layout unsearched, that layout and why.

    Why: ``--method optimal --lights 3`` keeps the uniform layout (three lights leave no
    redundancy to trade), and the summary said "(optimal, normals)" as if it had searched."""
    report = planned.report
    why, layout = report.kept_layout_why, report.start_layout
    if why is None or layout is None:
        return f"{planned.method}, {planned.objective}"
    return f"the {layout} layout, not optimised: {why}"


def _stopped(why: str, request: PlanLightsRequest, before: Stamp, done: dict[str, Any]) -> str:
    """What a stop (Ctrl-C, SIGTERM) of ``plan`` left, said as it is on disk.

    Why: a stop once the plan is on disk had said only "rti-rig: stopped (Ctrl-C)", and the
    next run refused the --out; a stop as the map's line is printed finds the map written (it
    had been said "not drawn" beside the map on disk); a stop before the plan is written says
    so, and that a file already there (--force) is the earlier one."""
    out_file, figure = request.out_file, request.figure
    planned = done.get("planned")
    if planned is None and not written_since(out_file, before):
        kept = "" if before is None else " (the file already there is as it was)"
        return (
            f"Stopped ({why}) while planning: no plan was written to {shown_path(out_file)}{kept}"
        )
    count = "" if planned is None else f" ({len(planned.schedule)} lights)"
    map_said = (
        ""
        if figure is None
        else f"; the map {shown_path(figure)} is written"
        if done.get("drawn")
        else f"; the map {shown_path(figure)} was not drawn"
    )
    return f"Stopped ({why}): the plan {shown_path(out_file)} is written{count}{map_said}"
