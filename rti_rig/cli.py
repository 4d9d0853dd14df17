"""The `rti-rig` command line: run sessions, plan lights, export `.lp` files.

Every user-facing failure is an :class:`~rti_rig.core.errors.RtiRigError` printed as one clear
message (file, line or key, and what to do) with exit status 2, never a traceback.
"""

from __future__ import annotations

import math
import os
import shlex
import signal
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any

import typer
from rich.console import Console
from rich.markup import escape
from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn

from rti_rig.core.errors import RtiRigError

if TYPE_CHECKING:
    pass

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


def _fail(exc: RtiRigError) -> typer.Exit:
    # the message is plain text: "[camera]" or "[dome.serial]" in it must not be read as markup
    err.print(f"[bold red]error:[/] {escape(str(exc))}", highlight=False, soft_wrap=True)
    return typer.Exit(code=2)


def _print_notes(notes) -> None:  # type: ignore[no-untyped-def]
    """What a tolerant reader accepted but the user should know (file, line, what was done)."""
    for note in notes:
        err.print(f"[yellow]note:[/] {escape(note)}", highlight=False, soft_wrap=True)


def _default_lights(loaded, geometry) -> int:  # type: ignore[no-untyped-def]
    from rti_rig.core.rig_geometry import DomeGeometry

    cfg = loaded.config
    if isinstance(geometry, DomeGeometry):
        assert cfg.dome is not None
        return cfg.dome.default_lights or geometry.count
    assert cfg.arm is not None
    return cfg.arm.default_lights


def _check_max_saturated(max_saturated: float) -> None:
    if not 0.0 <= max_saturated < 1.0:
        raise RtiRigError(
            f"--max-saturated {max_saturated:g}: give a fraction of pixels in [0, 1), "
            "e.g. 0.001 for 0.1 %"
        )


def _checked_rig(loaded, schedule):  # type: ignore[no-untyped-def]
    """The rig, opened, with ``schedule`` checked against it before anything moves.

    The rig is closed (lights off, arm stopped) if the check fails, whatever the exception.
    """
    from rti_rig.app.compose import build_rig
    from rti_rig.runtime.controller import validate_schedule

    rig = build_rig(loaded)
    try:
        validate_schedule(rig, schedule)
    except BaseException:
        rig.close()
        raise
    return rig


def _open_new_session(  # type: ignore[no-untyped-def]
    loaded, schedule, out_dir: Path, auto_exposure: bool, max_saturated: float
):
    """Check the folder, open and check the rig, meter if asked, make the folder.

    The folder is checked first, so nothing lights or moves for a session that could not be
    written; the rig is closed if anything after opening it fails, whatever the exception.
    """
    from rti_rig.runtime.session import SessionFolder

    SessionFolder.check_new(out_dir)
    rig = _checked_rig(loaded, schedule)
    try:
        if auto_exposure:
            schedule = _fix_exposure(rig, schedule, max_saturated)
        folder = SessionFolder.create(out_dir, len(schedule))
    except BaseException:
        rig.close()
        raise
    return rig, schedule, folder


