"""A resume given the options a session began with: the same request goes on, another is refused.

Why: a lab's script runs ``rti-rig run RIG --out S --lights 24`` and, if that fails, the same
line with ``--resume S`` added. Every option that begins a session had been refused with a
resume ("drop --lights"), the identical request as much as a different one, so the script
could not continue a session with the line that began it. The request is now compared with
what the manifest records (the schedule the options give on this rig, the adaptive settings,
the metering): identical goes on, as a plain ``--resume`` would; different is refused before
anything on disk is touched, naming what differs and what to do.
"""

from __future__ import annotations

import math
import re
import shlex
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

from rti_rig.app.usecases.run_options import adaptive_options, band_options
from rti_rig.core.errors import RtiRigError
from rti_rig.core.geometry import angle_between_deg, az_el_from_direction
from rti_rig.core.out_folders import free_name
from rti_rig.core.rig_geometry import led_said
from rti_rig.core.shell_words import shell_word, shown_path

#: Two lights of a plan are the same light within this angle (°): an .lp carries six decimals
#: (or fewer, rewritten by another program), which moves a direction by far less than this.
SAME_LIGHT_DEG = 0.01


@dataclass(frozen=True)
class StartOptions:
    """The options of ``run`` that begin a session, as given with ``--resume`` (defaults where
    not given)."""

    lights: int | None = None
    plan: Path | None = None
    adaptive: bool = False
    until_error_deg: float | None = None
    min_lights: int | None = None
    auto_exposure: bool = False
    #: None: not given (the default, 0.001)
    max_saturated: float | None = None
    min_elevation_deg: float = 0.0
    max_elevation_deg: float = 90.0
    allow_no_normals: bool = False
    #: ``--objective`` (checked by the resume itself; here it is part of an adaptive request)
    objective: str | None = None
    #: the flags as typed, for the refusals that name them (``--rebuild-journal`` of a completed
    #: session, which reads no rig to compare them with)
    given: tuple[str, ...] = ()

    @property
    def is_adaptive(self) -> bool:
        return self.adaptive or self.until_error_deg is not None


def check_same_start(
    asked: StartOptions, manifest: dict[str, Any], loaded: Any, root: Path
) -> None:
    """Refuse ``asked`` unless it is the request session ``root`` began with (its manifest
    read by the caller; ``loaded`` its rig config, on which a layout is planned again to be
    compared). Reads nothing in the folder and changes nothing."""
    from rti_rig.app.usecases.replay_advice import session_options

    diffs = _differences(asked, manifest, loaded)
    if not diffs:
        return
    began = session_options(manifest).strip()
    if _metered(manifest):
        from rti_rig.app.usecases.session import NewSessionRequest

        limit = _recorded_max_saturated(manifest)
        if limit is not None and _same_number(limit, NewSessionRequest.max_saturated):
            limit = None  # the default: said by no option
        began = " ".join([began, *_exposure_words(True, limit)]).strip()
    folder = shell_word(str(root))
    give = "give those options or none"
    by_default = _default_count_said(began, manifest, loaded)
    if by_default is not None:
        said, rest = by_default
        began = f"{said} and {rest}" if rest else said
        give = "give those options without --lights, or none" if rest else "drop those options"
    said = _differences_said(diffs, asked)
    shoot = _new_session_advice(asked, manifest, loaded, root, by_default is not None)
    if (manifest.get("runner") or {}).get("finish_reason") == "completed":
        # a finished session has nothing to continue: "to continue it as it began" had sent
        # the user to a resume that answers "complete, nothing to resume"
        from rti_rig.app.usecases.next_fit import next_fit

        raise RtiRigError(
            f"{shown_path(root)}: this resume asks for another session than the one in it ("
            + said
            + f"). It began with {began or 'the defaults'} and is complete: a finished session "
            f"is not extended (nothing in the folder was changed). {shoot[0].upper()}"
            f"{shoot[1:]}. To use the session as it is: {next_fit(root)}"
        )
    raise RtiRigError(
        f"{shown_path(root)}: this resume asks for another session than the one in it ("
        + said
        + f"). It began with {began or 'the defaults'} (nothing in the folder was changed): "
        f"to continue it as it began, {give} (rti-rig run --resume "
        f"{folder}); {shoot}"
    )


