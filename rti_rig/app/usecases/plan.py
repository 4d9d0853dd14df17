"""Use case: plan an ordered set of lights for a rig and write it as an ``.lp`` file.

What ``rti-rig plan`` does, as a Python function that needs no command line:
:func:`plan_lights` checks the request (every check before any file is read), reads the rig and
the preview, plans (:func:`rti_rig.planner.make_plan.plan`) and writes the plan;
:func:`draw_plan_figure` then draws its map. The rig is a rig config TOML, or a bare ``.lp``
meaning "a dome with exactly these lights".
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from rti_rig.app.compose import arm_order_for, read_preview_image
from rti_rig.app.config import (
    LoadedRig,
    load_rig_config,
    project_lp_note,
    rig_geometry,
    rtibuilder_project_lp,
)
from rti_rig.app.normals_determined import (
    band_advice,
    refuse_undetermined,
    undetermined_normals,
)
from rti_rig.app.output_files import (
    check_output_file,
    lp_name_note,
    recorded_images,
    rig_inputs,
)
from rti_rig.app.preview_clipping import preview_clipped_note
from rti_rig.app.preview_source import given_light_differs, resolve_preview
from rti_rig.app.usecases.fit_outlook import fit_needs, fit_outlook, fit_without_normals
from rti_rig.core.errors import RtiRigError
from rti_rig.core.fit_minimums import PLAN_DEFAULT_LIGHTS
from rti_rig.core.geometry import direction_from_az_el
from rti_rig.core.image_files import png_alpha_note
from rti_rig.core.lp_format import LpEntry, image_file_name, lights_said, read_lp, write_lp
from rti_rig.core.out_folders import free_name
from rti_rig.core.rig_geometry import ArmGeometry, DomeGeometry, coincident_leds
from rti_rig.core.schedule import LightSchedule
from rti_rig.core.shell_words import shell_word, shown_path
from rti_rig.planner.light_origin import LightOrigin
from rti_rig.planner.make_plan import (
    DEFAULT_OBJECTIVE,
    MIN_PLAN_LIGHTS,
    PlanRequest,
    check_plan_options,
    plan,
)
from rti_rig.planner.plan_report import PlanReport
from rti_rig.runtime.session import image_names


@dataclass(frozen=True)
class PlanLightsRequest:
    """What to plan, for which rig, and where to write it (the options of ``rti-rig plan``)."""

    rig: Path
    out_file: Path = Path("plan.lp")
    #: False where ``rig`` is the command's default (no ``--rig``): a preview from an rti-rig
    #: session is then planned for the rig config its manifest records, and any other plan is
    #: told which rig it was planned for (:func:`_rig_of_preview`).
    rig_given: bool = True
    lights: int = PLAN_DEFAULT_LIGHTS
    #: False where ``lights`` is the command's default, not the user's: a rig with fewer
    #: lights is then told what the default is (it was told it had "asked for 12 lights").
    lights_given: bool = True
    #: A preview image or the session folder ``rti-rig preview`` wrote (None: plan without one).
    preview: Path | None = None
    #: None: ``optimal`` with a preview, ``uniform`` without.
    method: str | None = None
    objective: str | None = None
    #: (azimuth, elevation) in degrees; None: recorded with the preview, or estimated.
    preview_light: tuple[float, float] | None = None
    depth_model: Path | None = None
    min_elevation_deg: float = 0.0
    max_elevation_deg: float = 90.0
    #: each bound of the band was typed, not defaulted: an arm that cannot reach the band says
    #: so even of 0..90, naming only the options typed
    min_elevation_given: bool = False
    max_elevation_given: bool = False
    #: None: the rig config's ``[camera] signal_noise`` (0 for a bare ``.lp``).
    signal_noise: float | None = None
    material: str = "auto"
    figure: Path | None = None
    force: bool = False
    #: Plan lights that cannot determine a normal (one plane, bunched at the zenith) with a
    #: warning, in place of the refusal: a ring of low lights for a relightable PTM/HSH only.
    allow_no_normals: bool = False
    #: ``(done, total)`` of an arm's stop-order search as it goes (seconds at 1000 stops, a
    #: minute before its neighbour lists, which ``plan`` had passed in silence); None: not told
    order_progress: Callable[[int, int], None] | None = None

    @property
    def method_or_default(self) -> str:
        return self.method or ("optimal" if self.preview is not None else "uniform")

    @property
    def objective_or_default(self) -> str:
        return self.objective or DEFAULT_OBJECTIVE


@dataclass(frozen=True)
class PlannedLights:
    """A written plan and the evidence behind it."""

    schedule: LightSchedule
    report: PlanReport
    geometry: DomeGeometry | ArmGeometry
    out_file: Path
    method: str
    objective: str
    #: What the tolerant ``.lp`` reader accepted but the user should know (file, line, what).
    notes: tuple[str, ...] = ()
    #: The rig the plan is for, as ``run`` takes it (the preview session's recorded config
    #: where no ``--rig`` was given): the CLI's next step names it.
    rig: Path | None = None


@dataclass(frozen=True)
class _PreviewRig:
    """The rig a plan without ``--rig`` is for, and the note that says so; ``manifest`` and
    ``recorded`` (the identity it records) where it is the rig the preview's session names."""

    config: Path
    note: str
    manifest: Path | None = None
    recorded: dict[str, object] | None = None


