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
    from rti_rig.core.rig_geometry import ArmGeometry, DomeGeometry
    from rti_rig.core.schedule import LightSchedule
    from rti_rig.planner.plan_report import PlanReport

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


def _check_output_file(
    out_file: Path, force: bool, inputs: dict[str, Path | None], option: str = "--out"
) -> None:
    """Refuse, before any work, an output the command could not write or should not replace.

    ``inputs`` names the files the command reads (``{"PREVIEW": path, ...}``): replacing one of
    them is refused even with ``--force``, as is replacing a file inside a session folder —
    nothing already captured is ever overwritten. ``option`` is the flag that named the file.
    """
    from rti_rig.runtime.session import MANIFEST

    if out_file.is_dir():
        raise RtiRigError(f"{option} {out_file} is a folder: give the name of the file to write")
    parent = out_file.parent
    if not parent.is_dir():
        raise RtiRigError(f"{option} {out_file}: folder {parent} does not exist; create it first")
    if not out_file.exists():
        return
    for what, path in inputs.items():
        if path is not None and path.exists() and out_file.samefile(path):
            raise RtiRigError(
                f"{option} {out_file} is the {what} this command reads; choose another"
            )
    for folder in out_file.resolve().parents:
        if (folder / MANIFEST).is_file():
            raise RtiRigError(
                f"{option} {out_file} would replace a file of the session in {folder}; a "
                "session's files are never overwritten: write it elsewhere"
            )
    if not force:
        raise RtiRigError(f"{option} {out_file} exists; use --force to replace it")


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
    no_verdict: Annotated[
        bool, typer.Option("--no-verdict", help="Do not print the QA verdict at the end.")
    ] = False,
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
        else:
            if rig_config is None or out_dir is None:
                raise RtiRigError("give a RIG_CONFIG and --out DIR (or --resume SESSION_DIR)")
            loaded = load_rig_config(rig_config)
            geometry = rig_geometry(loaded)
            if plan is not None:
                if lights is not None:
                    raise RtiRigError("give either --plan or --lights, not both")
                schedule = schedule_from_lp(
                    read_lp(plan, upper_hemisphere=True), geometry, str(plan)
                )
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
        _execute(rig, schedule, folder, out_dir)
    if not no_verdict:
        _print_verdict(out_dir)


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