def _differences_said(diffs: list[str], asked: StartOptions) -> str:
    """``diffs`` with those of options the user gave first, then those of options not given.

    Why: "--adaptive not given; --lights not given, the session 12; --min-lights 6, the
    session not given" read as three mistakes where the user had typed one option; the options
    not given differ too (a resume's options are the whole request), and are said as such."""
    flags = _given_flags(asked)

    def unasked(diff: str) -> bool:
        flag = re.match(r"--[a-z-]+", diff)
        return flag is not None and flag.group(0) not in flags

    named = [d for d in diffs if not unasked(d)]
    rest = [d for d in diffs if unasked(d)]
    if not rest:
        return "; ".join(named)
    whole = "options given with --resume are the whole request, so these differ" + (
        " too: " if named else ": "
    )
    return "; ".join([*named, whole + "; ".join(rest)])


def _given_flags(asked: StartOptions) -> set[str]:
    """The options ``asked`` was given with (``--objective`` is held apart by the CLI)."""
    return set(asked.given) | ({"--objective"} if asked.objective is not None else set())


#: the option that sets each field of :class:`StartOptions`
_FIELD_OF = {
    "--plan": "plan",
    "--lights": "lights",
    "--adaptive": "adaptive",
    "--until-error": "until_error_deg",
    "--min-lights": "min_lights",
    "--objective": "objective",
    "--auto-exposure": "auto_exposure",
    "--max-saturated": "max_saturated",
    "--min-elevation-deg": "min_elevation_deg",
    "--max-elevation-deg": "max_elevation_deg",
    "--allow-no-normals": "allow_no_normals",
}
_ADAPTIVE_FLAGS = frozenset({"--adaptive", "--until-error", "--min-lights", "--objective"})


def _new_session_advice(
    asked: StartOptions,
    manifest: dict[str, Any],
    loaded: Any,
    root: Path,
    default_count: bool,
) -> str:
    """The advice "to shoot it with your options in place of its own, start a new session:
    CMD": the session's own options with those given put in their place; or, where run would
    refuse that, why.

    Why: the command had repeated only the options given, so ``--resume S --max-elevation-deg
    45`` of an adaptive session advised a planned run of every light, and ``--resume S
    --min-lights 6`` a command run refused. Where the options given are all the session's own
    (only some left out), the request is taken as typed, as before: what else differs is what
    was left out."""
    from rti_rig.app.usecases.session import NewSessionRequest, check_option_pairs

    began = _began_options(manifest, default_count)
    request = _merged(asked, began)
    how = "with your options in place of its own"
    if _same_request(request, began):
        request, how = asked, "with the options you gave alone"
    command = _new_session_command(request, loaded, root)
    options = _request_options(request) or "the defaults"
    if request.is_adaptive:  # the metering _request_options leaves out of an adaptive run's
        options = " ".join(
            [options, *_exposure_words(request.auto_exposure, request.max_saturated)]
        )
    new = NewSessionRequest(
        Path(loaded.path),
        free_name(root, folder=True),
        lights=request.lights,
        plan=request.plan,
        min_elevation_deg=request.min_elevation_deg,
        max_elevation_deg=request.max_elevation_deg,
        auto_exposure=request.auto_exposure,
        adaptive=request.adaptive,
        until_error_deg=request.until_error_deg,
        objective=request.objective,
        min_lights=request.min_lights,
        allow_no_normals=request.allow_no_normals,
        **_limit(request.max_saturated),
    )
    try:
        check_option_pairs(new)
        if not request.is_adaptive:  # its layout on this rig, as run plans it (a band
            # holding fewer LEDs than --lights, a plan outside it): never advised if refused
            from rti_rig.app.usecases.session import new_session_schedule

            new_session_schedule(new, loaded)
    except RtiRigError as exc:
        return f"no new session takes it {how} ({options}): {exc}"
    if request.is_adaptive and (request.auto_exposure or request.max_saturated is not None):
        return (
            f"no new session takes it {how} ({options}): an "
            "adaptive session is not metered (its lights are chosen as the images arrive); "
            "meter once with a planned run, set camera.exposure_s in the rig config, and leave "
            "--auto-exposure out"
        )
    return f"to shoot it {how}, start a new session: {command}"