#: The identity keys that say where a rig's lights can be (:mod:`rti_rig.app.rig_identity`):
#: what a plan is made of. The camera, exposure, scene or a dome's controller board may have
#: changed since the preview without changing which directions a plan can hold.
_LIGHT_KEYS = ("kind", "lights", "light_positions", "light_directions", "arm_reach")


def _rig_of_preview(req: PlanLightsRequest) -> _PreviewRig:
    """The rig to plan for when no ``--rig`` was given: the rig config the preview's rti-rig
    session records (a session folder, or an image in one), else ``req.rig`` (the default),
    each with a note naming it. A recorded config that is not there any more is refused.

    Why: ``rti-rig plan S`` of a preview shot on another rig planned for the shipped simulated
    dome in silence, its advice naming that dome; the plan was refused only by ``run`` ("no
    LED of this dome within 1° … replan"), though the session's manifest names its rig."""
    from rti_rig.app.preview_source import session_of_image
    from rti_rig.runtime.session import MANIFEST, read_manifest

    preview = req.preview
    default = f"rti-rig's simulated dome, {shown_path(req.rig)}"
    give = "give --rig RIG.toml to plan for your rig"
    if preview is None:
        return _PreviewRig(
            req.rig, f"no --rig given and no preview: planning for {default}; {give}"
        )
    root = preview if (preview / MANIFEST).is_file() else None
    if root is None and preview.is_file():
        root = session_of_image(preview)
    if root is None:
        return _PreviewRig(
            req.rig,
            f"the preview {shown_path(preview)} is not from an rti-rig session (no {MANIFEST} "
            f"beside it), so nothing says which rig it was shot on: planning for {default}; "
            f"{give}",
        )
    manifest = root / MANIFEST
    rig = read_manifest(root).get("rig") or {}
    config = rig.get("config_path") if isinstance(rig, dict) else None
    if not isinstance(config, str) or not config:
        return _PreviewRig(
            req.rig,
            f"{shown_path(manifest)} does not say which rig config the preview was shot on: "
            f"planning for {default}; {give}",
        )
    path = Path(config)
    if not path.is_file():
        raise RtiRigError(
            f"{shown_path(manifest)}: the preview was shot on the rig {shown_path(path)}, "
            "which is not there any more (moved or renamed?): give --rig with its path now "
            "(or another rig's) to plan for it"
        )
    recorded = rig.get("identity")
    return _PreviewRig(
        path,
        f"planning for the rig the preview was shot on: {shown_path(path)} (from "
        f"{shown_path(manifest)}); give --rig to plan for another",
        manifest,
        recorded if isinstance(recorded, dict) else None,
    )


def _check_preview_rig(preview_rig: _PreviewRig, loaded: LoadedRig) -> None:
    """Refuse the preview session's rig config where its lights are no longer where the
    session recorded them (edited, or another file under its name since the preview).

    Why: the plan is made of the rig's light directions, and a plan for the config as it is
    now, from a preview shot with lights elsewhere, is what ``--rig`` asks for knowingly;
    compared as a resume compares a rig (:func:`~rti_rig.app.rig_identity.
    identity_differences`), on where the lights can be only (:data:`_LIGHT_KEYS`)."""
    if preview_rig.recorded is None or preview_rig.manifest is None:
        return  # a session from before identities were recorded: the file is all there is
    from rti_rig.app.rig_identity import identity_differences, rig_identity

    now = rig_identity(loaded)
    diffs = identity_differences(
        {k: v for k, v in preview_rig.recorded.items() if k in _LIGHT_KEYS},
        {k: v for k, v in now.items() if k in _LIGHT_KEYS},
    )
    if diffs:
        config = shell_word(str(preview_rig.config))
        raise RtiRigError(
            f"{shown_path(preview_rig.manifest)}: the rig the preview was shot on, "
            f"{shown_path(preview_rig.config)}, is no longer the rig it recorded ("
            + "; ".join(diffs)
            + f"): give --rig to say which rig to plan for (--rig {config} to plan for it as "
            "it is now)"
        )


