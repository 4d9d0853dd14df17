"""The `rti-rig` command line: run sessions, plan lights, export `.lp` files.

Every user-facing failure is an :class:`~rti_rig.errors.RtiRigError` printed as one clear message
(file, line or key, and what to do) with exit status 2, never a traceback.
"""

from __future__ import annotations

import signal
from pathlib import Path
from typing import Annotated

import typer
from rich.console import Console
from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn

from rti_rig.errors import RtiRigError

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

RigArg = Annotated[
    Path,
    typer.Argument(help="Rig config TOML (see rig_configs/), e.g. rig_configs/simulated_dome.toml"),
]


def _fail(exc: RtiRigError) -> typer.Exit:
    err.print(f"[bold red]error:[/] {exc}", highlight=False, markup=True, soft_wrap=True)
    return typer.Exit(code=2)


def _default_lights(loaded, geometry) -> int:  # type: ignore[no-untyped-def]
    from rti_rig.rig_geometry import DomeGeometry

    cfg = loaded.config
    if isinstance(geometry, DomeGeometry):
        assert cfg.dome is not None
        return cfg.dome.default_lights or geometry.count
    assert cfg.arm is not None
    return cfg.arm.default_lights


@app.command()
def run(
    rig_config: RigArg,
    out_dir: Annotated[
        Path, typer.Option("--out", help="New or empty folder to write the session into.")
    ],
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
) -> None:
    """Run a capture session (a dry run when the config's backend is 'simulated')."""
    from planner.from_lp import schedule_from_lp
    from planner.uniform import plan_uniform
    from rti_rig.compose import build_rig
    from rti_rig.config import load_rig_config, rig_geometry
    from rti_rig.controller import CancelToken, FinishReason, StepCompleted, run_session
    from rti_rig.lp_format import read_lp
    from rti_rig.session import LP_NAME, SessionFolder

    try:
        loaded = load_rig_config(rig_config)
        geometry = rig_geometry(loaded)
        if plan is not None:
            if lights is not None:
                raise typer.BadParameter("give either --plan or --lights, not both")
            schedule = schedule_from_lp(read_lp(plan), geometry, str(plan))
        else:
            n = lights if lights is not None else _default_lights(loaded, geometry)
            schedule = plan_uniform(geometry, n, min_elevation_deg)
        rig = build_rig(loaded)
        from rti_rig.controller import validate_schedule

        validate_schedule(rig, schedule)
        folder = SessionFolder.create(out_dir, len(schedule))
    except RtiRigError as exc:
        raise _fail(exc) from None

    cancel = CancelToken()

    def on_sigint(signum, frame):  # type: ignore[no-untyped-def]
        if cancel.cancelled:
            raise KeyboardInterrupt
        cancel.cancel()
        err.print("[yellow]Stopping after this image (Ctrl-C again to stop at once)…[/]")

    previous = signal.signal(signal.SIGINT, on_sigint)
    dry = " (dry run)" if loaded.config.backend == "simulated" else ""
    out.print(f"Rig [bold]{loaded.config.name}[/]{dry}: {len(schedule)} lights → {out_dir}")
    try:
        with Progress(
            TextColumn("[progress.description]{task.description}"),
            BarColumn(),
            MofNCompleteColumn(),
            TimeElapsedColumn(),
            console=out,
        ) as progress:
            task = progress.add_task("capturing", total=len(schedule))

            def on_event(event):  # type: ignore[no-untyped-def]
                if isinstance(event, StepCompleted):
                    progress.update(task, completed=event.index + 1)

            result = run_session(rig, schedule, folder, cancel=cancel, on_event=on_event)
    except RtiRigError as exc:
        err.print(f"Images already captured are kept in {out_dir}; lights are off.")
        raise _fail(exc) from None
    finally:
        signal.signal(signal.SIGINT, previous)

    out.print(
        f"{len(result.records)} image(s) written; {LP_NAME} lists the lights that fired.\n"
        f"Session time on the real rig: {result.rig_time_s:.1f} s"
        + (f" (simulated in {result.wall_time_s:.1f} s)" if dry else "")
    )
    for failure in result.teardown_failures:
        err.print(f"[red]teardown problem:[/] {failure}")
    if result.finish_reason is FinishReason.CANCELLED:
        err.print("[yellow]Session cancelled; the images captured so far are kept.[/]")
        raise typer.Exit(code=130)


@app.command()
def plan(
    preview: Annotated[
        Path | None,
        typer.Argument(help="Preview image (not needed by the 'uniform' method)."),
    ] = None,
    rig: Annotated[
        Path,
        typer.Option(
            "--rig",
            help="Rig config TOML, or a bare .lp meaning 'a dome with exactly these lights'.",
        ),
    ] = Path("rig_configs/simulated_dome.toml"),
    lights: Annotated[int, typer.Option("--lights", help="Number of lights to plan.")] = 12,
    method: Annotated[str, typer.Option("--method", help="Planning method: uniform.")] = "uniform",
    min_elevation_deg: Annotated[
        float, typer.Option("--min-elevation-deg", help="Lowest elevation allowed (degrees).")
    ] = 0.0,
    out_file: Annotated[Path, typer.Option("--out", help="Plan file to write (.lp).")] = Path(
        "plan.lp"
    ),
    force: Annotated[
        bool, typer.Option("--force", help="Overwrite an existing plan file.")
    ] = False,
) -> None:
    """Plan an ordered set of lights for a rig and write it as an .lp file."""
    from planner.uniform import plan_uniform
    from rti_rig.config import load_rig_config, rig_geometry
    from rti_rig.lp_format import LpEntry, read_lp, write_lp
    from rti_rig.rig_geometry import DomeGeometry
    from rti_rig.session import image_names

    if method != "uniform":
        raise _fail(RtiRigError(f"--method {method!r} is not available; use 'uniform'"))
    try:
        if rig.suffix.lower() == ".lp":
            entries = read_lp(rig)
            geometry: object = DomeGeometry(
                [e.direction for e in entries], tuple(e.name for e in entries)
            )
        else:
            geometry = rig_geometry(load_rig_config(rig))
        schedule = plan_uniform(geometry, lights, min_elevation_deg)  # type: ignore[arg-type]
        if out_file.exists() and not force:
            raise RtiRigError(f"{out_file} exists; use --force to replace it")
        if rig.suffix.lower() == ".lp":
            names = [s.label for s in schedule.steps]
        else:
            names = [f"{n}.jpg" for n in image_names(len(schedule))]
        write_lp(
            out_file, [LpEntry(n, s.direction) for n, s in zip(names, schedule.steps, strict=True)]
        )
    except RtiRigError as exc:
        raise _fail(exc) from None
    out.print(f"Planned {len(schedule)} lights ({method}) → {out_file}")


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
    from rti_rig.lp_format import write_lp
    from rti_rig.session import session_lp_entries

    try:
        entries = session_lp_entries(session_dir, linear=linear)
        if out_file.exists() and not force:
            raise RtiRigError(f"{out_file} exists; use --force to replace it")
        write_lp(out_file, entries)
    except RtiRigError as exc:
        raise _fail(exc) from None
    out.print(f"{len(entries)} lights → {out_file}")


def main() -> None:
    app()