def _limit(max_saturated: float | None) -> dict[str, float]:
    return {} if max_saturated is None else {"max_saturated": max_saturated}


def _began_options(manifest: dict[str, Any], default_count: bool) -> StartOptions:
    """The options session ``manifest`` began with, as :class:`StartOptions` (a count the rig
    chose by itself, ``default_count``, as no ``--lights``)."""
    from rti_rig.app.usecases.replay_advice import allowed_no_normals

    schedule = manifest.get("schedule") or {}
    provenance = schedule.get("provenance") or {}
    header = manifest.get("adaptive")
    if isinstance(header, dict):
        from rti_rig.app.usecases.adaptive import lights_asked

        until, floor = header.get("until_error_deg"), header.get("min_lights")
        objective = header.get("objective")
        return StartOptions(
            lights=lights_asked(header),
            adaptive=until is None,
            until_error_deg=float(until) if until is not None else None,
            min_lights=int(floor) if floor is not None else None,
            objective=str(objective) if objective not in (None, "normals") else None,
            min_elevation_deg=float(header.get("min_elevation_deg", 0.0)),
            max_elevation_deg=float(header.get("max_elevation_deg", 90.0)),
        )
    from rti_rig.app.usecases.session import NewSessionRequest

    plan = provenance.get("plan_file")
    n = provenance.get("n")
    limit = _recorded_max_saturated(manifest) if _metered(manifest) else None
    if limit is not None and _same_number(limit, NewSessionRequest.max_saturated):
        limit = None  # the default: said by no option
    return StartOptions(
        lights=None if plan or default_count or n is None else int(n),
        plan=Path(plan) if plan else None,
        auto_exposure=_metered(manifest),
        max_saturated=limit,
        min_elevation_deg=float(provenance.get("min_elevation_deg", 0.0)),
        max_elevation_deg=float(provenance.get("max_elevation_deg", 90.0)),
        allow_no_normals=allowed_no_normals(manifest, provenance),
    )


def _same_request(a: StartOptions, b: StartOptions) -> bool:
    """Whether ``a`` and ``b`` ask one session (``--adaptive`` says nothing beside
    ``--until-error``, which is adaptive by itself)."""

    def plain(o: StartOptions) -> StartOptions:
        return replace(o, given=(), adaptive=o.is_adaptive and o.until_error_deg is None)

    return plain(a) == plain(b)


