"""`rti-rig calibrate-lights`: parse, call :mod:`rti_rig.app.usecases.calibrate`, print."""

from __future__ import annotations

import math
import os
from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer
from rich.markup import escape

from rti_rig.cli.app import FILE, app, err, fail, out, print_notes, shown_path, stop_exit_code
from rti_rig.cli.stopping import Terminated, sigterm_stops, stamp, stop_signal, written_since
from rti_rig.core.deferred_signals import stop_words
from rti_rig.core.errors import RtiRigError
from rti_rig.core.shell_words import shell_word
from rti_rig.core.toml_strings import NotTomlText, toml_basic_string

if TYPE_CHECKING:
    from rti_rig.app.usecases.calibrate import CalibrateRequest
    from rti_rig.app.usecases.sphere_lights import SphereLights


#: The calibration file a card session gets without ``--out`` (``CalibrateRequest.target``).
DEFAULT_CALIBRATION_NAME = "light_calibration.toml"


def _parse_normal(text: str) -> tuple[float, float, float]:
    """``"X,Y,Z"`` → a unit vector pointing up out of the card; a clear error otherwise."""

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


def _check_min_elevation(value: float) -> float:
    """``--min-elevation-deg`` as given, if it is an elevation strictly between 0° and 90°.

    Why here: the calibration refused it deeper down as ``min_elevation_deg must be in (0,
    90)``, a name the user never typed, without the default to go back to."""
    if not 0.0 < value < 90.0:
        raise RtiRigError(
            f"--min-elevation-deg {value:g}: give an elevation above 0 and below 90 degrees "
            "(the default is 5)"
        )
    return value


def _how_to_set(raw: dict) -> str:  # type: ignore[type-arg]
    """How the calibration line goes into the rig config: added, or replacing the correction
    the config already names. Why: a config with a correction was told to "add" the line, and
    a second ``intensity_correction_file`` under ``[dome.serial]`` is refused as invalid TOML
    ("Cannot overwrite a value"); ``intensity_correction`` and the file may not be given
    together either."""
    serial = (raw.get("dome") or {}).get("serial") or {}
    if "intensity_correction_file" in serial:
        return "replace its intensity_correction_file line under"
    if "intensity_correction" in serial:
        return "replace its intensity_correction = [...] with this line under"
    return "add under"


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
            metavar=FILE,
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
            "card is the most sensitive to its tilt and texture). Degrees, above 0 and below 90.",
        ),
    ] = 5.0,
    force: Annotated[
        bool,
        typer.Option(
            "--force",
            help="Overwrite an existing --out file (the card session's own "
            "light_calibration.toml is never replaced).",
        ),
    ] = False,
    not_flat_ok: Annotated[
        bool,
        typer.Option(
            "--not-flat-ok",
            help="Calibrate even if the images do not look like a flat card's (their normals "
            "spread more than 10°: a card large for its dome).",
        ),
    ] = False,
) -> None:
    """Measure each LED's light from a card session and write the intensity correction that
    evens the dome out (every LED dimmed to the weakest one's light), for \\[dome.serial]
    intensity_correction_file in the rig config. Only a link that can dim an LED takes one
    (the default and binary profiles, framed with send_level = true): the on/off firmware
    profiles (nab-rti-v1, rtipy, ...) are refused."""
    # the backslash above keeps typer's rich help from reading "[dome.serial]" as markup and
    # dropping it (tests/cli/test_help_markup.py)

    # the file to write, as CalibrateRequest.target names it, known before the use case is
    # imported: that import takes seconds on a loaded machine, and a Ctrl-C in it had said only
    # "rti-rig: stopped (Ctrl-C)" (a SIGTERM nothing), not whether a --force'd --out was kept
    target = out_file or card_session / DEFAULT_CALIBRATION_NAME
    before = stamp(target)  # a file there already (--force) is not one this run wrote
    reported: list[bool] = []  # set once the file is written and its report begun
    try:
        # SIGTERM as Ctrl-C: without a handler it ended the command mid-write, leaving a
        # hidden .light_calibration.toml.tmp beside the file asked for, and said nothing
        with sigterm_stops():
            from rti_rig.app.usecases.calibrate import CalibrateRequest

            try:
                request = CalibrateRequest(
                    card_session,
                    rig_config,
                    out_file,
                    _parse_normal(card_normal),
                    _check_min_elevation(min_elevation_deg),
                    force,
                    not_flat_ok,
                )
            except RtiRigError as exc:
                raise fail(exc) from None
            if out_file is not None and _setting_line(target, rig_config) is None:
                # refused before anything is measured or written: the line cannot be said
                raise fail(
                    RtiRigError(
                        f"{_not_toml_text(target, rig_config)}: give --out a file whose path "
                        "from the config's folder is UTF-8 (nothing was measured or written)"
                    )
                )
            _calibrate_and_report(request, reported)
    except (KeyboardInterrupt, Terminated) as exc:
        signum = stop_signal(exc)
        why = stop_words(signum)
        if reported or written_since(target, before):
            line = _setting_line(target, rig_config) or _copy_to_use(target, rig_config)
            said = (
                f"Stopped ({why}): the calibration {shown_path(target)} is written; to use it, "
                f"set {line} under [dome.serial] in {shown_path(rig_config)}"
            )
        else:
            kept = "" if before is None else " (the file already there is as it was)"
            said = (
                f"Stopped ({why}) before the calibration was written: nothing was written to "
                f"{shown_path(target)}{kept}"
            )
        err.print(said, markup=False, highlight=False, soft_wrap=True)
        raise typer.Exit(code=stop_exit_code(signum)) from None