def _bare_lp_dome(rig: Path, notes: list[str]) -> tuple[DomeGeometry, list[LpEntry]]:
    """A bare ``.lp`` as a rig: a dome with exactly these lights, each listed once."""
    from rti_rig.runtime.session import refuse_if_in_use

    # a session's lights.lp while its run still captures lists the lights fired so far: a
    # plan had been made for "a dome of 11 LEDs" of what would be 72
    refuse_if_in_use(rig.parent, "plan on its lights")
    entries = read_lp(rig, upper_hemisphere=True, notes=notes)
    pair = coincident_leds([e.direction for e in entries])
    if pair is not None:
        i, j = pair
        raise RtiRigError(
            f"{rig}: {lights_said(entries, (i, j))} give the same direction; as --rig, an .lp "
            "means a dome with exactly these lights, each listed once (remove the repeats)"
        )
    return DomeGeometry([e.direction for e in entries], tuple(e.name for e in entries)), entries


def _signal_noise(req: PlanLightsRequest, loaded: LoadedRig | None, objective: str) -> float:
    """The signal noise to plan for: the request's, else the rig config's camera's."""
    if req.signal_noise is not None:
        return req.signal_noise
    if loaded is None or loaded.config.camera.signal_noise <= 0:
        return 0.0
    noise = loaded.config.camera.signal_noise
    if objective != "normals":
        raise RtiRigError(
            f"{shown_path(req.rig)}: [camera] signal_noise = {noise:g} is modelled by the normals "
            f"objective only; give --signal-noise 0 to plan for --objective {objective}"
        )
    return noise


def _check_outputs(req: PlanLightsRequest, loaded: LoadedRig | None) -> None:
    # the rig's own files (its LED .lp, intensity correction, LED map) are inputs too
    # a bare .lp's images (a recorded acquisition) too: a plan had been written over one
    rig_files = recorded_images(req.rig) if loaded is None else rig_inputs(req.rig, loaded)
    rig_files.pop("RIG", None)  # named "rig file" here
    inputs: dict[str, Path | None] = {
        "preview": req.preview,
        "rig file": req.rig,
        "depth model": req.depth_model,
        **rig_files,
    }
    check_output_file(req.out_file, req.force, inputs)
    if req.figure is not None:
        from rti_rig.app.plan_figure import check_figure_path  # matplotlib only when asked

        check_figure_path(req.figure)
        check_output_file(req.figure, req.force, inputs, "--figure")
        if req.figure.resolve() == req.out_file.resolve():
            raise RtiRigError(f"--figure {req.figure} is the --out plan file; choose another")


def plan_lights(req: PlanLightsRequest) -> PlannedLights:
    """Check, plan and write ``req.out_file``; nothing is read before the options are checked
    but the preview session's manifest, which says which rig the plan is for (its messages
    name that rig)."""
    preview_rig = None
    if not req.rig_given:
        preview_rig = _rig_of_preview(req)
        req = replace(req, rig=preview_rig.config, rig_given=True)
    planned = _plan_lights(req, preview_rig)
    # an RTIBuilder project folder is planned on its .lp, and run as that (set inside)
    planned = replace(planned, rig=planned.rig or req.rig)
    if preview_rig is None:
        return planned
    return replace(planned, notes=(preview_rig.note, *planned.notes))