def _merged(asked: StartOptions, began: StartOptions) -> StartOptions:
    """``began`` with the options ``asked`` gave put in their place: a plan given replaces
    the count and the adaptive options, a count or an adaptive option given replaces the plan,
    and a request made adaptive drops the session's metering and ``--allow-no-normals``
    (which an adaptive session refuses) unless they too were given."""
    flags = _given_flags(asked)
    request = began
    if "--plan" in flags:
        request = replace(
            request,
            lights=None,
            adaptive=False,
            until_error_deg=None,
            min_lights=None,
            objective=None,
        )
    elif flags & (_ADAPTIVE_FLAGS | {"--lights", "--min-elevation-deg", "--max-elevation-deg"}):
        # a count, an adaptive option or a band asks for the rig's own layout: a plan kept
        # beside a band given had advised a run that refuses the plan's lights outside it
        request = replace(request, plan=None)
    request = replace(
        request, **{_FIELD_OF[f]: getattr(asked, _FIELD_OF[f]) for f in flags & set(_FIELD_OF)}
    )
    if "--until-error" in flags:
        # the stop decides the count (a planned session's --lights had become a cap its
        # --min-lights could not exceed), and --until-error goes with the normals objective;
        # an adaptive session's --lights stays, as the cap it is beside the stop ("the first
        # reached stops"): dropped, `--adaptive --lights 30` given --until-error 2 had been
        # advised a session of up to 100 lights (QA, 2026-12-05)
        kept = began.lights if began.is_adaptive else None
        if kept is not None and "--min-lights" in flags and (asked.min_lights or 0) > kept:
            kept = None  # a minimum above the session's count: the stop decides the count
        request = replace(
            request,
            lights=asked.lights if "--lights" in flags else kept,
            objective=asked.objective if "--objective" in flags else None,
        )
    if request.is_adaptive and not began.is_adaptive:
        request = replace(
            request,
            auto_exposure=request.auto_exposure and "--auto-exposure" in flags,
            max_saturated=request.max_saturated if "--max-saturated" in flags else None,
            allow_no_normals=request.allow_no_normals and "--allow-no-normals" in flags,
        )
    return replace(request, given=asked.given)


def _exposure_words(auto_exposure: bool, max_saturated: float | None) -> list[str]:
    """``--auto-exposure`` and ``--max-saturated L`` as a command gives them, for what a
    session began with and for the new session asked: one spelling, so the two read alike
    (each had built its own)."""
    words = ["--auto-exposure"] if auto_exposure else []
    return words + ([f"--max-saturated {max_saturated:g}"] if max_saturated is not None else [])


def _new_session_command(asked: StartOptions, loaded: Any, root: Path) -> str:
    """The ``run`` that shoots ``asked`` on ``loaded``'s rig as a new session, into a folder
    beside ``root`` free when said, as words that run pasted.

    Why: "start a new session in a new --out" had left the command to be put together, the
    config and a folder to be found."""
    options = _request_options(asked)
    return " ".join(
        w
        for w in [
            "rti-rig",
            "run",
            shell_word(str(loaded.path)),
            options,
            "--out",
            shell_word(str(free_name(root, folder=True))),
        ]
        if w
    )


def _request_options(asked: StartOptions) -> str:
    """``asked``'s options as a new session's ``run`` is given them ('' for none)."""
    words = []
    if asked.plan is not None:
        words += ["--plan", shell_word(str(asked.plan))]
    if asked.is_adaptive:  # as every advised adaptive run says them (run_options)
        objective = shlex.quote(asked.objective or "normals")  # a fixed choice, not a path
        words.append(
            adaptive_options(asked.until_error_deg, asked.lights, asked.min_lights, objective)
        )
    else:
        # a planned request's --min-lights or --objective kept as asked: the advice says why
        # run refuses them (check_option_pairs) rather than shoot a request not made
        words += ["--lights", str(asked.lights)] if asked.lights is not None else []
        words += ["--min-lights", str(asked.min_lights)] if asked.min_lights is not None else []
        words += ["--objective", shlex.quote(asked.objective)] if asked.objective else []
    # only options a new session accepts together (run's own refusals): --max-saturated only
    # with --auto-exposure (a limit given asks for the metering that reads it), neither with
    # an adaptive session, nor --allow-no-normals. The command had repeated a lone
    # --max-saturated, and pasted it was refused.
    metered = not asked.is_adaptive and (asked.auto_exposure or asked.max_saturated is not None)
    words += _exposure_words(metered, asked.max_saturated if metered else None)
    words.append(band_options((asked.min_elevation_deg, asked.max_elevation_deg)).strip())
    if asked.allow_no_normals and not asked.is_adaptive:
        words.append("--allow-no-normals")
    return " ".join(w for w in words if w)  # no band: no word