def _setting_line(target: Path, rig_config: Path) -> str | None:
    """The ``intensity_correction_file = "..."`` line naming ``target`` relative to the rig
    config's folder, as a TOML basic string (a quote or backslash in the name escaped), for the
    user to paste under ``[dome.serial]``; None where the name is not UTF-8 (no TOML file can
    hold it: :func:`_not_toml_text` says so).

    Why: it was printed as ``"{rel}"``, the name unescaped: a line TOML refused or misread."""
    rel = os.path.relpath(target.resolve(), rig_config.resolve().parent)
    try:
        return f"intensity_correction_file = {toml_basic_string(rel)}"
    except NotTomlText:
        return None


def _not_toml_text(target: Path, rig_config: Path) -> str:
    """Why ``target`` cannot be named in ``rig_config``: its path from the config's folder."""
    rel = os.path.relpath(target.resolve(), rig_config.resolve().parent)
    return (
        f"{shown_path(target)}: its name as the rig config {shown_path(rig_config)} would give "
        f"it ({shown_path(rel)}) is not UTF-8 text, which a TOML file cannot hold"
    )


def _copy_to_use(target: Path, rig_config: Path) -> str:
    """What to do with a calibration whose name no TOML file can hold."""
    return (
        f"copy it to a file whose name is UTF-8 (cp {shell_word(target)} NEW.toml, beside "
        f'{shown_path(rig_config)}) and set intensity_correction_file = "NEW.toml"'
    )


