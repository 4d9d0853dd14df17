"""The trade on the user's own object: `rti-rig bench tradeoff --from ACQ/dirs.lp --out DIR`.

A conservator runs this once on a dense acquisition of their own (an `.lp` with its images) to
decide how many lights their objects need.

* **Normals**: robust photometric stereo on every light of the acquisition is the reference
  (on the mask of well-lit pixels); each plan's normal error is measured against it.
* **Relighting**: about a sixth of the lights (``held_out_lights``: one drawn in each of as
  many elevation bands, each band holding as many of the acquisition's lights) are held out
  *before anything is planned*: no plan may take them, and every plan's relighting PSNR is
  measured on the same held-out images. (Scoring each plan on the lights it did not take, as
  this benchmark did before, scores different plans on different lights: a plan that took the
  grazing lights was then judged on the easier high ones.) The fit of every light that is not
  held out is the reference row `all` (not a ceiling: its model, of the order its count allows,
  can relight worse than a sparser layout fitted with a simpler one).

For N lights (those below the count of lights not held out, among 6, 9, 12, 18, 24, 36, 48),
every plan chosen among the lights not held out:

* `uniform` — the homogeneous layout, at floor 0° and at the floor that does best here
  (tuned with hindsight, which a user without this dense acquisition could not do);
* `optimal` — `plan --rig ACQ/dirs.lp --method optimal` (no preview: a level surface);
* `adaptive` — `run ACQ/dirs.lp --adaptive --lights N` (the same chooser, fed these images; one
  run per N, since with N known the design is chosen for N), with the normals objective and
  with `--objective relight`.

Session time: N lights at the replayed dome's 1.17 s a light (the default dome timing), or at
the step of the dome ``--rig`` gives (:func:`rig_facts`, its firmware's own hold
window included where it times its LEDs itself). The
images are read as the replay rig reads them (JPEG decoded and linearised, 16-bit on their own
white: 4095 for 12-bit camera data, read as the replay and the fit read it), averaged to grey,
and shrunk to at most ``MAX_PX`` wide for speed.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from itertools import pairwise
from pathlib import Path
from typing import Any

import cv2
import numpy as np

from benchmarks.tradeoff import Row, best_floor, plot, write_csv
from rti_rig.core.errors import RtiRigError
from rti_rig.core.shell_words import shell_word

COUNTS = (6, 9, 12, 18, 24, 36, 48)
FLOORS = (0.0, 10.0, 20.0, 30.0)
MAX_PX = 256
#: the share of an acquisition's lights held out to score relighting, and the fewest held out
HELD_OUT_SHARE = 1 / 6
MIN_HELD_OUT = 3
#: the fewest lights a trade-off plans from (a PTM needs 6; the smallest N is 6, below them)
MIN_CANDIDATES = 7


def replay_seconds_per_light() -> float:
    """The time one light takes on the replayed dome (`rti-rig run ACQ/dirs.lp`): the
    config's default timing and exposure, as the replay rig is built from them.

    Why from the defaults: the sum had been written out by hand (0.02 + 0.1 + 0.05 + 0.3 +
    0.7), and a changed default would have left the trade's time axis on the old one while
    the replayed run's own "Session time on the real rig" moved."""
    from rti_rig.app.config import CameraConfig, TimingConfig

    t = TimingConfig()
    exposure_s = float(CameraConfig.model_fields["exposure_s"].default)
    return t.light_switch_s + t.settle_s + exposure_s + t.readout_s + t.transfer_s


PER_LIGHT_S = replay_seconds_per_light()
#: How the summary names where ``PER_LIGHT_S`` comes from.
PER_LIGHT_SAID = "the replayed dome's default timing"


#: Said after the time's source when the acquisition is a session shot on an arm.
ARM_TIMES_SAID = (
    "; this acquisition was shot on an arm (its manifest says so), whose session time depends "
    "on its moves between the lights, which this trade does not plan: the times below are a "
    "dome's at that step, not the arm's. A dry run of the arm's config with --lights N says "
    "the arm's"
)