@app.command()
def run(
    rig_config: Annotated[
        Path | None,
        typer.Argument(
            help="Rig config TOML (see rig_configs/), e.g. rig_configs/simulated_dome.toml. "
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
            "or the arm's default_lights).",
        ),
    ] = None,
    plan: Annotated[
        Path | None,
        typer.Option("--plan", help="Run this plan (.lp from 'rti-rig plan') instead."),
    ] = None,
    min_elevation_deg: Annotated[
        float,
        typer.Option("--min-elevation-deg", help="Elevation floor of the homogeneous layout."),
    ] = 0.0,
    max_elevation_deg: Annotated[
        float,
        typer.Option(
            "--max-elevation-deg",
            help="Elevation ceiling of the homogeneous layout (90 = up to the zenith; 60 keeps "
            "lights away from the camera axis, see 'plan --max-elevation-deg').",
        ),
    ] = 90.0,
    auto_exposure: Annotated[
        bool,
        typer.Option(
            "--auto-exposure",
            help="Before starting, meter at the brightest planned light (a short test series) "
            "and fix the exposure that keeps saturated pixels under --max-saturated.",
        ),
    ] = False,
    max_saturated: Annotated[
        float,
        typer.Option("--max-saturated", help="Largest fraction of saturated pixels allowed."),
    ] = 0.001,
    resume: Annotated[
        Path | None,
        typer.Option(
            "--resume",
            help="Continue an interrupted session folder: verify what is on disk and capture "
            "only the steps not yet done.",
        ),
    ] = None,
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
            help="Adaptive: stop once the estimated mean normal error is at most this many "
            "degrees (with --lights: whichever comes first).",
        ),
    ] = None,
) -> None:
    """Run a capture session (a dry run when the config's backend is 'simulated').

    Ctrl-C once stops after the current image; Ctrl-C twice or SIGTERM stops at once (lights
    off, arm stopped, and parked if the config says park_on_emergency_stop = true); SIGUSR1
    pauses or resumes between images. An interrupted session can be
    continued with --resume.
    """
    from rti_rig.app.compose import arm_order_for
    from rti_rig.app.config import load_rig_config, rig_geometry
    from rti_rig.core.lp_format import read_lp
    from rti_rig.core.schedule import LightSchedule
    from rti_rig.planner.from_lp import schedule_from_lp
    from rti_rig.planner.make_plan import check_elevation_band
    from rti_rig.planner.uniform import plan_uniform
    from rti_rig.runtime.session import SessionFolder

    source = None  # an adaptive session's step source (rti_rig.app.usecases.adaptive)
    try:
        _check_max_saturated(max_saturated)
        if resume is not None:
            if out_dir is not None or plan is not None or lights is not None:
                raise RtiRigError(
                    "--resume continues a session as planned: drop --out, --plan, --lights"
                )
            folder = SessionFolder.reopen(resume)
            manifest = folder.manifest
            config_path = rig_config or Path(manifest["rig"]["config_path"])
            loaded = load_rig_config(config_path)
            if loaded.sha256 != manifest["rig"].get("config_sha256"):
                err.print(
                    f"[yellow]note:[/] {escape(str(config_path))} has changed since the session "
                    "began; the remaining steps are checked against it before anything moves."
                )
            schedule = LightSchedule.from_dict(manifest["schedule"])
            out_dir = resume
            done = len(folder.done)
            out.print(
                f"Resuming {resume}: {done} of {len(schedule)} images verified on disk"
                + (
                    f", {len(folder.resume.recovered)} unverified file(s) moved to recovered/"
                    if folder.resume and folder.resume.recovered
                    else ""
                )
            )
            rig = _checked_rig(loaded, schedule)
            if "adaptive" in manifest:
                from rti_rig.app.usecases.adaptive import resume_adaptive_source

                try:
                    source = resume_adaptive_source(rig, folder)
                except BaseException:
                    rig.close()
                    raise
        elif adaptive or until_error is not None:
            from rti_rig.app.usecases.adaptive import open_adaptive_session

            if rig_config is None or out_dir is None:
                raise RtiRigError("give a RIG_CONFIG and --out DIR (or --resume SESSION_DIR)")
            if plan is not None or auto_exposure:
                raise RtiRigError("--adaptive chooses its own lights: drop --plan/--auto-exposure")
            loaded = load_rig_config(rig_config)
            _print_notes(loaded.notes)
            rig, schedule, folder, source = open_adaptive_session(
                loaded, out_dir, lights, until_error
            )
        else:
            if rig_config is None or out_dir is None:
                raise RtiRigError("give a RIG_CONFIG and --out DIR (or --resume SESSION_DIR)")
            loaded = load_rig_config(rig_config)
            _print_notes(loaded.notes)
            geometry = rig_geometry(loaded)
            if plan is not None:
                if lights is not None:
                    raise RtiRigError("give either --plan or --lights, not both")
                plan_notes: list[str] = []
                schedule = schedule_from_lp(
                    read_lp(plan, upper_hemisphere=True, notes=plan_notes), geometry, str(plan)
                )
                _print_notes(plan_notes)
            else:
                check_elevation_band(min_elevation_deg, max_elevation_deg)
                n = lights if lights is not None else _default_lights(loaded, geometry)
                schedule = plan_uniform(
                    geometry, n, min_elevation_deg, arm_order_for(loaded), max_elevation_deg
                )
            rig, schedule, folder = _open_new_session(
                loaded, schedule, out_dir, auto_exposure, max_saturated
            )
    except RtiRigError as exc:
        raise _fail(exc) from None
    with rig:
        _execute(rig, schedule, folder, out_dir, source)
    if source is not None:
        from rti_rig.app.usecases.adaptive import record_result

        result = source.conclude()
        record_result(out_dir, result)
        est = result["estimated_error_deg"]
        out.print(
            f"Adaptive: {result['lights_used']} lights; stopped: {result['stop']['reason']}; "
            f"estimated mean normal error {'n/a' if est is None else f'{est:.2f}°'}",
            highlight=False,
        )