def _calibrate_and_report(request: CalibrateRequest, reported: list[bool]) -> None:
    """Measure, write the calibration and report it: the body of :func:`calibrate_lights`, run
    under its stop handling (``reported`` gets True once the file is written)."""
    import numpy as np

    from rti_rig.app.light_calibration import evened_sentence
    from rti_rig.app.usecases.calibrate import calibrate_lights

    card_session, rig_config = request.card_session, request.rig_config
    try:
        done = calibrate_lights(request)
    except RtiRigError as exc:
        raise fail(exc) from None
    reported.append(True)
    cal, card, loaded, geometry, target = (
        done.calibration,
        done.card,
        done.loaded,
        done.geometry,
        done.target,
    )
    print_notes(done.notes)
    normal = np.asarray(request.card_normal)
    measured = np.flatnonzero(cal.measured)
    elevation = np.degrees(np.arcsin(np.clip(geometry.directions[measured] @ normal, -1, 1)))
    lowest = float(elevation.min())
    weak = int(np.argmin(cal.output))  # the LED the correction evens out to
    # the extremes this session measured: with a correction in force an LED it did not shoot
    # is assumed at its old figure, and had been named as if measured ("is still 0.74 to 1.57
    # (LED 38)" from a card session of 12 LEDs without LED 38)
    low, high = (int(measured[f(cal.output[measured])]) for f in (np.argmin, np.argmax))
    each = "each LED" if cal.measured.all() else "each measured LED"

    def led(i: int) -> str:
        """An LED by its number and direction (a ring dome's had been said by its id,
        "LED 36, led_036") and as the session shot it (the image to open)."""
        shot = card.image_of.get(i)
        return geometry.led_fields(i) + (f", session image {shot}" if shot else "")

    out.print(
        f"Card session {escape(shown_path(card_session))}: {len(card.leds)} images of rig "
        f"'{escape(loaded.config.name)}'; {len(measured)} of {geometry.count} LEDs measured "
        f"(lowest {lowest:.1f}° above the card)."
    )
    in_force = card.correction is not None
    # the LEDs no image shows, and those shown but left out as too low: "the 1 others were
    # not shot" had been said of an LED --min-elevation-deg left out of a full card session
    not_shot = geometry.count - len(set(int(i) for i in card.leds))
    below = geometry.count - len(measured) - not_shot
    unmeasured = ", ".join(
        [
            *([f"{not_shot} not shot"] if not_shot else []),
            *(
                [f"{below} below --min-elevation-deg {request.min_elevation_deg:g}°"]
                if below
                else []
            ),
        ]
    )
    #: what is left after a correction in force that needs no further calibration
    even_enough = 0.01
    if in_force:
        # a re-shot card under the correction: the spread as shot is what is left, the LEDs'
        # own (uncorrected) outputs are the same as before, which is no failure
        change = float(np.max(np.abs(cal.correction / np.maximum(cal.previous, 1e-9) - 1.0)))
        out.print(
            f"Lights as shot, with the intensity correction in force: spread "
            f"{100 * cal.shot_spread:.1f} % RMS"
            + (
                ""
                if cal.shot_spread >= even_enough
                else " — the dome is even."
                if cal.measured.all()
                else f" — the {len(measured)} LEDs measured are even ({unmeasured}, so "
                "not checked)."
            )
        )
        out.print(
            f"{each[0].upper()}{each[1:]}'s own light, without the correction, is still "
            f"{cal.output[low]:.2f} "
            f"({escape(led(low))}) to {cal.output[high]:.2f} "
            f"({escape(led(high))}) of the median; the new correction "
            f"differs from the one in force by at most {100 * change:.1f} %."
        )
    else:
        out.print(
            f"Lights as shot: spread {100 * cal.shot_spread:.1f} % RMS; {each}'s own light "
            f"from {cal.output[low]:.2f} ({escape(led(low))}) to "
            f"{cal.output[high]:.2f} ({escape(led(high))}) of the median."
        )
    out.print(evened_sentence(cal, 2) + ".")
    if not cal.measured.all():
        skipped = "; ".join(geometry.led_said(int(i)) for i in np.flatnonzero(~cal.measured))
        err.print(
            f"[yellow]note:[/] not measured (not in the session, or lower than "
            f"{request.min_elevation_deg:g}° above the card), assumed to give the median light "
            f"under the correction in force: {escape(skipped)}"
        )
    if cal.output[weak] < 0.5:
        err.print(
            f"[yellow]warning:[/] {escape(led(weak))} gives only {cal.output[weak]:.2f} of the "
            "median light; check it (a failing LED, a dirty diffuser) before evening the dome "
            "out to it."
        )
    tilt_pct = 100 * math.tan(math.radians(1.0)) / math.tan(math.radians(lowest))
    out.print(
        f"A card tilted by 1° would move the lowest LEDs' figures by up to {tilt_pct:.0f} %: "
        "level it with care."
    )
    out.print(f"Calibration → {escape(shown_path(target))}")
    if in_force and cal.shot_spread < even_enough and cal.measured.all():
        out.print(
            "The correction in force is good: no new calibration is needed. To use this "
            f"one instead, set under {escape('[dome.serial]')} in "
            f"{escape(shown_path(rig_config))}:",
            highlight=False,
        )
    elif in_force and cal.shot_spread < even_enough:
        # 6 of 48 LEDs shot had said "the dome is even … no new calibration is needed" of a
        # dome whose 42 others no image had shown
        from rti_rig.app.usecases.run_options import run_words
        from rti_rig.core.out_folders import free_folder_beside

        again = run_words(rig_config, free_folder_beside(card_session, "card"))
        ways = [
            *(
                [
                    f"shoot the card under every LED ({again}, without --lights) and calibrate "
                    "from that session"
                ]
                if not_shot
                else []
            ),
            *(["give a lower --min-elevation-deg"] if below else []),
        ]
        out.print(
            f"The correction in force is good for the {len(measured)} LEDs measured; to check "
            f"the others ({unmeasured}), {escape(' and '.join(ways))}. To use this one "
            f"meanwhile, set under {escape('[dome.serial]')} in "
            f"{escape(shown_path(rig_config))}:",
            highlight=False,
        )
    else:
        out.print(
            f"To use it, {_how_to_set(loaded.raw)} {escape('[dome.serial]')} in "
            f"{escape(shown_path(rig_config))}:",
            highlight=False,
        )
    # the line to paste, on its own and never wrapped (a wrapped line pastes as two)
    line = _setting_line(target, rig_config)
    if line is None:
        err.print(
            f"[yellow]warning:[/] {escape(_not_toml_text(target, rig_config))}; "
            f"{escape(_copy_to_use(target, rig_config))}",
            highlight=False,
            soft_wrap=True,
        )
    else:
        out.print(line, markup=False, highlight=False, soft_wrap=True)
    if not (in_force and cal.shot_spread < even_enough):
        out.print(
            "Then shoot the card again and calibrate that session: its spread is what is left."
        )