def _default_count_said(
    began: str, manifest: dict[str, Any], loaded: Any
) -> tuple[str, str] | None:
    """When ``began``'s ``--lights N`` is the count the rig runs without ``--lights`` (its
    lights the same): what chose it, "every light of the dome (48)" or "the rig's default of
    24 lights" (a config's ``default_lights``), and the options after it; else ``None``.

    Why: a session begun with no ``--lights`` was refused with "It began with --lights 48",
    an option never given (the manifest records the count, not whether it was typed); both
    lines begin the same session, so the count is said by what chose it."""
    from rti_rig.app.usecases.session import NewSessionRequest, new_session_schedule
    from rti_rig.core.schedule import LightSchedule

    schedule = manifest.get("schedule") or {}
    provenance = schedule.get("provenance") or {}
    n = provenance.get("n")
    words = f"--lights {n}"
    if isinstance(manifest.get("adaptive"), dict) or provenance.get("plan_file") or n is None:
        return None
    if not (began == words or began.startswith(words + " ")):
        return None
    low, high = provenance.get("min_elevation_deg"), provenance.get("max_elevation_deg")
    try:
        recorded = LightSchedule.from_dict(schedule)
        default = new_session_schedule(
            NewSessionRequest(
                Path(loaded.path),
                Path("."),
                min_elevation_deg=float(low) if low is not None else 0.0,
                max_elevation_deg=float(high) if high is not None else 90.0,
                allow_no_normals=bool(provenance.get("allow_no_normals", False)),
            ),
            loaded,
        )
    except (RtiRigError, KeyError, TypeError, ValueError):  # said as recorded, as before
        return None
    if len(default) != len(recorded) or any(
        (a.led, b.led) != (None, None) and a.led != b.led
        for a, b in zip(default.steps, recorded.steps, strict=True)
    ):
        return None
    dome = getattr(loaded.config, "dome", None)
    if dome is not None and not dome.default_lights:
        banded = low not in (None, 0.0) or high not in (None, 90.0)
        said = f"every light of the dome{' in its band' if banded else ''} ({len(recorded)})"
    else:
        said = f"the rig's default of {len(recorded)} lights (no --lights)"
    return said, began[len(words) :].strip()


def _differences(asked: StartOptions, manifest: dict[str, Any], loaded: Any) -> list[str]:
    header = manifest.get("adaptive")
    if isinstance(header, dict):
        # what differs, option by option (an --until-error not given is said by its own)
        plain = not asked.is_adaptive and header.get("until_error_deg") is None
        return [
            *(["--adaptive not given, the session is adaptive"] if plain else []),
            *_adaptive_differences(asked, header),
        ]
    if asked.is_adaptive:
        return ["the session ran a planned layout; this asks for an adaptive one"]
    return [
        *_schedule_differences(asked, manifest, loaded),
        *_metering_differences(asked, manifest),
    ]


def _adaptive_differences(asked: StartOptions, header: dict[str, Any]) -> list[str]:
    from rti_rig.app.usecases.adaptive import lights_asked

    diffs = []
    began = lights_asked(header)  # not the default_lights an --adaptive alone designs for
    # --lights N where the session, begun without it, designs for the config's N anyway
    # (default_lights): the same session, choice for choice, as a planned resume's --lights
    # is judged by the layout it gives (it had been refused, and a new session advised)
    designed = header.get("design_lights")
    same_design = began is None and designed is not None and asked.lights == int(designed)
    if asked.lights != began and not same_design:
        diffs.append(f"--lights {_or_none(asked.lights)}, the session {_or_none(began)}")
    if not _same_number(asked.until_error_deg, header.get("until_error_deg")):
        diffs.append(
            f"--until-error {_or_none(asked.until_error_deg)}, the session "
            f"{_or_none(header.get('until_error_deg'))}"
        )
    if asked.min_lights != header.get("min_lights"):
        diffs.append(
            f"--min-lights {_or_none(asked.min_lights)}, the session "
            f"{_or_none(header.get('min_lights'))}"
        )
    objective = asked.objective or "normals"
    if objective != (header.get("objective") or "normals"):
        diffs.append(f"--objective {objective}, the session {header.get('objective')}")
    diffs += _band_differences(asked, header)
    if asked.plan is not None:
        diffs.append("--plan: the session chooses its own lights")
    if asked.auto_exposure:
        diffs.append("--auto-exposure: an adaptive session is not metered")
    elif asked.max_saturated is not None:  # a limit no metering reads, as a new session says
        diffs.append(f"--max-saturated {asked.max_saturated:g}: an adaptive session is not metered")
    return diffs


