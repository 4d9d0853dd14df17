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


def _flags_show_no_type() -> None:
    """Show on/off flags in help without a value type: typer 0.29 labels them ``<bool>``, as if
    ``--force`` took a value (it takes none). Every command's flags at once, in one place."""
    from typer.core import TyperOption

    original = TyperOption.display_type_rich
    if getattr(original, "_rti_rig", False):
        return

    def display_type_rich(self, ctx):  # type: ignore[no-untyped-def]
        if getattr(self, "is_flag", False) and self.metavar is None:
            return None
        return original(self, ctx)

    display_type_rich._rti_rig = True  # type: ignore[attr-defined]
    TyperOption.display_type_rich = display_type_rich  # type: ignore[method-assign]


_flags_show_no_type()


def _fail(exc: RtiRigError) -> typer.Exit:
    # the message is plain text: "[camera]" or "[dome.serial]" in it must not be read as markup
    err.print(f"[bold red]error:[/] {escape(str(exc))}", highlight=False, soft_wrap=True)
    return typer.Exit(code=2)


def _print_notes(notes) -> None:  # type: ignore[no-untyped-def]
    """What a tolerant reader accepted but the user should know (file, line, what was done)."""
    for note in notes:
        err.print(f"[yellow]note:[/] {escape(note)}", highlight=False, soft_wrap=True)