def _parse_circle(text: str) -> tuple[float, float, float]:
    """``"X,Y,R"`` → the sphere's centre column, centre row and radius in pixels."""
    try:
        x, y, r = (float(p) for p in text.replace(" ", "").split(","))
    except ValueError:
        raise RtiRigError(
            f"--sphere {text!r}: give the sphere's circle as X,Y,R in image pixels (centre "
            "column, centre row, radius; e.g. 2990,2010,850), as an image viewer shows them"
        ) from None
    return (x, y, r)


@app.command("lights-from-sphere")
def lights_from_sphere(
    session: Annotated[
        Path,
        typer.Argument(
            help="A session of a black glossy or chrome sphere shot under every LED "
            "('rti-rig run').",
            show_default=False,
        ),
    ],
    sphere: Annotated[
        str,
        typer.Option(
            "--sphere",
            help="The sphere's circle in the images as X,Y,R: centre column, centre row and "
            "radius, in pixels (row 0 at the top).",
            show_default=False,
        ),
    ],
    out_file: Annotated[
        Path,
        typer.Option("--out", metavar=FILE, help="The dome's .lp to write.", show_default=False),
    ],
    force: Annotated[bool, typer.Option("--force", help="Replace an existing --out file.")] = False,
) -> None:
    """Measure each LED's direction from the sphere's highlight in a session (the highlight
    method: l = 2(n·v)n − v, n the sphere's normal at the highlight) and write the dome's .lp,
    line i = LED i, for layout = "lp" in its config. An image whose highlight cannot be
    measured is named with why, and no .lp is written."""
    # SIGTERM and a hang-up as Ctrl-C, from before the use case's import (seconds on a loaded
    # machine): without a handler a SIGTERM ended the command without a word, and a Ctrl-C said
    # only "rti-rig: stopped (Ctrl-C)", not whether --out (a file kept there with --force) was
    # written. The .lp is written whole at the end (a rename), so a stop before it wrote nothing.
    before = stamp(out_file)
    done: list[SphereLights] = []  # the result, once measured and written
    try:
        with sigterm_stops():
            from rti_rig.app.usecases.sphere_lights import SphereRequest
            from rti_rig.app.usecases.sphere_lights import lights_from_sphere as measure
            from rti_rig.reconstruct.sphere_lights import Circle

            try:
                request = SphereRequest(session, Circle(*_parse_circle(sphere)), out_file, force)
                done.append(measure(request))
            except RtiRigError as exc:
                raise fail(exc) from None
            result = done[0]
            out.print(
                f"Wrote {shown_path(result.out)}: {len(result.highlights)} LED directions "
                f"measured from the sphere in {shown_path(session)} (line i = LED i).",
                markup=False,
                highlight=False,
                soft_wrap=True,
            )
            for note in result.notes:
                err.print(f"[yellow]warning:[/] {escape(note)}", highlight=False, soft_wrap=True)
            out.print(
                f"To use it, {_sphere_lp_line(result)}.",
                markup=False,
                highlight=False,
                soft_wrap=True,
            )
    except (KeyboardInterrupt, Terminated) as exc:
        signum = stop_signal(exc)
        why = stop_words(signum)
        if done:
            said = (
                f"Stopped ({why}): {shown_path(out_file)} is written; to use it, "
                f"{_sphere_lp_line(done[0])}"
            )
        elif written_since(out_file, before):  # stopped as the use case returned
            said = f"Stopped ({why}): {shown_path(out_file)} is written"
        else:
            kept = "" if before is None else " (the file already there is as it was)"
            said = (
                f"Stopped ({why}) before the .lp was written: nothing was written to "
                f"{shown_path(out_file)}{kept}"
            )
        err.print(said, markup=False, highlight=False, soft_wrap=True)
        raise typer.Exit(code=stop_exit_code(signum)) from None


def _sphere_lp_line(result: SphereLights) -> str:
    """The setting that puts a measured ``.lp`` in the dome's config, its path relative to the
    config the sphere was shot with (where the config is named; else to the working folder)."""
    config = result.config
    base = config.resolve().parent if config is not None else Path.cwd()
    try:
        named = toml_basic_string(os.path.relpath(result.out.resolve(), base))
    except NotTomlText:  # a name no TOML file can hold: the user copies the file to one
        named = '"…" (copy the file to a UTF-8 name first)'
    where = f"the dome's config {shown_path(config)}" if config else "the dome's config"
    if result.layout == "lp":  # a dome measured again: only the file changes
        return f"set lp_file = {named} under [dome] in {where}, in place of the one it names"
    # the other layout's keys are refused beside layout = "lp": "in place of its count" had
    # been said of a ring dome, whose [[dome.rings]] tables must go
    replaced = {"fibonacci": "its count", "rings": "its [[dome.rings]] tables"}.get(
        str(result.layout), "its layout's keys"
    )
    return (
        f'set layout = "lp" and lp_file = {named} under [dome] in {where}, in place of {replaced}'
    )