def _fix_exposure(rig, schedule, max_saturated: float):  # type: ignore[no-untyped-def]
    """Meter the session's exposure with the camera driver layer's test series."""
    from rti_rig.drivers.cameras.exposure import meter_exposure
    from rti_rig.drivers.cameras.settings import ExposureRule
    from rti_rig.runtime.exposure_policy import fix_session_exposure

    cam = rig.camera_config
    rule = ExposureRule(
        max_saturated_fraction=max_saturated,
        headroom=1.25,  # other planned lights may be a little brighter than the metered one
        min_exposure_s=cam.min_exposure_s,
        max_exposure_s=cam.max_exposure_s,
    )

    def meter(camera, start_s: float):  # type: ignore[no-untyped-def]
        shutter = getattr(camera, "available_exposures_s", None)
        return meter_exposure(camera, rule, start_s, shutter() if shutter else None)

    fixed = fix_session_exposure(rig, schedule, meter)
    chosen = fixed.provenance["exposure"]
    out.print(
        f"Exposure fixed at {chosen['exposure_s']:.4g} s ({chosen['reason']})", highlight=False
    )
    return fixed


def _execute(rig, schedule, folder, out_dir: Path, source=None) -> None:  # type: ignore[no-untyped-def]
    """Run with a progress bar and signal handling; print what happened and how to go on."""
    from rti_rig.runtime.controller import (
        CancelToken,
        EmergencyStop,
        FinishReason,
        Paused,
        StepCompleted,
        run_session,
    )
    from rti_rig.runtime.session import LP_NAME

    cancel = CancelToken()

    def on_sigint(signum, frame):  # type: ignore[no-untyped-def]
        if cancel.cancelled:
            raise EmergencyStop("second Ctrl-C")
        cancel.cancel()
        err.print("[yellow]Stopping after this image (Ctrl-C again to stop at once)…[/]")

    def on_sigterm(signum, frame):  # type: ignore[no-untyped-def]
        raise EmergencyStop("SIGTERM")

    def on_sigusr1(signum, frame):  # type: ignore[no-untyped-def]
        if cancel.paused:
            cancel.resume()
            err.print("[green]Resuming.[/]")
        else:
            cancel.pause()
            err.print("[yellow]Pausing after this image (lights off); SIGUSR1 again resumes.[/]")

    handlers = {signal.SIGINT: on_sigint, signal.SIGTERM: on_sigterm}
    if hasattr(signal, "SIGUSR1"):
        handlers[signal.SIGUSR1] = on_sigusr1
    previous = {sig: signal.signal(sig, h) for sig, h in handlers.items()}
    dry = " (dry run)" if rig.loaded.config.backend != "hardware" else ""
    total = len(schedule) if source is None else source.total
    todo = total - len(folder.done)
    out.print(
        f"Rig [bold]{escape(rig.name)}[/]{dry}: {todo} of {total} lights"
        + (" at most, adaptive" if source is not None else "")
        + " → "
        f"{escape(str(out_dir))}"
    )
    resume_hint = f"Continue with: rti-rig run --resume {out_dir}"
    try:
        with Progress(
            TextColumn("[progress.description]{task.description}"),
            BarColumn(),
            MofNCompleteColumn(),
            TimeElapsedColumn(),
            console=out,
        ) as progress:
            task = progress.add_task("capturing", total=total, completed=len(folder.done))

            def on_event(event):  # type: ignore[no-untyped-def]
                if isinstance(event, StepCompleted):
                    progress.advance(task)
                elif isinstance(event, Paused):
                    progress.update(task, description="paused")

            result = run_session(
                rig, schedule, folder, cancel=cancel, on_event=on_event, source=source
            )
    except EmergencyStop as exc:
        from rti_rig.app.usecases.safe_state import lights_state

        err.print(
            f"[red]Emergency stop ({escape(str(exc))}):[/] {escape(lights_state(rig))}; "
            "images kept."
        )
        err.print(resume_hint)
        raise typer.Exit(code=143 if str(exc) == "SIGTERM" else 130) from None
    except RtiRigError as exc:
        from rti_rig.app.usecases.safe_state import lights_state

        err.print(
            f"Images already captured are kept in {out_dir}; {lights_state(rig)}. {resume_hint}",
            markup=False,
        )
        raise _fail(exc) from None
    finally:
        for sig, h in previous.items():
            signal.signal(sig, h)

    total_done = len(folder.done) + len(result.records)
    out.print(
        f"{total_done} image(s) in the session; {LP_NAME} lists the lights that fired.\n"
        f"Session time on the real rig: {result.rig_time_s:.1f} s"
        + (f" (simulated in {result.wall_time_s:.1f} s)" if dry else "")
    )
    for note in folder.manifest.get("notices") or []:
        err.print(f"[yellow]note:[/] {escape(str(note))}")
    for failure in result.teardown_failures:
        err.print(f"[red]teardown problem:[/] {escape(str(failure))}")
    if result.finish_reason is FinishReason.CANCELLED:
        err.print(
            f"[yellow]Session cancelled; the images captured so far are kept.[/] {resume_hint}"
        )
        raise typer.Exit(code=130)