def _print_note(note) -> None:  # type: ignore[no-untyped-def]
    """Show a use case's note: information on stdout, warnings on stderr."""
    if note.level == "warning":
        err.print(f"[yellow]note:[/] {escape(note.text)}", soft_wrap=True)
    else:
        out.print(note.text, highlight=False, markup=False)


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
            "only the steps not yet done (on the rig the session began on).",
        ),
    ] = None,
    accept_rig_change: Annotated[
        bool,
        typer.Option(
            "--accept-rig-change",
            help="With --resume: go on although the rig differs from the session's (a "
            "repaired LED, a new exposure); the change is recorded in the manifest.",
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
            help="Adaptive: stop once the estimated mean normal error is at most this many "
            "degrees (with --lights: whichever comes first).",
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
    from rti_rig.app.usecases.session import (
        NewSessionRequest,
        ResumeRequest,
        open_new_session,
        open_resumed_session,
    )

    try:
        if resume is not None:
            if out_dir is not None or plan is not None or lights is not None:
                raise RtiRigError(
                    "--resume continues a session as planned: drop --out, --plan, --lights"
                )
            opened = open_resumed_session(
                ResumeRequest(
                    resume,
                    rig_config,
                    max_saturated=max_saturated,
                    accept_rig_change=accept_rig_change,
                ),
                _print_note,
            )
        else:
            if rig_config is None or out_dir is None:
                raise RtiRigError("give a RIG_CONFIG and --out DIR (or --resume SESSION_DIR)")
            if accept_rig_change:
                raise RtiRigError("--accept-rig-change goes with --resume SESSION_DIR only")
            opened = open_new_session(
                NewSessionRequest(
                    rig_config,
                    out_dir,
                    lights=lights,
                    plan=plan,
                    min_elevation_deg=min_elevation_deg,
                    max_elevation_deg=max_elevation_deg,
                    auto_exposure=auto_exposure,
                    max_saturated=max_saturated,
                    adaptive=adaptive,
                    until_error_deg=until_error,
                ),
                _print_note,
            )
    except RtiRigError as exc:
        raise _fail(exc) from None
    _execute(opened)
    if not no_verdict:
        _print_verdict(opened.out_dir)


def _after_stop(opened, resume_hint: str) -> str:  # type: ignore[no-untyped-def]
    """What a stopped session left on disk and how to go on (never a resume hint for nothing)."""
    from rti_rig.runtime.session import LP_NAME

    folder, out_dir = opened.folder, opened.out_dir
    if folder.images_kept:
        return (
            f"{folder.images_kept} image(s) kept in {out_dir}, listed in {LP_NAME}. {resume_hint}"
        )
    if opened.resumed:
        return f"No new image was captured. {resume_hint}"
    if folder.begun:
        return f"Nothing was captured: {out_dir} holds no image and may be used again."
    return f"Nothing was captured and nothing was written to {out_dir}."


def _execute(opened) -> None:  # type: ignore[no-untyped-def]
    """Run with a progress bar and signal handling; print what happened and how to go on."""
    from rti_rig.app.usecases.session import run_opened_session
    from rti_rig.runtime.controller import (
        CancelToken,
        EmergencyStop,
        FinishReason,
        Paused,
        StepCompleted,
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
    rig, folder, out_dir = opened.rig, opened.folder, opened.out_dir
    dry = " (dry run)" if opened.dry_run else ""
    adaptive = " at most, adaptive" if opened.source is not None else ""
    out.print(
        f"Rig [bold]{escape(rig.name)}[/]{dry}: {opened.steps_to_do} of {opened.total_steps} "
        f"lights{adaptive} → {escape(str(out_dir))}"
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
            task = progress.add_task(
                "capturing", total=opened.total_steps, completed=len(folder.done)
            )

            def on_event(event):  # type: ignore[no-untyped-def]
                if isinstance(event, StepCompleted):
                    progress.advance(task)
                elif isinstance(event, Paused):
                    progress.update(task, description="paused")

            result = run_opened_session(opened, cancel, on_event)
    except EmergencyStop as exc:
        from rti_rig.app.usecases.safe_state import lights_state

        err.print(
            f"[red]Emergency stop ({escape(str(exc))}):[/] {escape(lights_state(rig))}."
        )
        err.print(_after_stop(opened, resume_hint), markup=False, soft_wrap=True)
        raise typer.Exit(code=143 if str(exc) == "SIGTERM" else 130) from None
    except RtiRigError as exc:
        from rti_rig.app.usecases.safe_state import lights_state

        state = lights_state(rig)
        err.print(
            f"{state[:1].upper()}{state[1:]}. {_after_stop(opened, resume_hint)}", markup=False
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
    adaptive_result = opened.extra.get("adaptive_result")
    if adaptive_result is not None:
        est = adaptive_result["estimated_error_deg"]
        out.print(
            f"Adaptive: {adaptive_result['lights_used']} lights; stopped: "
            f"{adaptive_result['stop']['reason']}; estimated mean normal error "
            f"{'n/a' if est is None else f'{est:.2f}°'}",
            highlight=False,
        )
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
    from rti_rig.app.usecases.session import PreviewRequest, open_preview_session

    try:
        opened = open_preview_session(
            PreviewRequest(
                rig_config,
                out_dir,
                _parse_az_el(light, "--light"),
                auto_exposure=auto_exposure,
                max_saturated=max_saturated,
            ),
            _print_note,
        )
    except RtiRigError as exc:
        raise _fail(exc) from None
    _execute(opened)
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
    """Write the .lp of a session from its verified journal: the lights that actually fired,
    for every image on disk as captured (an interrupted session's too)."""
    from rti_rig.app.output_files import check_output_file
    from rti_rig.core.lp_format import write_lp
    from rti_rig.runtime.session import session_lp_report

    try:
        entries, left_out = session_lp_report(session_dir, linear=linear)
        check_output_file(out_file, force, {})
        write_lp(out_file, entries)
    except RtiRigError as exc:
        raise _fail(exc) from None
    if left_out:
        err.print(
            f"[yellow]note:[/] left out, missing or changed since they were captured: "
            f"{escape(', '.join(left_out))}",
            soft_wrap=True,
        )
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
    in_force = card.correction is not None
    #: what is left after a correction in force that needs no further calibration
    even_enough = 0.01
    if in_force:
        # a re-shot card under the correction: the spread as shot is what is left, the LEDs'
        # own (uncorrected) outputs are the same as before, which is no failure
        change = float(np.max(np.abs(cal.correction / np.maximum(cal.previous, 1e-9) - 1.0)))
        out.print(
            f"Lights as shot, with the intensity correction in force: spread "
            f"{100 * cal.shot_spread:.1f} % RMS"
            + (" — the dome is even." if cal.shot_spread < even_enough else ".")
        )
        out.print(
            f"Each LED's own light, without the correction, is still {cal.output[weak]:.2f} "
            f"(LED {weak}, {escape(names[weak])}) to {cal.output[strong]:.2f} "
            f"(LED {strong}, {escape(names[strong])}) of the median; the new correction "
            f"differs from the one in force by at most {100 * change:.1f} %."
        )
    else:
        out.print(
            f"Lights as shot: spread {100 * cal.shot_spread:.1f} % RMS; each LED's own light "
            f"from {cal.output[weak]:.2f} (LED {weak}, {escape(names[weak])}) to "
            f"{cal.output[strong]:.2f} (LED {strong}, {escape(names[strong])}) of the median."
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
    if in_force and cal.shot_spread < even_enough:
        out.print(
            "The correction in force is good: no new calibration is needed. To use this "
            f"one instead, set under {escape('[dome.serial]')} in {escape(str(rig_config))}:",
            highlight=False,
        )
    else:
        out.print(
            f"To use it, add under {escape('[dome.serial]')} in {escape(str(rig_config))}:",
            highlight=False,
        )
    # the line to paste, on its own and never wrapped (a wrapped line pastes as two)
    out.print(f'intensity_correction_file = "{rel}"', markup=False, highlight=False, soft_wrap=True)
    if not (in_force and cal.shot_spread < even_enough):
        out.print(
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
        Path | None,
        typer.Option(
            "--out",
            help="Folder to write results.csv, the plots and summary.md into (the repository's "
            "committed results are docs/research/tradeoff). Without it the summary is only "
            "printed.",
        ),
    ] = None,
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
    (or on your own acquisition with --from).

    Nothing is written unless --out is given, so a quick run never replaces the committed
    full-run results. The benchmarks live in the repository's benchmarks/ folder (they are not
    installed): run this from a checkout."""
    import time

    try:
        from benchmarks.tradeoff import (
            TradeoffSettings,
            plot,
            run_tradeoff,
            summarise,
            write_csv,
        )
        from benchmarks.tradeoff_from import bench_from
    except ImportError:
        raise _fail(
            RtiRigError(
                "rti-rig bench runs the benchmarks of a checkout of the rti-rig repository "
                "(they are not installed): run it from the repository's folder"
            )
        ) from None
    if from_lp is not None:
        try:
            text = bench_from(from_lp, out_dir, lambda msg: out.print(msg, highlight=False))
        except RtiRigError as exc:
            raise _fail(exc) from None
        except ValueError as exc:
            raise _fail(RtiRigError(str(exc))) from None
        out.print(text, highlight=False)
        return

    settings = TradeoffSettings.quick() if quick else TradeoffSettings()
    t0 = time.perf_counter()
    rows = run_tradeoff(settings, progress=lambda msg: out.print(msg, highlight=False))
    command = "rti-rig bench tradeoff" + (" --quick" if quick else "")
    if out_dir is not None:
        command += f" --out {out_dir}"
    text = summarise(rows, settings, time.perf_counter() - t0, command)
    if out_dir is not None:
        out_dir.mkdir(parents=True, exist_ok=True)
        write_csv(rows, out_dir / "results.csv")
        plot(rows, out_dir)
        (out_dir / "summary.md").write_text(text, encoding="utf-8")
    out.print(text, highlight=False)
    if out_dir is None:
        out.print("(nothing written: give --out DIR to keep the results)", highlight=False)


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