def _plan_lights(req: PlanLightsRequest, preview_rig: _PreviewRig | None) -> PlannedLights:
    """:func:`plan_lights` for ``req.rig``: ``preview_rig``, where ``req.rig`` was found in
    the preview's session, is checked against what the session recorded once it is loaded."""
    project_lp = rtibuilder_project_lp(req.rig)
    if project_lp is not None:  # an RTIBuilder project folder: planned on its .lp, as given
        said = project_lp_note(req.rig, project_lp, "planning on")
        planned = plan_lights(replace(req, rig=project_lp))
        return replace(planned, notes=(said, *planned.notes))
    method, objective = req.method_or_default, req.objective_or_default
    if req.lights < MIN_PLAN_LIGHTS:
        raise RtiRigError(
            f"--lights {req.lights}: give at least {MIN_PLAN_LIGHTS} lights to plan; fewer "
            f"cannot determine a surface normal ({fit_needs()}), so no planner can do better than "
            "another (a 2-light plan read 90° expected error); a test shot of 1 or 2 lights "
            f"needs no plan: rti-rig run {_config_shown(req.rig)} --lights 1 --out "
            f"{_run_folder(req.out_file, 'test-shot')}"
        )
    check_plan_options(
        method=method,
        objective=objective,
        n=req.lights,
        has_preview=req.preview is not None,
        preview_light=req.preview_light,
        depth_model=req.depth_model,
        min_elevation_deg=req.min_elevation_deg,
        max_elevation_deg=req.max_elevation_deg,
        signal_noise=req.signal_noise or 0.0,
        material=req.material,
        rig=_config_shown(req.rig),
        out=_run_folder(req.out_file),
    )
    bare_lp = req.rig.suffix.lower() == ".lp"
    loaded = None if bare_lp else load_rig_config(req.rig)
    if preview_rig is not None and loaded is not None:
        _check_preview_rig(preview_rig, loaded)
    if loaded is not None:
        from rti_rig.app.flash_sync import refuse_options

        # a camera-triggered dome runs its own order only: a session beside the plan's file
        refuse_options(loaded, req.out_file.parent / "session", plan=True)
    notes: list[str] = [] if loaded is None else list(loaded.notes)
    _check_outputs(req, loaded)
    arm_order = None
    entries: list[LpEntry] = []
    geometry: DomeGeometry | ArmGeometry
    if loaded is None:
        geometry, entries = _bare_lp_dome(req.rig, notes)
    else:
        geometry = rig_geometry(loaded)
        arm_order = arm_order_for(loaded, req.order_progress)
    if (
        not req.lights_given
        and isinstance(geometry, DomeGeometry)
        and MIN_PLAN_LIGHTS <= geometry.count < req.lights
    ):
        raise RtiRigError(
            f"{shown_path(req.rig)}: the dome has {geometry.count} LEDs, fewer than the "
            f"{req.lights} lights plan plans when --lights is not given: give --lights "
            f"{geometry.count} or fewer"
        )
    signal_noise = _signal_noise(req, loaded, objective)
    az_el, light_note, image, unrecorded = req.preview_light, None, None, None
    if req.preview is not None:
        rig_lp = (req.rig, entries) if loaded is None else None
        source = resolve_preview(req.preview, rig_lp, az_el is not None)
        if az_el is None and source.light_az_el_deg is not None:
            az_el, light_note = source.light_az_el_deg, source.light_source
        unrecorded = source.unrecorded
        if az_el is not None and light_note is None:
            differs = given_light_differs(req.preview, az_el, rig_lp)
            if differs is not None:
                notes.append(differs)
        stored = read_preview_image(source.image)
        rig_word = _config_shown(req.rig)
        meter = (
            None
            if rig_word == "RIG.toml"
            else f"rti-rig preview {rig_word} --out {_run_folder(req.out_file, 'preview')} "
            "--auto-exposure"
        )
        clipped = preview_clipped_note(source.image, stored, meter)
        if clipped is not None:
            notes.append(clipped)
        image, colour_note = preview_in_its_space(source.image, stored)
        if colour_note is not None:
            notes.append(colour_note)
        turned = preview_orientation_note(source.image)
        if turned is not None:
            notes.append(turned)
        # its alpha or transparency key dropped, said as run and fit say it of an acquisition
        notes.extend(png_alpha_note([source.image.name], [source.image]))
    schedule, report = plan(
        PlanRequest(
            image,
            geometry,
            req.lights,
            method,
            objective,
            preview_light=az_el,
            preview_light_origin=LightOrigin.GIVEN if light_note is None else LightOrigin.RECORDED,
            depth_model=req.depth_model,
            min_elevation_deg=req.min_elevation_deg,
            max_elevation_deg=req.max_elevation_deg,
            min_elevation_given=req.min_elevation_given,
            max_elevation_given=req.max_elevation_given,
            signal_noise=signal_noise,
            material=req.material,
            arm_order=arm_order,
            rig_said=_config_shown(req.rig),
            preview_folder_said=_run_folder(req.out_file, "preview"),
            uniform_said=_uniform_command(req),
        )
    )
    # every planner picks among the rig's lights in the band: where those cannot determine a
    # normal, any choice cannot (the plan had been written, "expected RMS normal error 90.00")
    _check_determined(req, schedule, notes)
    if report.preview_light_origin is not None:
        report.preview_light_source = preview_light_said(
            report.preview_light_origin, light_note, unrecorded, report.preview_light_why_zenith
        )
    if req.signal_noise and not report.signal_noise:
        # as --material's note says (planner.make_plan): an option given and silently unused
        # had read as if the plan modelled the JPEG noise
        report.notes.append(
            f"--signal-noise {req.signal_noise:g} is not used: no surface was modelled "
            f"({method} needs none)"
        )
    if bare_lp:
        # the acquisition's own names, written as the .lp profile allows (no whitespace): a
        # name with spaces (RTIBuilder's 'H:\\RTI Data\\...' paths) had stopped the plan with a
        # traceback; the plan is run by its directions, the names are labels
        names = _lp_labels([s.label for s in schedule.steps])
    else:
        names = [f"{n}.jpg" for n in image_names(len(schedule))]
    write_lp(
        req.out_file,
        [LpEntry(n, s.direction) for n, s in zip(names, schedule.steps, strict=True)],
    )
    # what the session it plans gives `rti-rig fit` (run says it again before it shoots)
    # (lights planned with --allow-no-normals: their own note has said it, from the same rules)
    determined = undetermined_normals(np.array([s.direction for s in schedule.steps])) is None
    if determined and (outlook := fit_outlook(len(schedule))) is not None:
        notes.append(outlook)
    if (misnamed := lp_name_note(Path(req.out_file), run_reads_it=True)) is not None:
        notes.append(misnamed)
    return PlannedLights(schedule, report, geometry, req.out_file, method, objective, tuple(notes))