def _schedule_differences(asked: StartOptions, manifest: dict[str, Any], loaded: Any) -> list[str]:
    """The schedule ``asked`` gives on this rig (planned again, as a new session plans it)
    against the one recorded."""
    from rti_rig.app.usecases.session import NewSessionRequest, new_session_schedule
    from rti_rig.core.schedule import LightSchedule

    recorded = LightSchedule.from_dict(manifest["schedule"])
    if not _chooses_lights(asked):
        # only options that choose no light (--allow-no-normals, the metering's): the session's
        # own lights go on, as a plain --resume's do. Planned again as a new session would
        # plan them, the rig's default layout had been compared with the session's plan, and
        # `--resume S --allow-no-normals` of a raking-light plan refused as another request
        return _allow_difference(recorded, asked)
    request = NewSessionRequest(
        Path(loaded.path),
        Path("."),
        lights=asked.lights,
        plan=asked.plan,
        min_elevation_deg=asked.min_elevation_deg,
        max_elevation_deg=asked.max_elevation_deg,
        allow_no_normals=asked.allow_no_normals,
    )
    what = (
        f"--plan {asked.plan}"
        if asked.plan is not None
        else f"--lights {asked.lights}"
        if asked.lights is not None
        else "--lights not given (the rig's own count)"
    )
    try:
        wanted = new_session_schedule(request, loaded)
    except RtiRigError as exc:  # a request no layout of this rig takes: a difference, said
        # with the session's options, not a refusal of its own that hid them (it had been
        # "asked for 30 lights but the dome has only 24 LEDs …" and nothing of the session)
        return [f"{what}{_band_words(asked)}: {exc}"]
    if (wanted.method == "plan") != (recorded.method == "plan"):
        began = "a plan" if recorded.method == "plan" else "a homogeneous layout"
        return [f"{what} gives {_layout(wanted)}; the session ran {began}"]
    # the band asked, as recorded (the same LEDs or not); a band that differs is what moved
    # the lights, so it is named rather than the --lights that was the session's own
    band = _band_differences(asked, recorded.provenance or {}) if recorded.method != "plan" else []
    if len(wanted) != len(recorded):
        return [f"{what} gives {len(wanted)} lights; the session has {len(recorded)}", *band]
    for i, (mine, theirs) in enumerate(zip(wanted.steps, recorded.steps, strict=True)):
        # a dome's light is its LED (its recorded direction moves with a recalibration the
        # resume accepts with --accept-rig-change); an arm's is its direction
        if (mine.led, theirs.led) != (None, None):
            differs = mine.led != theirs.led
        else:
            differs = float(angle_between_deg(mine.direction, theirs.direction)) > SAME_LIGHT_DEG
        if differs:
            said = f"{what}: its light {i + 1} is {_light(mine)}, the session's {_light(theirs)}"
            return band or [said]
    if band:
        return band
    return _allow_difference(recorded, asked)