@app.command()
def preview(
    rig_config: Annotated[
        Path, typer.Argument(help="Rig config TOML, e.g. rig_configs/simulated_dome.toml.")
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
    auto_exposure: Annotated[
        bool,
        typer.Option(
            "--auto-exposure",
            help="Meter first (a short test series) so the preview is not saturated.",
        ),
    ] = False,
    max_saturated: Annotated[
        float,
        typer.Option("--max-saturated", help="Largest fraction of saturated pixels allowed."),
    ] = 0.001,
) -> None:
    """Shoot the planner's preview: one image under one light, as a session of one image.

    The session records the light that fired, so `rti-rig plan OUT_DIR --rig RIG ...` plans from
    its linear image with that light (no --preview-light needed).
    """
    from rti_rig.app.config import load_rig_config, rig_geometry
    from rti_rig.planner.preview_shot import preview_schedule

    try:
        _check_max_saturated(max_saturated)
        az_el = _parse_az_el(light, "--light")
        loaded = load_rig_config(rig_config)
        schedule, notes = preview_schedule(rig_geometry(loaded), az_el)
        for note in notes:
            err.print(f"[yellow]note:[/] {escape(note)}", soft_wrap=True)
        rig, schedule, folder = _open_new_session(
            loaded, schedule, out_dir, auto_exposure, max_saturated
        )
    except RtiRigError as exc:
        raise _fail(exc) from None
    with rig:
        _execute(rig, schedule, folder, out_dir)
    out.print(
        f"Plan from it: rti-rig plan {shlex.quote(str(out_dir))} --rig "
        f"{shlex.quote(str(rig_config))} --lights N --out plan.lp",
        highlight=False,
        markup=False,
        soft_wrap=True,
    )


def _parse_az_el(text: str | None, option: str = "--preview-light") -> tuple[float, float] | None:
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


@app.command()
def plan(
    preview: Annotated[
        Path | None,
        typer.Argument(
            help="One preview image of the object (8-bit JPEG/PNG/TIFF = sRGB, 16-bit "
            "PNG/TIFF = linear, as 'rti-rig run' writes them; a camera RAW file - DNG, CR2, "
            "NEF, ARW... - is decoded linearly, its light taken from --preview-light or a "
            "--rig .lp that lists it), or the session folder "
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
            "(default: the simulated 48-LED dome shipped with rti-rig).",
        ),
    ] = None,
    lights: Annotated[int, typer.Option("--lights", help="Number of lights to plan.")] = 12,
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
            "the bare .lp given as --rig that lists the image, else estimated from the image.",
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
            "[camera] signal_noise (0 if absent, and for a bare .lp).",
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
    out_file: Annotated[Path, typer.Option("--out", help="Plan file to write (.lp).")] = Path(
        "plan.lp"
    ),
    figure: Annotated[
        Path | None,
        typer.Option(
            "--figure",
            help="Also draw the plan as a map (.png, .svg or .pdf): the lights seen from above, "
            "numbered in firing order, on the dome's LEDs or the arm's reach.",
        ),
    ] = None,
    force: Annotated[
        bool, typer.Option("--force", help="Overwrite an existing plan file (and --figure).")
    ] = False,
) -> None:
    """Plan an ordered set of lights from one preview shot and write it as an .lp file.

    Without PREVIEW: `uniform` (the default then) or `optimal`, which plans for a level surface,
    matte unless `--material glossy` (on the benchmarks in docs/research/planner.md it did as
    well as with a preview).

    The plan's lights are the rig's own (a dome's LEDs, used once each; an arm's reachable
    directions, ordered for the least move time); `rti-rig run RIG --plan PLAN.lp` runs it.
    """
    from rti_rig.app.config import default_config_path
    from rti_rig.app.usecases.plan import PlanLightsRequest, draw_plan_figure, plan_lights

    try:
        request = PlanLightsRequest(
            rig=rig or default_config_path(),
            out_file=out_file,
            lights=lights,
            preview=preview,
            method=method,
            objective=objective,
            preview_light=_parse_az_el(preview_light),
            depth_model=depth_model,
            min_elevation_deg=min_elevation_deg,
            max_elevation_deg=max_elevation_deg,
            signal_noise=signal_noise,
            material=material,
            figure=figure,
            force=force,
        )
        planned = plan_lights(request)
    except RtiRigError as exc:
        raise _fail(exc) from None
    _print_notes(planned.notes)
    for line in planned.report.lines():
        out.print(line, highlight=False, markup=False)
    out.print(
        f"Planned {len(planned.schedule)} lights ({planned.method}, {planned.objective}) → "
        f"{out_file}"
    )
    if figure is not None:
        # after the report: a map that cannot be drawn must not hide a plan that was written
        try:
            draw_plan_figure(request, planned)
        except RtiRigError as exc:
            raise _fail(exc) from None
        out.print(f"Map of the plan → {figure}")


@app.command("export-lp")
def export_lp(
    session_dir: Annotated[Path, typer.Argument(help="A session folder written by 'rti-rig run'.")],
    out_file: Annotated[Path, typer.Option("--out", help="The .lp file to write.")],
    linear: Annotated[
        bool,
        typer.Option("--linear", help="Name the 16-bit linear TIFFs instead of the JPEGs."),
    ] = False,
    force: Annotated[bool, typer.Option("--force", help="Overwrite an existing file.")] = False,
) -> None:
    """Write the .lp of a session (from the lights that actually fired)."""
    from rti_rig.app.output_files import check_output_file
    from rti_rig.core.lp_format import write_lp
    from rti_rig.runtime.session import session_lp_entries

    try:
        entries = session_lp_entries(session_dir, linear=linear)
        check_output_file(out_file, force, {})
        write_lp(out_file, entries)
    except RtiRigError as exc:
        raise _fail(exc) from None
    out.print(f"{len(entries)} lights → {out_file}")


def _parse_normal(text: str) -> tuple[float, float, float]:
    """``"X,Y,Z"`` → a unit vector pointing up out of the card; a clear error otherwise."""
    import math

    try:
        x, y, z = (float(p) for p in text.replace(" ", "").split(","))
    except ValueError:
        raise RtiRigError(
            f"--card-normal {text!r}: give the card's normal as X,Y,Z (e.g. 0,0,1 for level)"
        ) from None
    norm = math.sqrt(x * x + y * y + z * z)
    if not (math.isfinite(norm) and norm > 0 and z / norm > 0.5):
        raise RtiRigError(
            f"--card-normal {text!r}: the card must face the camera (z > 0, within 60° of the "
            "zenith); give its normal as X,Y,Z"
        )
    return (x / norm, y / norm, z / norm)


@app.command("calibrate-lights")
def calibrate_lights(
    card_session: Annotated[
        Path,
        typer.Argument(
            help="A session of a level matte white card shot under every LED ('rti-rig run').",
            show_default=False,
        ),
    ],
    rig_config: Annotated[
        Path, typer.Option("--rig", help="The dome's rig config (the one the card was shot on).")
    ],
    out_file: Annotated[
        Path | None,
        typer.Option(
            "--out",
            help="Calibration file to write (default: CARD_SESSION/light_calibration.toml).",
        ),
    ] = None,
    card_normal: Annotated[
        str, typer.Option("--card-normal", help="The card's normal as X,Y,Z if it is not level.")
    ] = "0,0,1",
    min_elevation_deg: Annotated[
        float,
        typer.Option(
            "--min-elevation-deg",
            help="LEDs lower than this above the card are not measured (grazing light on a "
            "card is the most sensitive to its tilt and texture).",
        ),
    ] = 5.0,
    force: Annotated[bool, typer.Option("--force", help="Overwrite an existing file.")] = False,
) -> None:
    """Measure each LED's light from a card session and write the intensity correction that
    evens the dome out (every LED dimmed to the weakest one's light), for [dome.serial]
    intensity_correction_file in the rig config."""
    import math

    import numpy as np

    from rti_rig.app.usecases.calibrate import CalibrateRequest, calibrate_lights

    try:
        done = calibrate_lights(
            CalibrateRequest(
                card_session,
                rig_config,
                out_file,
                _parse_normal(card_normal),
                min_elevation_deg,
                force,
            )
        )
    except RtiRigError as exc:
        raise _fail(exc) from None
    cal, card, loaded, geometry, target = (
        done.calibration,
        done.card,
        done.loaded,
        done.geometry,
        done.target,
    )
    normal = np.asarray(_parse_normal(card_normal))
    measured = np.flatnonzero(cal.measured)
    elevation = np.degrees(np.arcsin(np.clip(geometry.directions[measured] @ normal, -1, 1)))
    lowest = float(elevation.min())
    weak, strong = int(np.argmin(cal.output)), int(np.argmax(cal.output))
    names = geometry.names
    out.print(
        f"Card session {escape(str(card_session))}: {len(card.leds)} images of rig "
        f"'{escape(loaded.config.name)}'; {len(measured)} of {geometry.count} LEDs measured "
        f"(lowest {lowest:.1f}° above the card)."
    )
    out.print(
        f"Lights as shot: spread {100 * cal.shot_spread:.1f} % RMS; each LED's own light from "
        f"{cal.output[weak]:.2f} (LED {weak}, {escape(names[weak])}) to {cal.output[strong]:.2f} "
        f"(LED {strong}, {escape(names[strong])}) of the median."
    )
    out.print(
        f"Evened out, every LED gives {cal.evened_light:.2f} of the median LED's light "
        f"({cal.stops_lost:.2f} stop(s) more exposure)."
    )
    if not cal.measured.all():
        skipped = ", ".join(names[i] for i in np.flatnonzero(~cal.measured))
        err.print(
            f"[yellow]note:[/] not measured (not in the session, or lower than "
            f"{min_elevation_deg:g}° above the card), assumed to give the median light under "
            f"the correction in force: {escape(skipped)}"
        )
    if cal.output[weak] < 0.5:
        err.print(
            f"[yellow]warning:[/] LED {weak} gives only {cal.output[weak]:.2f} of the median "
            "light; check it (a failing LED, a dirty diffuser) before evening the dome out to it."
        )
    tilt_pct = 100 * math.tan(math.radians(1.0)) / math.tan(math.radians(lowest))
    out.print(
        f"A card tilted by 1° would move the lowest LEDs' figures by up to {tilt_pct:.0f} %: "
        "level it with care."
    )
    rel = os.path.relpath(target.resolve(), rig_config.resolve().parent)
    out.print(f"Calibration → {escape(str(target))}")
    out.print(
        f"To use it, add under {escape('[dome.serial]')} in {escape(str(rig_config))}:  "
        f'intensity_correction_file = "{escape(rel)}"\n'
        "Then shoot the card again and calibrate that session: its spread is what is left."
    )


@app.command()
def check(
    rig_config: Annotated[Path, typer.Argument(help="Rig config TOML to check.")],
    intensity: Annotated[
        float, typer.Option("--intensity", help="LED drive level for the walk, in (0, 1].")
    ] = 0.2,
) -> None:
    """Self-test the rig's lights: a dome lights each LED in turn and reports what answered; an
    arm visits poses spanning its band (checking where it really got to), flashes the lamp at
    each and parks."""
    from rti_rig.app.compose import build_rig
    from rti_rig.app.config import load_rig_config
    from rti_rig.core.rig_geometry import ArmGeometry
    from rti_rig.runtime.arm_check import arm_self_test
    from rti_rig.runtime.dome_policy import self_test
    from rti_rig.runtime.lighting import ArmLighting, DomeLighting

    try:
        if not 0.0 < intensity <= 1.0:
            raise RtiRigError(
                f"--intensity {intensity:g}: give the LED drive level as a fraction in (0, 1]"
            )
        loaded = load_rig_config(rig_config)
        rig = build_rig(loaded)
    except RtiRigError as exc:
        raise _fail(exc) from None
    with rig:
        report: Any
        if isinstance(rig.lighting, DomeLighting):
            report = self_test(rig.lighting.source, rig.clock, intensity=intensity)
        elif isinstance(rig.lighting, ArmLighting) and isinstance(rig.geometry, ArmGeometry):
            report = arm_self_test(
                rig.lighting.carrier,
                rig.geometry,
                rig.clock,
                park=rig.lighting.park_after_session,
            )
        else:
            raise _fail(RtiRigError(f"{rig_config}: no self-test for this kind of lighting"))
    for line in report.lines():
        out.print(line, highlight=False)
    if not report.ok:
        raise typer.Exit(code=1)


bench_app = typer.Typer(help="Benchmarks on the simulator: the speed/accuracy trade.")
app.add_typer(bench_app, name="bench")


@bench_app.command("tradeoff")
def bench_tradeoff(
    out_dir: Annotated[
        Path, typer.Option("--out", help="Folder for results.csv, the plots and summary.md.")
    ] = Path("docs/research/tradeoff"),
    quick: Annotated[
        bool, typer.Option("--quick", help="Fewer scenes, light counts and pixels (minutes).")
    ] = False,
    from_lp: Annotated[
        Path | None,
        typer.Option(
            "--from",
            help="A dense acquisition of your own (an .lp with its images beside it): the trade "
            "for uniform, optimal and adaptive against all its lights.",
        ),
    ] = None,
) -> None:
    """Error against number of lights and session time, for every planner, on simulated scenes
    (or on your own acquisition with --from)."""
    import time

    if from_lp is not None:
        from benchmarks.tradeoff_from import bench_from

        try:
            text = bench_from(from_lp, out_dir, lambda msg: out.print(msg, highlight=False))
        except RtiRigError as exc:
            raise _fail(exc) from None
        except ValueError as exc:
            raise _fail(RtiRigError(str(exc))) from None
        out.print(text, highlight=False)
        return

    from benchmarks.tradeoff import TradeoffSettings, plot, run_tradeoff, summarise, write_csv

    settings = TradeoffSettings.quick() if quick else TradeoffSettings()
    t0 = time.perf_counter()
    rows = run_tradeoff(settings, progress=lambda msg: out.print(msg, highlight=False))
    out_dir.mkdir(parents=True, exist_ok=True)
    write_csv(rows, out_dir / "results.csv")
    plot(rows, out_dir)
    command = "rti-rig bench tradeoff" + (" --quick" if quick else "") + f" --out {out_dir}"
    text = summarise(rows, settings, time.perf_counter() - t0, command)
    (out_dir / "summary.md").write_text(text, encoding="utf-8")
    out.print(text, highlight=False)


@app.command()
def probe(
    port: Annotated[str, typer.Argument(help="Serial port of the dome, e.g. /dev/ttyACM0.")],
) -> None:
    """Identify which known dome firmware answers on PORT (least intrusive probes first, never
    leaving a light on) and print the rig-config lines to use."""
    from rti_rig.app.usecases.probe import ProbeRequest
    from rti_rig.app.usecases.probe import probe as run_probe

    result = run_probe(ProbeRequest(port))
    for line in result.lines():
        out.print(line, highlight=False, markup=False)
    if result.profile is None:
        raise typer.Exit(code=1)


def main() -> None:
    app()


if __name__ == "__main__":
    main()