def preview_in_its_space(path: Path, image: np.ndarray) -> tuple[np.ndarray, str | None]:
    """The preview's pixels in linear sRGB where its file says a space other than sRGB (or is
    16-bit sRGB-encoded), converted as a session's frames are
    (:func:`~rti_rig.drivers.cameras.colour_convert.to_linear_srgb`), and what to say of it;
    as read otherwise (the planner then takes 8-bit as sRGB and 16-bit as linear). Why: a
    preview's brightness was read through the sRGB curve (8-bit) or as linear (16-bit)
    whatever its file said: a ProPhoto TIFF's gamma 1.8 was taken for the light itself, and
    the relief and the light estimated from it were of flattened shading. A RAW preview
    (decoded linear camera RGB) and a grey one are left as they are."""
    from rti_rig.core.image_files import is_camera_raw
    from rti_rig.drivers.cameras.colour_convert import needs_conversion, to_linear_srgb
    from rti_rig.drivers.cameras.file_colour import file_colour

    if is_camera_raw(path) or image.ndim != 3 or image.shape[2] not in (3, 4):
        return image, None
    colour = file_colour(path)
    if colour.space == "other":
        return image, (
            f"preview {shown_path(path)} is {colour.name} (said by {colour.said_by}), a space "
            "rti-rig does not convert: its brightness is read as if sRGB (8-bit through the "
            "sRGB curve, 16-bit as linear); for a plan from its true shading, export it as sRGB"
        )
    if colour.space == "srgb" and colour.exif_linear and image.dtype == np.uint16:
        return image, (  # (needs_conversion's rule: an Exif tag copied from the camera)
            f"preview {shown_path(path)} is 16-bit, says sRGB only by its Exif ColorSpace 1 "
            "(no ICC profile) and was written by dcraw or LibRaw (its Software tag), whose "
            "16-bit output is linear: its brightness is read as linear, no curve undone; if "
            "it is sRGB-encoded, export it with the sRGB ICC profile embedded"
        )
    if not needs_conversion(colour, image.dtype):
        return image, None
    converted = to_linear_srgb(image, colour)
    curve = (
        "taken as linear, as its profile's curve (gamma 1.0) says,"
        if colour.linear_curve
        else f"{converted.record['curve_undone']} undone"
    )
    # its colours sRGB cannot show are clipped, and counted (as a session's frame's are,
    # colour_convert.clipped_notice): the plan's brightness of those pixels is the clipped one
    clipped = (
        f"; {converted.clipped} of its {image.shape[0] * image.shape[1]} pixels lie outside "
        "sRGB's gamut and were clipped to it"
        if converted.clipped
        else ""
    )
    # an sRGB file's primaries are sRGB's already: only its curve was read differently
    primaries = "its primaries kept as" if colour.space == "srgb" else "its primaries converted"
    return converted.pixels, (
        f"preview {shown_path(path)} is {colour.name} (said by {colour.said_by}): its brightness "
        f"is read in linear sRGB, {curve} and {primaries} to sRGB's{clipped}"
    )