def _band_words(asked: StartOptions) -> str:
    """`` with --max-elevation-deg 30`` (the band options given, if any)."""
    words = band_options((asked.min_elevation_deg, asked.max_elevation_deg)).strip()
    return f" with {words}" if words else ""


def _chooses_lights(asked: StartOptions) -> bool:
    """Whether ``asked`` gives an option that chooses the lights (a count, a plan, a band)."""
    return (
        asked.lights is not None
        or asked.plan is not None
        or asked.min_elevation_deg != 0.0
        or asked.max_elevation_deg != 90.0
    )


def _allow_difference(recorded: Any, asked: StartOptions) -> list[str]:
    """``--allow-no-normals`` asked against what the session recorded of it."""
    allowed = bool((recorded.provenance or {}).get("allow_no_normals", False))
    if allowed != asked.allow_no_normals:
        return [
            "--allow-no-normals "
            + ("not given; the session had it" if allowed else "given; the session had not")
        ]
    return []


def _metering_differences(asked: StartOptions, manifest: dict[str, Any]) -> list[str]:
    metered = _metered(manifest)
    if asked.auto_exposure != metered:
        return [
            "--auto-exposure "
            + (
                "not given; the session's exposure was metered"
                if metered
                else "given; the session was not metered"
            )
        ]
    if not metered and asked.max_saturated is not None:
        # a limit no metering reads (a new session refuses it without --auto-exposure): it had
        # gone on, the option ignored in silence
        return [f"--max-saturated {asked.max_saturated:g} given; the session was not metered"]
    if metered:
        from rti_rig.app.usecases.session import NewSessionRequest

        # not given: the default a new session meters with
        limit = asked.max_saturated
        limit = NewSessionRequest.max_saturated if limit is None else limit
        recorded = _recorded_max_saturated(manifest)
        if recorded is not None and not _same_number(limit, recorded):
            given = (
                f"--max-saturated {limit:g}"
                if asked.max_saturated is not None
                else (f"--max-saturated not given ({limit:g})")
            )
            return [f"{given}, the session {recorded:g}"]
    return []


def _band_differences(asked: StartOptions, header: dict[str, Any]) -> list[str]:
    diffs = []
    for flag, mine, key, default in (
        ("--min-elevation-deg", asked.min_elevation_deg, "min_elevation_deg", 0.0),
        ("--max-elevation-deg", asked.max_elevation_deg, "max_elevation_deg", 90.0),
    ):
        theirs = header.get(key, default)
        if not _same_number(mine, theirs):
            diffs.append(f"{flag} {mine:g}, the session {_or_none(theirs)}")
    return diffs


def _metered(manifest: dict[str, Any]) -> bool:
    provenance = (manifest.get("schedule") or {}).get("provenance") or {}
    return isinstance(provenance.get("exposure"), dict)


def _recorded_max_saturated(manifest: dict[str, Any]) -> float | None:
    exposure = ((manifest.get("schedule") or {}).get("provenance") or {}).get("exposure") or {}
    rule = exposure.get("rule") if isinstance(exposure, dict) else None
    value = rule.get("max_saturated_fraction") if isinstance(rule, dict) else None
    return float(value) if isinstance(value, int | float) else None


def _layout(schedule: Any) -> str:
    return "a plan" if schedule.method == "plan" else f"a homogeneous layout of {len(schedule)}"


def _light(step: Any) -> str:
    """``LED 13`` (a dome's), or the light's azimuth/elevation."""
    if step.led is not None:
        return led_said(step.led, step.direction, step.label)
    az, el = az_el_from_direction(step.direction)
    return f"az {float(az):.2f}° el {float(el):.2f}°"


def _same_number(a: Any, b: Any) -> bool:
    if a is None or b is None:
        return a is None and b is None
    return math.isclose(float(a), float(b), rel_tol=1e-9, abs_tol=1e-9)


def _or_none(value: Any) -> str:
    return (
        "not given" if value is None else f"{value:g}" if isinstance(value, float) else str(value)
    )