def _session_rig(lp: Path) -> dict[str, Any]:
    """The ``rig`` record of the session whose .lp ``lp`` is (its manifest beside it); empty
    for an acquisition that is no session, or a manifest that cannot be read."""
    import json

    # read for its rig alone, tolerantly: read_manifest's checks of a whole session are not
    # this note's to make (a manifest it would refuse still says what rig shot the images)
    try:
        manifest = json.loads((Path(lp).parent / "manifest.json").read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return {}
    rig = manifest.get("rig") if isinstance(manifest, dict) else None
    return rig if isinstance(rig, dict) else {}


def shot_on_an_arm(lp: Path) -> bool:
    """Whether ``lp`` is a session's .lp whose manifest (beside it) records an arm rig.

    Why: the trade on an arm session said "1.17 s a light (the replayed dome's default
    timing)" and 58 s for 50 lights the arm had taken 124.8 s for, with no word that the
    times were a dome's (``--rig`` refuses an arm's config, rightly: its time depends on the
    moves). A manifest that cannot be read says nothing either way."""
    return _session_rig(lp).get("kind") == "arm"


def advice_rig(lp: Path, rig: Path | None) -> str:
    """The rig config the advice's commands name: ``--rig``'s, else the one the session
    (``lp``'s manifest) was shot with where it is still there, else ``RIG``."""
    if rig is not None:
        return shell_word(rig)
    shot_with = _session_rig(lp).get("config_path")
    if isinstance(shot_with, str) and Path(shot_with).is_file():
        return shell_word(shot_with)
    return "RIG"


def rig_facts(rig_path: Path) -> tuple[tuple[float, str], int]:
    """From one reading of the user's dome config: (seconds a light takes on it, the words that
    say where that comes from) — its ``[timing]`` and ``[camera] exposure_s``, summed as a dry
    run on the simulated dome counts a step — and its LED count. What the CLI reads before
    minutes of computing, so that the trade is timed and its advice bounded by the config it
    checked.

    Why: the trade is for deciding how many lights the user's own objects need, and its time
    axis had always been the replayed dome's defaults (1.17 s a light), where a DSLR dome's
    step takes seconds; and an 8-LED dome had been advised a 36-light session, which `run`
    refused (the advice names no session of more lights than the dome has). An arm is
    refused: its time depends on its moves between the lights, which an acquisition's
    directions do not give it. Raises ``RtiRigError`` naming the file."""
    from rti_rig.app.config import load_rig_config, rig_geometry

    loaded = load_rig_config(rig_path)
    per_light = _seconds_per_light(rig_path, loaded.config)
    return per_light, len(rig_geometry(loaded).directions)


def _seconds_per_light(rig_path: Path, cfg: Any) -> tuple[float, str]:
    from rti_rig.core.errors import RtiRigError
    from rti_rig.core.shell_words import shown_path

    if cfg.kind != "dome":
        raise RtiRigError(
            f"--rig {shown_path(rig_path)} is an arm's config: an arm's session time depends on "
            "its moves between the lights, which the trade on an acquisition does not plan. "
            "Give a dome's config, or leave --rig out (the replayed dome's default timing)"
        )
    t, exposure_s = cfg.timing, cfg.camera.exposure_s
    seconds = t.light_switch_s + t.settle_s + exposure_s + t.readout_s + t.transfer_s
    said = (
        f"{shown_path(rig_path)}'s timing.light_switch_s {t.light_switch_s:g} + settle_s "
        f"{t.settle_s:g} + camera.exposure_s {exposure_s:g} + readout_s {t.readout_s:g} + "
        f"transfer_s {t.transfer_s:g}, as a dry run counts a step (the serial link's replies "
        "and the camera's own delays are in it only as far as these keys hold them)"
    )
    held = timed_firmware_seconds(cfg)
    if held is not None and held[0] > seconds:
        return held[0], f"{shown_path(rig_path)}: {held[1]}"
    return seconds, said


def timed_firmware_seconds(cfg: Any) -> tuple[float, str] | None:
    """(seconds a light takes, the words) on a dome whose firmware times its LEDs itself
    (RTIPy: ``T,x,y,secs`` lights an LED for whole seconds and blocks), None for any other.

    Why: the bench summed ``[timing]`` and the exposure (1.17 s a light on
    ``emulated_rtipy.toml``) where a dry run of that config takes about 3.1 s a light: the
    scripted driver writes the light command, the firmware reads it only after its framing
    silence (``frame_silence_s``, 1 s), holds the LED for its window (``window_s``, 2 s) and
    the host waits the window out plus ``TIMED_MARGIN_S`` before the next light
    (``ScriptedDomeDriver.light`` and ``_wait_window``). The figures are the driver's own: the
    profile's description (``protocol_for``, as the dry run's driver is built from it), its
    wire time (10 bits a character at the profile's baud rate) and its margin."""
    from rti_rig.drivers.led_dome.factory import protocol_for
    from rti_rig.drivers.led_dome.scripted import TIMED_MARGIN_S

    serial = cfg.dome.serial if cfg.dome is not None else None
    if serial is None or not serial.is_described:
        return None
    spec = protocol_for(serial)
    if spec.window_s is None or spec.stepping:
        return None
    count = min(spec.led_count, int(cfg.dome.count))
    longest = max(len(spec.render(spec.light.send, i, frozenset({i}))) for i in range(count))
    wire_s = longest * 10.0 / spec.baudrate
    seconds = wire_s + spec.frame_silence_s + spec.window_s + TIMED_MARGIN_S
    said = (
        f"the {spec.name} firmware times each LED itself: its light command on the wire "
        f"{wire_s:.3f} s + its framing silence {spec.frame_silence_s:g} s + the {spec.window_s} s "
        f"it holds the LED lit (light_on_s) + {TIMED_MARGIN_S:g} s margin, as a dry run's "
        "driver waits them; longer than its [timing] and exposure, which fit inside the window"
    )
    return seconds, said


def load_acquisition(lp: Path) -> tuple[np.ndarray, np.ndarray, list[str]]:
    """(grey linear images (N, H, W) float32, directions (N, 3), names) of an acquisition."""
    grey, _, dirs, names = load_acquisition_colour(lp)
    return grey, dirs, names


def load_acquisition_colour(lp: Path) -> tuple[np.ndarray, np.ndarray, np.ndarray, list[str]]:
    """(grey linear images (N, H, W), the linear colour images the fit reads (N, H, W, C),
    directions, names), both shrunk to at most ``MAX_PX`` wide. The colour stack is for the
    choice of fit.rti's order, which `rti-rig fit` makes on colour pixels with the saturated
    ones left out (a grey mean hides a channel at its top code)."""
    from rti_rig.app.usecases.fit_full_scale import recorded_full_scale
    from rti_rig.core.image_files import read_image_any
    from rti_rig.core.lp_format import read_lp

    entries = read_lp(lp, upper_hemisphere=True)
    paths = _image_files(lp, entries)
    # 16-bit files of 12-bit camera data judged against their own white (4095), as the
    # replay and the fit read them: against 65535 a clip at 4095 was no clip to the choice
    # of fit.rti's order
    full = recorded_full_scale(lp.parent, paths, [e.name for e in entries])
    white16 = 65535.0 if full is None else float(full.level)
    images, colour = [], []
    for path in paths:
        img = read_image_any(path)
        x = img.astype(np.float32) / (255.0 if img.dtype == np.uint8 else white16)
        if img.dtype == np.uint8:  # sRGB decoding
            x = np.where(x <= 0.04045, x / 12.92, ((x + 0.055) / 1.055) ** 2.4)
        g = x.mean(axis=-1) if x.ndim == 3 else x
        if g.shape[1] > MAX_PX:
            size = (MAX_PX, max(1, round(g.shape[0] * MAX_PX / g.shape[1])))
            g = cv2.resize(g, size, interpolation=cv2.INTER_AREA)
            # nearest: an area mean would pull a saturated pixel below the top code
            x = cv2.resize(x, size, interpolation=cv2.INTER_NEAREST)
        images.append(g.astype(np.float32))
        colour.append(x.astype(np.float32))
    dirs = np.array([e.direction for e in entries])
    return np.stack(images), np.stack(colour), dirs, [e.name for e in entries]


def _too_few_lights(lp: Path, count: int) -> str | None:
    """What is said of an acquisition of ``count`` lights too few for a trade-off, or None."""
    smallest = MIN_CANDIDATES + MIN_HELD_OUT
    if count >= smallest:
        return None
    return (
        f"{lp}: {count} lights; at least {smallest} are needed for a trade-off "
        f"({MIN_CANDIDATES} to plan from and {MIN_HELD_OUT} held out to score relighting)"
    )


def check_acquisition(lp: Path, notes: list[str] | None = None) -> list[Path]:
    """Refuse ``lp`` by name, as :func:`load_acquisition_colour` and
    :func:`run_tradeoff_from` would, without reading the pixels: for the command to say it
    before it creates its ``--out`` folder (an acquisition of too few lights had been refused
    only once read, leaving an empty ``--out`` behind).

    What the tolerant reader kept of a flawed file (a count line that disagrees, a light a hair
    below the horizon clamped to it) is appended to ``notes`` for the command to say, as
    ``run``, ``check``, ``plan`` and ``fit`` say it: such a file had been measured in silence.
    So are the notes ``run`` and ``fit`` give of its images (PNGs whose alpha or transparency
    key is dropped, 8-bit files mixed with 16-bit ones): they had gone unsaid here.

    Returns the image files, for the command to keep ``--out`` out of their folders."""
    from rti_rig.core.acquisition_images import mixed_depth_note
    from rti_rig.core.errors import RtiRigError
    from rti_rig.core.image_files import png_alpha_note
    from rti_rig.core.lp_format import read_lp
    from rti_rig.runtime.session import refuse_if_in_use

    # a session still being captured: its lights.lp and images are not yet the acquisition
    # (a trade of its first 11 lights had been measured in silence)
    refuse_if_in_use(lp.parent, "measure the trade on it")
    entries = read_lp(lp, upper_hemisphere=True, notes=notes)
    twins = _twin_lights(lp, entries)
    if twins is not None:
        raise RtiRigError(twins)
    files = _image_files(lp, entries)
    if notes is not None:  # what run and fit of it say of its images, said alike here
        names = [e.name for e in entries]
        notes.extend(png_alpha_note(names, files))
        mixed = mixed_depth_note(lp, names, files, "measured")
        if mixed:
            notes.append(mixed)
    too_few = _too_few_lights(lp, len(entries))
    if too_few is not None:
        raise RtiRigError(too_few)
    no_normals = _no_reference_normals(lp, np.array([e.direction for e in entries]))
    if no_normals is not None:
        raise RtiRigError(no_normals)
    return files


def _twin_lights(lp: Path, entries: list[Any]) -> str | None:
    """What is said of an acquisition two of whose lines give one direction (a light re-shot
    and kept, ``IMG_0013`` and ``IMG_0013b``), or None.

    Why: ``run`` and ``check`` of it refuse it, but the trade measured it in silence, and the
    lights held out to score relighting are drawn one by one: a held-out light whose twin
    stayed among the lights planned from was "relit" by a copy of itself, its plan's PSNR
    raised, and the columns no longer compared like with like."""
    from rti_rig.core.lp_format import lights_said
    from rti_rig.core.rig_geometry import COINCIDENT_LED_DEG, coincident_leds

    pair = coincident_leds([e.direction for e in entries])
    if pair is None:
        return None
    return (
        f"{lp}: {lights_said(entries, pair)} share one direction (within "
        f"{COINCIDENT_LED_DEG}°): a trade-off holds lights out to score relighting, and a held-out "
        "light's twin among the lights planned from would relight it by its copy; remove one "
        "of the two lines (its image is then left out) to measure the others"
    )


def _no_reference_normals(lp: Path, dirs: np.ndarray) -> str | None:
    """What is said of an acquisition whose lights cannot determine a surface normal, or None.

    Why: the trade is scored against normals fitted on every light (:func:`reference`); lights
    in one plane (one azimuth, the horizon) or one direction repeated give none, and the
    solver's refusal reached the user as "light set is ill-conditioned ... (from Python,
    ill_conditioned='regularise' fits it regularised)", naming no file and advising what a
    command-line user cannot do. Judged as ``plan``, ``run`` and ``fit`` judge it
    (:func:`~rti_rig.app.normals_determined.undetermined_normals`), before any pixel is read.
    """
    from rti_rig.app.normals_determined import undetermined_normals

    reason = undetermined_normals(dirs, "lights")
    if reason is None:
        return None
    return (
        f"{lp}: {reason}; a trade-off is scored against the normals fitted on every light, so "
        "it needs an acquisition whose lights span several elevations and azimuths"
    )


def _image_files(lp: Path, entries: list[Any]) -> list[Path]:
    """The image file of every line of ``lp``, checked as ``run ACQ/dirs.lp`` checks them
    (found, whole, readable, one size and one kind) before minutes of work.

    Why: only their existence had been checked, so an image of another size was met after
    every image was read, as "all input arrays must have the same shape" naming no file, or
    (larger than ``MAX_PX`` wide) was scaled to the others' width in silence and measured."""
    from rti_rig.core.acquisition_images import check_acquisition_images

    return check_acquisition_images(
        lp, entries, use="measure", pixels="that rti-rig cannot read"
    ).paths


def held_out_lights(dirs: np.ndarray, seed: int = 0) -> np.ndarray:
    """Sorted indices of the lights held out to score every plan's relighting on.

    The acquisition's lights sorted by elevation are cut into as many bands of (nearly) equal
    count as lights are held out, and one light is drawn in each (seeded: the same set on
    every run): the held-out set follows the acquisition's own spread over elevation (a dome
    denser near the horizon is scored there as densely) without the azimuth pattern a fixed
    stride would pick from every ring alike."""
    k = len(dirs)
    count = max(MIN_HELD_OUT, round(k * HELD_OUT_SHARE))
    order = np.argsort(np.asarray(dirs)[:, 2], kind="stable")
    edges = np.linspace(0, k, count + 1).round().astype(int)
    rng = np.random.default_rng(seed)
    return np.sort([int(order[rng.integers(a, b)]) for a, b in pairwise(edges)])


def run_tradeoff_from(
    lp: Path, progress: Callable[[str], None] = print
) -> tuple[list[Row], list[str]]:
    """Rows (one per plan and N, and the row ``all``: every light not held out) for the
    acquisition ``lp``, and the names of the held-out lights; see the module docstring."""
    from benchmarks.planner_real_data import (
        evaluate_scores,
        planned_leds,
        reference,
        written_rti_psnr,
    )
    from rti_rig.app.usecases.adaptive import AdaptiveChooser, dome_start
    from rti_rig.core.errors import ScheduleError
    from rti_rig.core.rig_geometry import DomeGeometry
    from rti_rig.planner.adaptive import START_LIGHTS
    from rti_rig.planner.objectives import models_for
    from rti_rig.planner.uniform import select_uniform_leds

    images, colour, dirs, names = load_acquisition_colour(Path(lp))
    too_few = _too_few_lights(lp, len(dirs))
    if too_few is not None:  # the command says it first (check_acquisition): for other callers
        raise ValueError(too_few)
    held = held_out_lights(dirs)
    keep = np.setdiff1d(np.arange(len(dirs)), held)  # what every plan chooses among
    dome = DomeGeometry(dirs[keep], tuple(names[i] for i in keep))
    ref, mask = reference(images, dirs)
    counts = [n for n in COUNTS if n < len(keep)]
    name = f"{Path(lp).parent.name}/{Path(lp).name}"

    def adaptive_run(n: int, objective: str) -> tuple[list[int], float]:
        """`run --adaptive --lights n [--objective relight]` on the recorded images: its lights
        (indices into ``keep``) and the mean time of a decision (with N known the design is
        chosen for N, so each N is its own session)."""
        sub = dirs[keep]
        chooser = AdaptiveChooser(
            sub,
            dome_start(dome, START_LIGHTS, n, objective),
            n,
            design_lights=n,
            objective=objective,
        )
        t0 = time.perf_counter()
        for i in range(n):
            c, _ = chooser.decide(i)
            if c is None:
                break
            chooser.observe(c, sub[c], images[keep[c]])
        return chooser.used, (time.perf_counter() - t0) / max(1, n - START_LIGHTS)

    rows: list[Row] = []

    def add(
        method: str, floor: float, n: int, leds: np.ndarray, plan_s: float, objective: str
    ) -> None:
        """One row; ``leds`` index ``keep`` (the lights not held out)."""
        chosen = keep[np.asarray(leds, dtype=int)]
        model = models_for(n)[-1]  # the richest basis n lights determine, as benchmarks.adaptive
        sc = evaluate_scores(chosen, images, dirs, ref, mask, model, held=held)
        # what the user would open: fit.rti as `rti-rig fit` (--model auto) writes it
        file_model, file_psnr = written_rti_psnr(
            images[chosen], dirs[chosen], images[held], dirs[held], mask, chosen_on=colour[chosen]
        )
        t = n * PER_LIGHT_S
        rows.append(
            Row(
                name,
                method,
                objective,
                n,
                floor,
                sc.normal_mean_deg,
                sc.normal_median_deg,
                float(mask.mean()),
                model,
                sc.relight_psnr_db,
                sc.relight_ssim,
                t,
                float("nan"),
                plan_s,
                file_model,
                file_psnr,
                # which images the layout took, for a user to look at or replay (run --plan)
                " ".join(str(int(i) + 1) for i in chosen),
            )
        )

    for n in counts:
        for f in FLOORS:
            try:
                leds = select_uniform_leds(dome, n, f)
            except ScheduleError:  # fewer LEDs above this floor than N: no such layout
                continue
            add("uniform", f, n, leds, 0.0, "normals")
        t1 = time.perf_counter()
        opt = planned_leds(None, dome, n, None)
        add("optimal", 0.0, n, opt, time.perf_counter() - t1, "normals")
        for objective in ("normals", "relight"):
            used, adaptive_s = adaptive_run(n, objective)
            add("adaptive", 0.0, n, np.array(used), adaptive_s, objective)
        progress(f"{name}: N = {n} done")
    # every light not held out, fitted with the model its count gets (a reference, not a bound)
    add("all", 0.0, len(keep), np.arange(len(keep)), 0.0, "normals")
    return rows, [names[i] for i in held]


#: The mean normal errors (degrees, against every light's normals) the advice finds the
#: fewest lights for; and the relighting targets: dB below the fit.rti of every light.
NORMAL_TARGETS_DEG = (1.0, 2.0, 3.0)
RELIGHT_TARGETS_DB = (0.5, 1.0, 2.0)


@dataclass(frozen=True)
class Targets:
    """What the advice finds the fewest lights for: mean normal errors (degrees) and
    relighting losses (dB below every light's fit.rti). Why options: the fixed 1°/2°/3° and
    0.5/1/2 dB are not every lab's; a collection's own tolerance is what the trade is run to
    answer."""

    normals_deg: tuple[float, ...] = NORMAL_TARGETS_DEG
    relight_db: tuple[float, ...] = RELIGHT_TARGETS_DB

    def options(self) -> str:
        """The command-line options that give these targets ('' for the defaults)."""
        said = ""
        if self.normals_deg != NORMAL_TARGETS_DEG:
            said += "".join(f" --target-deg {t:.10g}" for t in self.normals_deg)
        if self.relight_db != RELIGHT_TARGETS_DB:
            said += "".join(f" --target-db {t:.10g}" for t in self.relight_db)
        return said


def checked_targets(degrees: Sequence[float], decibels: Sequence[float]) -> Targets:
    """The targets given (each list sorted, repeats dropped; the default where none is given),
    or a refusal naming the option: a normal error is above 0° and below 90°, a relighting
    loss above 0 dB (a target of 0 is met by every light alone, NaN by none)."""
    for value in degrees:
        if not 0.0 < value < 90.0:  # NaN fails both
            raise RtiRigError(
                f"--target-deg {value:g}: a mean normal error target is above 0 and below 90 "
                "degrees (e.g. --target-deg 1.5)"
            )
    for value in decibels:
        if not 0.0 < value < 100.0:
            raise RtiRigError(
                f"--target-db {value:g}: a relighting target is the dB below every light's "
                "fit.rti a file may lose: above 0 and below 100 (e.g. --target-db 0.5)"
            )
    return Targets(
        tuple(sorted(set(degrees))) or NORMAL_TARGETS_DEG,
        tuple(sorted(set(decibels))) or RELIGHT_TARGETS_DB,
    )


#: The advice's planners: the summary's column keys, how a user says each, and the command
#: that shoots N lights so (``{rig}``, ``{n}``, ``{floor}`` filled in).
_PLANNERS = (
    (("uniform", "normals", 0.0), "uniform", "rti-rig run {rig} --out SESSION --lights {n}"),
    (
        ("uniform", "normals", None),
        "uniform above {floor:g}° (the floor that did best on this acquisition)",
        "rti-rig run {rig} --out SESSION --lights {n} --min-elevation-deg {floor:g}",
    ),
    (
        ("optimal", "normals", 0.0),
        "optimal",
        # as the table measured it: no preview (a level surface)
        "rti-rig plan --rig {rig} --method optimal --lights {n} --out plan.lp` then "
        "`rti-rig run {rig} --out SESSION --plan plan.lp",
    ),
    (
        ("adaptive", "normals", 0.0),
        "adaptive",
        "rti-rig run {rig} --out SESSION --adaptive --lights {n}",
    ),
    (
        ("adaptive", "relight", 0.0),
        "adaptive for relighting",
        "rti-rig run {rig} --out SESSION --adaptive --objective relight --lights {n}",
    ),
)


def _fewest(series: dict[int, Row], meets: Callable[[Row], bool]) -> int | None:
    """The smallest N from which this planner meets the target at every larger N it has a
    layout for (None: not at its largest). Why "from which": one layout per cell moves by
    luck, and an N that meets the target only between two that do not is not one to rely on.
    A high floor has no layout of the largest N (too few lights above it): its own largest
    counts."""
    found = None
    for n in sorted(series, reverse=True):
        if not meets(series[n]):
            break
        found = n
    return found


def how_many_lights(
    rows: list[Row],
    floor: float,
    per_light_s: float,
    rig: str = "RIG",
    targets: Targets | None = None,
    rig_lights: int | None = None,
) -> list[str]:
    """The summary's answer to what it is run for: for each target (mean normal error, and
    relighting of the fit.rti `rti-rig fit` writes, below every light's), the fewest lights
    each planner needs, the fastest of them with its session time, and the command.
    ``targets``: the lab's own (``--target-deg``/``--target-db``); the defaults without.
    ``rig_lights``: the LEDs of ``--rig``'s dome: a count above them gets no command (the
    rig would refuse it), and says so.

    Why: the tables gave 5 planners × 7 counts of cells and left a conservator to read the
    answer out of them (QA, 2026-12-05)."""
    targets = targets or Targets()
    counts = sorted({r.n for r in rows if r.method != "all"})
    every = next(r for r in rows if r.method == "all")
    by = {(r.method, r.objective, r.floor_deg, r.n): r for r in rows}
    planners = []
    for (method, objective, at), said, command in _PLANNERS:
        f = floor if at is None else at
        if at is None and floor == 0.0:
            continue  # the best floor is 0°: the plain uniform column already
        series = {
            n: by[(method, objective, f, n)] for n in counts if (method, objective, f, n) in by
        }
        planners.append((said.format(floor=f), command.replace("{floor:g}", f"{f:g}"), series))

    def line(target: str, meets: Callable[[Row], bool]) -> str:
        reached = [
            (n, said, cmd, series)
            for said, cmd, series in planners
            if (n := _fewest(series, meets)) is not None
        ]
        found = [(n, said, cmd) for n, said, cmd, _ in reached]
        if not found:
            return (
                f"- **{target}**: no planner reaches it up to {counts[-1]} lights of this "
                f"acquisition (every light's own: {every.n})"
            )
        fastest = min(n for n, _, _ in found)
        row = next(series[n] for n, _, _, series in reached if n == fastest)
        # an adaptive session also decides before each light (the row's mean decision time)
        seconds = fastest * (per_light_s + (row.plan_s if row.method == "adaptive" else 0.0))
        each = "; ".join(f"{said} {n}" for n, said, _ in sorted(found))
        best = [(said, cmd) for n, said, cmd in found if n == fastest]
        missing = [said for said, _, series in planners if all(said != s for _, s, _ in found)]
        how = best[0][1].format(rig=rig, n=fastest)
        fewest = " (the fewest the table tries: fewer may do)" if fastest == counts[0] else ""
        if rig_lights is not None and fastest > rig_lights:
            out = (
                f"- **{target}**: from **{fastest} lights**{fewest} of this acquisition, more "
                f"than the {rig_lights} LEDs of {rig}: no session on it reaches this target "
                f"as this acquisition's lights do. Each planner: {each}"
            )
        else:
            out = (
                f"- **{target}**: from **{fastest} lights**{fewest}, {seconds:.0f} s a "
                f"session, with {best[0][0]}: `{how}`. Each planner: {each}"
            )
        if missing:
            out += f"; not reached by {', '.join(missing)} (up to its most lights here)"
        return out + "."

    lines = [
        "## How many lights this object needs",
        "",
        "Read from the tables below: a planner's count is the fewest lights from which it "
        "meets the target at every larger count of the table too (one layout per cell moves "
        "by luck). Normals: the mean error against every light's normals; relighting: the "
        "fit.rti `rti-rig fit` writes, on the held-out lights, against that of every light "
        f"({every.file_psnr_db:.1f} dB). Session time: the lights at the step below, and an "
        "adaptive session's decisions.",
        "",
    ]
    if rig_lights is not None and rig_lights < max(counts[-1], every.n):
        lines[-1:-1] = [
            "",
            f"{rig} has {rig_lights} LEDs, fewer than this acquisition's lights: the counts "
            "below are measured on the acquisition's, and hold for your dome only as far as "
            "its LEDs light the object as these did; no command is given for more lights "
            "than it has.",
        ]
    for target in targets.normals_deg:
        lines.append(
            line(f"Normals within {target:.10g}°", lambda r, t=target: r.normal_mean_deg <= t)
        )
    if np.isfinite(every.file_psnr_db):
        for target in targets.relight_db:
            lines.append(
                line(
                    f"Relighting within {target:.10g} dB",
                    lambda r, t=target: bool(
                        r.file_model and r.file_psnr_db >= every.file_psnr_db - t
                    ),
                )
            )
    return [*lines, ""]


def summarise_from(
    rows: list[Row],
    seconds: float,
    command: str,
    held: list[str],
    per_light: tuple[float, str] = (PER_LIGHT_S, PER_LIGHT_SAID),
    rig_word: str = "RIG",
    targets: Targets | None = None,
    rig_lights: int | None = None,
) -> str:
    """The markdown summary; ``held``: the names of the held-out lights; ``per_light``: the
    seconds a light takes and where they come from; ``rig_word``: the rig config as the
    advice's commands name it (``--rig``'s, shell-quoted; ``RIG`` without one);
    ``rig_lights``: the LEDs of ``--rig``'s dome (None: no ``--rig``)."""
    per_light_s, per_light_said = per_light
    floor = best_floor(rows, rows[0].scene)  # as the plots' line: on the N every floor serves
    by = {(r.method, r.objective, r.floor_deg, r.n): r for r in rows}
    counts = sorted({r.n for r in rows if r.method != "all"})
    every = next(r for r in rows if r.method == "all")
    lines = [
        f"# The trade on {rows[0].scene}",
        "",
        f"Command: `{command}` ({seconds:.0f} s). Normals: against robust photometric stereo on "
        "every light of the acquisition (on its well-lit pixels). Relighting: PSNR on the same "
        f"{len(held)} held-out lights for every plan ({', '.join(held)}: one drawn in each of "
        f"{len(held)} elevation bands of equal count), which no plan may take; every plan "
        f"chooses among the other {every.n}. Session time: "
        f"{per_light_s:.2f} s a light ({per_light_said}).",
        "",
        *how_many_lights(rows, floor, per_light_s, rig_word, targets, rig_lights),
        "| N | session s | uniform 0° | uniform, best floor here "
        f"({floor:g}°, hindsight) | optimal | adaptive | adaptive, `--objective relight` |",
        "|---|---|---|---|---|---|---|",
    ]
    for n in counts:
        cells = _columns(by, floor, n)
        lines.append(
            f"| {n} | {n * per_light_s:.0f} | "
            + " | ".join(
                f"{r.normal_mean_deg:.2f}° / {r.relight_psnr_db:.1f} dB ({r.relight_model})"
                if r is not None
                else _NO_LAYOUT.format(floor=floor)
                for r in cells
            )
            + " |"
        )
    lines += [
        f"| all {every.n} | {every.n * per_light_s:.0f} | "
        f"{every.normal_mean_deg:.2f}° / {every.relight_psnr_db:.1f} dB "
        f"({every.relight_model}): every light not held out | | | | |",
        "",
        "Cells: mean normal error against the all-light reference / relighting PSNR on the "
        "held-out lights, fitted with the richest basis the planner gives N lights (in "
        "brackets: HSH1 from 6, PTM from 9, HSH2 from 14, HSH3 from 24; the basis changes with "
        "N, so PSNR need not rise at every step). One acquisition, one layout per cell: "
        "differences of a few tenths of a degree or dB between layouts are within what one "
        "layout's luck moves (docs/research/planner.md); read the trend with N, not single cells.",
        "",
        "**Relighting as `rti-rig fit` writes it**: the PSNR on the same held-out lights of the "
        "fit.rti that `rti-rig fit` (`--model auto`) would write for each layout — its HSH "
        "order (in brackets) chosen on the layout's own images by held-out evidence, as the "
        "fit chooses it — what a user opens in a viewer, where the table above fixes one "
        "basis per N to compare layouts.",
        "",
        "| N | uniform 0° | uniform, best floor here | optimal | adaptive | adaptive, "
        "`--objective relight` |",
        "|---|---|---|---|---|---|",
    ]
    for n in counts:
        cells = _columns(by, floor, n)
        lines.append(
            f"| {n} | "
            + " | ".join(
                _file_cell(r) if r is not None else _NO_LAYOUT.format(floor=floor) for r in cells
            )
            + " |"
        )
    lines.append(f"| all {every.n} | {_file_cell(every)} | | | | |")
    return "\n".join(lines)


#: the cell of a floor with fewer lights above it than N (a high floor on a small dome)
_NO_LAYOUT = "no layout: too few lights above {floor:g}°"


def _columns(by: dict, floor: float, n: int) -> list[Row | None]:  # type: ignore[type-arg]
    """The rows of one N in the summary's column order (both tables); None where the best
    floor has too few lights above it for N (it is chosen on the N every floor serves)."""
    keys = [
        ("uniform", "normals", 0.0),
        ("uniform", "normals", floor),
        ("optimal", "normals", 0.0),
        ("adaptive", "normals", 0.0),
        ("adaptive", "relight", 0.0),
    ]
    return [by.get((*k, n)) for k in keys]


def _file_cell(r: Row) -> str:
    """``23.7 dB (hsh1)``, or why there is no fit.rti."""
    if not r.file_model:
        return "no fit.rti"
    return f"{r.file_psnr_db:.1f} dB ({r.file_model})"


def bench_from(
    lp: Path,
    out_dir: Path | None,
    progress: Callable[[str], None] = print,
    force: bool = False,
    rig: Path | None = None,
    per_light: tuple[float, str] | None = None,
    targets: Targets | None = None,
    rig_lights: int | None = None,
) -> str:
    """Run, write results.csv, the plots and summary.md into ``out_dir`` (nothing written when
    it is None: the summary is only returned); return the summary (its command line says
    ``--force`` when the folder's files were replaced with it). ``rig``: the user's dome
    config, whose timing gives the session time (:func:`rig_facts`); else the
    replayed dome's defaults. ``per_light``: that time, when the caller has already read it
    from ``rig`` (the CLI reads the config before minutes of computing; read again here, a
    config edited in between would time the trade by another config than the one checked);
    ``rig_lights``: its LED count, read with it (:func:`rig_facts`)."""
    if per_light is None:
        if rig is None:
            per_light = (PER_LIGHT_S, PER_LIGHT_SAID)
        else:
            per_light, rig_lights = rig_facts(rig)
    if rig is None and shot_on_an_arm(lp):
        per_light = (per_light[0], per_light[1] + ARM_TIMES_SAID)
    t0 = time.perf_counter()
    rows, held = run_tradeoff_from(lp, progress)
    for row in rows:
        row.dome_time_s = row.n * per_light[0]
    # quoted as a shell reads it: an archive's folder with a space (``Tablet 3/dirs.lp``) had
    # been written bare, a command that fails when copied from summary.md; shell_word, not
    # shlex.quote: a name whose bytes are not UTF-8 is said as $'...' of those bytes (quoted,
    # it was a '\udce9' no shell reads back, and summary.md's UTF-8 write failed on it)
    command = f"rti-rig bench tradeoff --from {shell_word(lp)}"
    if rig is not None:
        command += f" --rig {shell_word(rig)}"
    targets = targets or Targets()
    command += targets.options()
    rig_word = advice_rig(lp, rig)
    if out_dir is None:
        return summarise_from(
            rows, time.perf_counter() - t0, command, held, per_light, rig_word, targets, rig_lights
        )
    out_dir.mkdir(parents=True, exist_ok=True)
    write_csv(rows, out_dir / "results.csv")
    for path in plot(rows, out_dir):
        if "arm_time" in path.name:  # a replayed acquisition is a dome: no arm time to plot
            path.unlink()
    command += f" --out {shell_word(out_dir)}" + (" --force" if force else "")
    text = summarise_from(
        rows, time.perf_counter() - t0, command, held, per_light, rig_word, targets, rig_lights
    )
    (out_dir / "summary.md").write_text(text + "\n", encoding="utf-8")
    return text