def preview_orientation_note(image: Path) -> str | None:
    """What to say of a JPEG or TIFF preview whose EXIF/TIFF Orientation is not 1; None for
    one upright as stored, another format, or no tag.

    Why: the preview is planned in its stored pixel order, as a session's JPEGs and TIFFs are
    recorded (folder_watch keeps them as stored and says so), so the plan's lights and the
    session's images share one frame; a phone preview marked "rotate 90°" had been planned
    sideways to the picture a viewer shows, with not a word."""
    from rti_rig.drivers.cameras.exif_tags import jpeg_orientation, tiff_orientation

    suffix = image.suffix.lower()
    if suffix in (".jpg", ".jpeg"):
        kind, turned = "JPEG", jpeg_orientation(image)
    elif suffix in (".tif", ".tiff"):
        kind, turned = "TIFF", tiff_orientation(image)
    else:
        return None
    if turned in (None, 1):
        return None
    from rti_rig.drivers.cameras.raw_decode import (
        MIRRORED_ORIENTATIONS,
        ORIENTATION_NAMES,
        orientation_words,
    )

    mirrored = turned in MIRRORED_ORIENTATIONS
    return (
        f"the preview {shown_path(image.name)} is marked as "
        f"{'mirrored' if mirrored else 'taken turned'} (Orientation tag "
        f"{turned}: {ORIENTATION_NAMES.get(turned, 'not a known value')}): it is planned in "
        f"its {kind}'s stored pixel order, not {orientation_words(turned)[1]}"
        " as a viewer shows it, as a "
        "session's JPEGs and TIFFs are recorded; the plan holds for a session shot with the "
        "camera held as it was for this preview (docs/cameras.md)"
    )


def preview_light_said(
    origin: LightOrigin, recorded_by: str | None, unrecorded: str | None, why_zenith: str | None
) -> str:
    """The plan's preview light's origin in the words the plan prints and saves: the one place
    it is worded (the planner gives the fact, :class:`LightOrigin`).

    ``recorded_by``: which record gave the light; ``unrecorded``: why none did; ``why_zenith``:
    why no direction could be estimated."""
    if origin is LightOrigin.RECORDED:
        return recorded_by or origin.value
    if origin is LightOrigin.ESTIMATED:
        return estimated_light_said(unrecorded)
    if origin is LightOrigin.ZENITH_ASSUMED:
        return zenith_assumed_said(unrecorded, why_zenith or "")
    return "given"


#: How far the light estimated from a preview was off the light that fired, where that was
#: measured: the real icon's 8 previews, docs/research/planner.md. A range seen, not a bound.
ESTIMATE_OFF_ON_ICON_DEG = (17, 59)
#: ... and on image05.jpg of tests/data/neuralrti_replay (a real dome acquisition, its light at
#: 16° elevation): off by more than the icon's worst, so the icon's range is not read as a bound
ESTIMATE_OFF_GRAZING_DEG = 106


def estimated_light_said(unrecorded: str | None) -> str:
    """How the plan's preview light was had when nothing recorded it and none was given: how it
    was estimated, why, what is known of its error, and how to give the real one.

    Why: it had been labelled "estimated (Zheng-Chellappa)" and no more, though the estimate
    is far from the light that fired (17–59° on the icon's previews, 106° on another real
    acquisition's image lit at 16°) and its error on this image is not known;
    ``--preview-light`` and ``rti-rig preview`` give the light itself."""
    lo, hi = ESTIMATE_OFF_ON_ICON_DEG
    why = f", as {unrecorded}" if unrecorded else ""
    return (
        f"estimated by Zheng & Chellappa's method from the image's shading{why}: how far off "
        f"it is here is not known ({lo}–{hi}° on the 8 previews of a real icon, "
        f"{ESTIMATE_OFF_GRAZING_DEG}° on another real acquisition's image lit at 16°, "
        "docs/research/planner.md); "
        "--preview-light AZ,EL gives the light that fired"
    )