def _execute(rig, schedule, folder, out_dir: Path) -> None:  # type: ignore[no-untyped-def]
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
    todo = len(schedule) - len(folder.done)
    out.print(
        f"Rig [bold]{escape(rig.name)}[/]{dry}: {todo} of {len(schedule)} lights → "
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
            task = progress.add_task("capturing", total=len(schedule), completed=len(folder.done))

            def on_event(event):  # type: ignore[no-untyped-def]
                if isinstance(event, StepCompleted):
                    progress.advance(task)
                elif isinstance(event, Paused):
                    progress.update(task, description="paused")

            result = run_session(rig, schedule, folder, cancel=cancel, on_event=on_event)
    except EmergencyStop as exc:
        err.print(
            f"[red]Emergency stop ({escape(str(exc))}):[/] lights off, devices safe; images kept."
        )
        err.print(resume_hint)
        raise typer.Exit(code=143 if str(exc) == "SIGTERM" else 130) from None
    except RtiRigError as exc:
        err.print(
            f"Images already captured are kept in {out_dir}; lights are off. {resume_hint}",
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
            "and on a steeply tilted object (docs/planner.md).",
        ),
    ] = 90.0,
    signal_noise: Annotated[
        float | None,
        typer.Option(
            "--signal-noise",
            help="Image noise proportional to the signal, as a fraction (normals objective): "
            "0.05 models 8-bit JPEG captures on a dome without LED intensity calibration "
            "(docs/planner.md); 0 models additive noise only. Default: the rig config's "
            "[camera] signal_noise (0 if absent, and for a bare .lp).",
        ),
    ] = None,
    material: Annotated[
        str,
        typer.Option(
            "--material",
            help="What you know of the surface: auto (highlights read from the preview; "
            "default), matte, or glossy (polished metal, gilding, varnish: one preview of a "
            "flat glossy object does not show its gloss; docs/planner.md).",
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
    matte unless `--material glossy` (on the benchmarks in docs/planner.md it did as well as
    with a preview).

    The plan's lights are the rig's own (a dome's LEDs, used once each; an arm's reachable
    directions, ordered for the least move time); `rti-rig run RIG --plan PLAN.lp` runs it.
    """
    from rti_rig.app.compose import arm_order_for, read_preview_image
    from rti_rig.app.config import default_config_path, load_rig_config, rig_geometry
    from rti_rig.app.preview_source import resolve_preview
    from rti_rig.core.lp_format import MAX_LIGHTS, LpEntry, read_lp, write_lp
    from rti_rig.core.rig_geometry import DomeGeometry, coincident_leds
    from rti_rig.planner.make_plan import (
        DEFAULT_OBJECTIVE,
        METHODS,
        check_elevation_band,
        plan_with_report,
    )
    from rti_rig.planner.objectives import OBJECTIVES, check_material, check_signal_noise
    from rti_rig.runtime.session import image_names

    rig = rig or default_config_path()
    try:
        method = method or ("optimal" if preview is not None else "uniform")
        if method not in METHODS:
            raise RtiRigError(f"--method {method!r} is not known; choose {', '.join(METHODS)}")
        objective = objective or DEFAULT_OBJECTIVE
        if objective not in OBJECTIVES:
            raise RtiRigError(
                f"--objective {objective!r} is not known; choose {', '.join(OBJECTIVES)}"
            )
        if signal_noise is not None:
            check_signal_noise(signal_noise, objective)
        check_material(material)
        if method == "kmeans" and preview is None:
            raise RtiRigError(
                "--method kmeans clusters the preview's normals: give PREVIEW (or use "
                "--method optimal, which plans for a flat surface without one)"
            )
        if depth_model is not None and not depth_model.is_file():
            raise RtiRigError(f"--depth-model {depth_model}: file not found")
        check_elevation_band(min_elevation_deg, max_elevation_deg)
        if lights > MAX_LIGHTS:
            raise RtiRigError(
                f"--lights {lights}: at most {MAX_LIGHTS} lights (the most an .lp file may list "
                "for readers such as relight)"
            )
        az_el = _parse_az_el(preview_light)
        bare_lp = rig.suffix.lower() == ".lp"
        loaded = None if bare_lp else load_rig_config(rig)
        inputs = {"preview": preview, "rig file": rig, "depth model": depth_model}
        if loaded is not None and loaded.config.dome is not None and loaded.config.dome.lp_file:
            # the dome's LED calibration is an input too
            inputs["rig's LED calibration (lp_file)"] = loaded.folder / loaded.config.dome.lp_file
        _check_output_file(out_file, force, inputs)
        if figure is not None:
            from rti_rig.app.plan_figure import check_figure_path  # matplotlib only when asked

            check_figure_path(figure)
            _check_output_file(figure, force, inputs, "--figure")
            if figure.resolve() == out_file.resolve():
                raise RtiRigError(f"--figure {figure} is the --out plan file; choose another")
        arm_order = None
        if loaded is None:
            entries = read_lp(rig, upper_hemisphere=True)
            pair = coincident_leds([e.direction for e in entries])
            if pair is not None:
                i, j = pair
                raise RtiRigError(
                    f"{rig}: lights {i + 1} ({entries[i].name}) and {j + 1} "
                    f"({entries[j].name}) give the same direction; as --rig, an .lp means a "
                    "dome with exactly these lights, each listed once (remove the repeats)"
                )
            geometry: object = DomeGeometry(
                [e.direction for e in entries], tuple(e.name for e in entries)
            )
        else:
            geometry = rig_geometry(loaded)
            arm_order = arm_order_for(loaded)
            if signal_noise is None and loaded.config.camera.signal_noise > 0:
                signal_noise = loaded.config.camera.signal_noise
                if objective != "normals":
                    raise RtiRigError(
                        f"{rig}: [camera] signal_noise = {signal_noise:g} is modelled by the "
                        f"normals objective only; give --signal-noise 0 to plan for "
                        f"--objective {objective}"
                    )
        image, light_note = None, None
        if preview is not None:
            rig_lp = (rig, entries) if loaded is None else None
            source = resolve_preview(preview, rig_lp, az_el is not None)
            if az_el is None and source.light_az_el_deg is not None:
                az_el, light_note = source.light_az_el_deg, source.light_source
            image = read_preview_image(source.image)
        schedule, report = plan_with_report(
            image,
            geometry,  # type: ignore[arg-type]
            lights,
            method,
            objective,
            preview_light=az_el,
            depth_model=depth_model,
            min_elevation_deg=min_elevation_deg,
            arm_order=arm_order,
            signal_noise=signal_noise or 0.0,
            material=material,
            max_elevation_deg=max_elevation_deg,
        )
        if light_note and report.preview_light_source == "given":
            report.preview_light_source = light_note
        if bare_lp:
            names = [s.label for s in schedule.steps]
        else:
            names = [f"{n}.jpg" for n in image_names(len(schedule))]
        write_lp(
            out_file, [LpEntry(n, s.direction) for n, s in zip(names, schedule.steps, strict=True)]
        )
    except RtiRigError as exc:
        raise _fail(exc) from None
    for line in report.lines():
        out.print(line, highlight=False, markup=False)
    out.print(f"Planned {len(schedule)} lights ({method}, {objective}) → {out_file}")
    if figure is not None:
        # after the report: a map that cannot be drawn must not hide a plan that was written
        how = f"{method}/{objective}"
        try:
            _write_plan_figure(
                figure,
                schedule,
                geometry,  # type: ignore[arg-type]
                report,
                how,
                rig,
                min_elevation_deg,
                max_elevation_deg,
            )
        except RtiRigError as exc:
            raise _fail(exc) from None
        out.print(f"Map of the plan → {figure}")


def _write_plan_figure(
    path: Path,
    schedule: LightSchedule,
    geometry: DomeGeometry | ArmGeometry,
    report: PlanReport,
    how: str,
    rig: Path,
    min_elevation_deg: float = 0.0,
    max_elevation_deg: float = 90.0,
) -> None:
    """Draw the plan's map (``plan --figure``); the .lp is already written, so a failure here
    names the map file and leaves the plan in place."""
    from rti_rig.app.plan_figure import expected_caption, layout_figure, write_layout_figure
    from rti_rig.core.geometry import direction_from_az_el

    light = report.preview_light_az_el_deg
    caption = expected_caption(report.expected_meaning or "expected error", report.expected)
    try:
        fig = layout_figure(
            [s.direction for s in schedule.steps],
            geometry,
            None if light is None else direction_from_az_el(*light),
            f"{len(schedule.steps)} lights · {how} · {rig.name}",
            [caption] if caption else [],
            min_elevation_deg,
            max_elevation_deg,
        )
        write_layout_figure(path, fig)
    except (OSError, ValueError, RuntimeError) as exc:
        raise RtiRigError(
            f"--figure {path}: could not write the map ({exc}); the plan itself was written"
        ) from None


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
    from rti_rig.core.lp_format import write_lp
    from rti_rig.runtime.session import session_lp_entries

    try:
        entries = session_lp_entries(session_dir, linear=linear)
        _check_output_file(out_file, force, {})
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

    from rti_rig.app.config import load_rig_config, rig_geometry
    from rti_rig.app.light_calibration import calibrate_dome, calibration_toml, read_card_session

    try:
        normal = _parse_normal(card_normal)
        loaded = load_rig_config(rig_config)
        serial = loaded.config.dome.serial if loaded.config.dome else None
        if serial is None:
            raise RtiRigError(
                f"{rig_config}: rig '{loaded.config.name}' has no [dome.serial]: only a serial "
                "dome can dim its LEDs (the simulated backend's are exact)"
            )
        from rti_rig.drivers.led_dome.profiles import make_codec

        if not make_codec(serial).has_level:
            raise RtiRigError(
                f"{rig_config}: the dome's '{serial.profile}' profile sends no PWM level "
                "(send_level = false), so it cannot dim an LED; divide the gains out of the "
                "images instead (rti_rig.reconstruct.apply_light_gains)"
            )
        geometry = rig_geometry(loaded)
        card = read_card_session(card_session, rig_name=loaded.config.name)
        target = out_file or card_session / "light_calibration.toml"
        if out_file is None and target.exists():
            raise RtiRigError(
                f"{target} exists: this card session was calibrated already (its file is never "
                "replaced); give --out to write the calibration elsewhere"
            )
        _check_output_file(target, force, {"RIG": rig_config})
        cal = calibrate_dome(
            card, geometry.count, card_normal=normal, min_elevation_deg=min_elevation_deg
        )
        text = calibration_toml(cal, loaded.config.name, card_session.resolve(), geometry.names)
        try:
            target.write_text(text, encoding="utf-8")
        except OSError as exc:
            raise RtiRigError(f"cannot write {target}: {exc.strerror or exc}") from None
    except RtiRigError as exc:
        raise _fail(exc) from None
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
    ] = Path("docs/tradeoff"),
    quick: Annotated[
        bool, typer.Option("--quick", help="Fewer scenes, light counts and pixels (minutes).")
    ] = False,
) -> None:
    """Error against number of lights and session time, for every planner, on simulated scenes."""
    import time

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


def _print_verdict(session: Path | None) -> None:
    """Last line of ``run``: the QA verdict (never fails the run: it is advice)."""
    from rti_rig.app.usecases.fit import verdict_for_session

    if session is None:
        return
    try:
        out.print(f"QA verdict: {escape(verdict_for_session(session))}")
    except (RtiRigError, ValueError) as exc:
        err.print(f"[yellow]QA verdict unavailable:[/] {escape(str(exc))}")


@app.command()
def fit(
    sources: Annotated[
        list[Path],
        typer.Argument(
            help="Session folder(s), or .lp file(s) with their images beside them. With more "
            "than one, a resumable batch: each goes to OUT/<name>, finished ones are skipped."
        ),
    ],
    out_dir: Annotated[Path, typer.Option("--out", help="New or empty folder for outputs.")],
    model: Annotated[
        str,
        typer.Option(
            "--model",
            help="auto (evidence-based choice), ps, robust-ps, lambert, ptm, hsh1, hsh2, hsh3.",
        ),
    ] = "auto",
    no_qa: Annotated[bool, typer.Option("--no-qa", help="Skip the QA verdict.")] = False,
    no_ptm: Annotated[bool, typer.Option("--no-ptm", help="Do not write fit.ptm.")] = False,
    no_hsh: Annotated[bool, typer.Option("--no-hsh", help="Do not write fit.rti.")] = False,
    no_normals: Annotated[
        bool, typer.Option("--no-normals", help="Do not fit normal and albedo maps.")
    ] = False,
) -> None:
    """Fit a session: normal map, albedo, .ptm, .rti, relight .dome and a QA verdict."""
    from rti_rig.app.usecases.fit import FitRequest, run_batch, run_fit
    from rti_rig.reconstruct.registry import model_spec

    try:
        if model != "auto":
            try:
                model_spec(model)
            except ValueError as exc:
                raise RtiRigError(str(exc)) from None
        request = FitRequest(
            sources[0],
            out_dir,
            model=model,
            qa=not no_qa,
            write_ptm=not no_ptm,
            write_hsh=not no_hsh,
            write_normals=not no_normals,
        )
        if len(sources) > 1:
            items = run_batch(sources, out_dir, request)
            for item in items:
                line = f"{item.source}: {item.status}"
                if item.verdict:
                    line += f"; QA verdict: {item.verdict}"
                out.print(escape(line))
            if any(i.status.startswith("failed") for i in items):
                raise typer.Exit(code=2)
            return
        result = run_fit(request)
    except RtiRigError as exc:
        raise _fail(exc) from None
    out.print(f"Model: {escape(result.reason)}")
    for text in result.warnings:
        err.print(f"[yellow]warning:[/] {escape(text)}")
    out.print(
        f"Wrote {len(result.files)} files to {escape(str(out_dir))} in {result.seconds:.1f} s"
    )
    if result.qa is not None:
        out.print(f"QA verdict: {escape(result.qa.verdict)}")


def main() -> None:
    app()


if __name__ == "__main__":
    main()