def zenith_assumed_said(unrecorded: str | None, why: str) -> str:
    """The plan's preview light when no direction could be estimated from the image and the
    zenith was assumed: that, why, and how to give the real one.

    Why: Zheng & Chellappa's slant has no solution for shading that varies little (a flat,
    evenly lit painting: ``4μ1/g > 1``), the estimate then falls back to the zenith, and the
    plan said "az 0.0°, el 90.0° (estimated by Zheng & Chellappa's method …)", as if the image
    had shown a light overhead."""
    unknown = f"; {unrecorded}" if unrecorded else ""
    return (
        f"the zenith, assumed: no light direction could be estimated from the image, as {why}"
        f"{unknown}; --preview-light AZ,EL gives the light that fired"
    )


def _check_determined(req: PlanLightsRequest, schedule: LightSchedule, notes: list[str]) -> None:
    """Refuse, before the plan is written, lights that cannot determine a normal, unless
    ``allow_no_normals`` asks for them: then a warning among the plan's notes.

    Why the way through: ``rti-rig run`` had ``--allow-no-normals`` and ``plan`` had not, so a
    conservator who wants only a relightable PTM/HSH from a ring of low lights could capture
    such lights but not plan them. The warning says what ``rti-rig fit`` will make of them,
    and that ``run --plan`` asks for the same option (the .lp, an interchange file other RTI
    tools read, carries no note of it).
    """
    lights = np.array([st.direction for st in schedule.steps], dtype=np.float64)
    if not req.allow_no_normals:
        refuse_undetermined(
            lights,
            "planned lights",
            f"the lights of {shown_path(req.rig)} between {req.min_elevation_deg:g}°.."
            f"{req.max_elevation_deg:g}° elevation leave no other choice: "
            + band_advice(req.min_elevation_deg, req.max_elevation_deg)
            + "; or, to plan them all the same (relighting only, no normal maps wanted), add "
            "--allow-no-normals",
            "nothing was written",
        )
        return
    reason = undetermined_normals(lights, "planned lights")
    if reason is not None:
        notes.append(
            f"{reason}; planned as asked (--allow-no-normals): "
            f"{fit_without_normals(len(lights))}; run it with --allow-no-normals too (the "
            "plan's Next line says the whole command)"
        )


def _config_shown(rig: Path) -> str:
    """The rig ``plan`` was given, as a ``run`` command line names it, one shell word: a bare
    ``.lp`` rig is named by the rig config beside it whose ``[dome] lp_file`` it is, or, where
    none is, by ``RIG.toml``, the one word left to fill in.

    Why: ``RIG.toml`` had been said for a bare ``.lp`` even with its config beside it. Where
    no config lists it, the ``.lp`` itself is no answer: ``run`` takes an ``.lp`` as a
    recorded acquisition to replay, and refuses one with no images beside it for its missing
    images, which would send the user after images, not a rig config."""
    rig = Path(rig)
    if rig.suffix.lower() != ".lp":
        return shell_word(str(rig))
    config = _config_listing(rig)
    return "RIG.toml" if config is None else shell_word(str(config))


def _config_listing(lp: Path) -> Path | None:
    """The first rig config (``*.toml``, by name) in ``lp``'s folder whose ``[dome] lp_file``
    (relative to the config's real folder, as the config is read) is ``lp``; None where none
    is, or the folder cannot be read. A config that does not parse is passed over: this only
    names a command, the command's own run says what is wrong with it."""
    import tomllib

    try:
        target = lp.resolve()
        candidates = sorted(lp.parent.glob("*.toml"))
    except OSError:
        return None
    for path in candidates:
        try:
            data = tomllib.loads(path.read_text(encoding="utf-8"))
            dome = data.get("dome")
            name = dome.get("lp_file") if isinstance(dome, dict) else None
            if isinstance(name, str) and (path.resolve().parent / name).resolve() == target:
                return path
        except (OSError, UnicodeDecodeError, tomllib.TOMLDecodeError, ValueError):
            continue
    return None


def _run_folder(plan_file: Path, name: str = "planned") -> str:
    """A folder for a ``run`` that a ``plan`` message offers, as a shell word: ``name`` beside
    the plan file, ``-2``… added if taken (``--out DIR`` pasted had made DIR)."""
    return shell_word(str(free_name(Path(plan_file).parent / name, folder=True)))


def _uniform_command(req: PlanLightsRequest) -> str:
    """The ``rti-rig plan`` command for an even layout of ``req``'s rig and count, as the
    note on many optimised lights offers it: the band typed kept (a 10° floor only where none
    was typed), and a free ``.lp`` beside the plan.

    Why: the note said "--method uniform --min-elevation-deg 10 did better" even to a user
    who had set ``--min-elevation-deg 55``, and as options, not a command to paste."""
    floor = req.min_elevation_deg if req.min_elevation_given else 10.0
    floor_said = f" --min-elevation-deg {floor:g}"
    ceiling = f" --max-elevation-deg {req.max_elevation_deg:g}" if req.max_elevation_given else ""
    out_file = Path(req.out_file)
    even = free_name(out_file.with_name(f"{out_file.stem}-uniform{out_file.suffix or '.lp'}"))
    return (
        f"rti-rig plan --rig {shell_word(str(req.rig))} --lights {req.lights} --method uniform"
        f"{floor_said}{ceiling} --out {shell_word(str(even))}"
    )


def run_plan_command(rig: Path, plan_file: Path, allow_no_normals: bool) -> str:
    """The ``rti-rig run`` command line that runs ``plan_file`` on ``rig``, with
    ``--allow-no-normals`` where asked: the rig config given to ``plan`` (a bare ``.lp`` rig
    named as :func:`_config_shown` names it), the plan, and a folder beside the plan that does
    not exist yet.

    Why: the advice had been ``rti-rig run --plan PLAN.lp --allow-no-normals``, which ``run``
    refuses ("give a RIG_CONFIG and --out DIR"), then ``--out DIR``, which pasted made a
    folder named DIR."""
    plan = shell_word(str(plan_file))
    allow = " --allow-no-normals" if allow_no_normals else ""
    return f"rti-rig run {_config_shown(rig)} --plan {plan} --out {_run_folder(plan_file)}{allow}"


def next_run_command(planned: PlannedLights) -> str:
    """The ``run`` that shoots a written plan, for ``plan`` to end with: on the rig it was
    planned for (the preview session's where no ``--rig`` was given), with
    ``--allow-no-normals`` only where its lights need it (``run --plan`` refuses them without).

    Why: ``plan`` ended at "Planned 12 lights → plan.lp"; ``preview`` and ``run`` each print
    the command that comes next, and the plan, the step between them, did not."""
    lights = np.array([s.direction for s in planned.schedule.steps], dtype=np.float64)
    undetermined = undetermined_normals(lights, "planned lights") is not None
    return run_plan_command(planned.rig or Path("RIG.toml"), planned.out_file, undetermined)


def _lp_labels(labels: list[str]) -> list[str]:
    """``labels`` as .lp names: each unchanged where the .lp profile allows it (ASCII, no
    whitespace, no leading '#'), else its file name with accents dropped and whitespace as
    underscores; kept unique (``-2``, ``-3``... before the extension where two coincide)."""
    import unicodedata

    out: list[str] = []
    for label in labels:
        name = label
        if not (name.isascii() and name.split() == [name] and not name.startswith("#")):
            plain = unicodedata.normalize("NFKD", image_file_name(label))
            plain = plain.encode("ascii", "ignore").decode()
            name = "_".join(plain.split()).lstrip("#") or "light"
        stem, dot, ext = name.rpartition(".")
        base, k = name, 2
        while name in out:
            name = f"{stem}-{k}.{ext}" if dot else f"{base}-{k}"
            k += 1
        out.append(name)
    return out


def draw_plan_figure(req: PlanLightsRequest, planned: PlannedLights) -> Path:
    """Draw the plan's map to ``req.figure``; the .lp is already written, so a failure here
    names the map file and leaves the plan in place."""
    from rti_rig.app.plan_figure import expected_caption, layout_figure, write_layout_figure

    assert req.figure is not None
    report = planned.report
    light = report.preview_light_az_el_deg
    caption = expected_caption(report.expected_meaning or "expected error", report.expected)
    how = f"{planned.method}/{planned.objective}"
    try:
        fig = layout_figure(
            [s.direction for s in planned.schedule.steps],
            planned.geometry,
            None if light is None else direction_from_az_el(*light),
            f"{len(planned.schedule.steps)} lights · {how} · {req.rig.name}",
            [caption] if caption else [],
            req.min_elevation_deg,
            req.max_elevation_deg,
        )
        write_layout_figure(req.figure, fig)
    except (OSError, ValueError, RuntimeError) as exc:
        raise RtiRigError(
            f"--figure {req.figure}: could not write the map ({exc}); the plan itself was written"
        ) from None
    return req.figure
