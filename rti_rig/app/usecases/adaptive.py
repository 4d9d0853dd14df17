"""Adaptive acquisition (`rti-rig run RIG --adaptive --lights N` / `--until-error DEG`).

Design: the controller runs the session as it runs any schedule, but asks a *step source*
(:class:`rti_rig.runtime.controller.StepSource`) for each next step; this module's
:class:`AdaptiveSteps` is that source. It keeps a small grey copy of every image captured,
fits normals and albedo to them with the project's robust photometric stereo
(:mod:`rti_rig.reconstruct`), and passes what is known of the surface to the pure chooser
(:mod:`rti_rig.planner.adaptive`), which picks the next light among what the rig can do (a
dome's LEDs; an arm's reachable set, move time counted). Why a step source rather than
one-step schedules run back to back: one session, one manifest and journal, one teardown and one
set of signal rules (Ctrl-C, SIGTERM, pause) whatever decides the steps, and the fixed path
is unchanged (no source: the schedule's steps).

Decisions are data: each step's decision and its evidence (estimated error now and predicted
after, the best candidates, the time each took) go into the journal line and the manifest's
steps; the settings into the manifest's ``adaptive`` table. A decision depends only on the
images before it, so ``--resume`` re-reads the linear TIFFs on disk and continues exactly as the
uninterrupted session would have.
"""

from __future__ import annotations

import time
import warnings
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass, replace
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import cv2
import numpy as np
from numpy.typing import NDArray

from rti_rig.app.usecases import fit_rti_order
from rti_rig.app.usecases.adaptive_constants import (
    constant_differences,
    decision_constants,
    describe_differences,
)
from rti_rig.app.usecases.adaptive_recorded import refuse_damaged_settings
from rti_rig.app.usecases.run_options import (
    HINT_UNTIL_ERROR_DEG,
    adaptive_options,
    band_options,
    run_words,
)
from rti_rig.core import fit_minimums
from rti_rig.core.arm_motion import move_time_s
from rti_rig.core.devices import Frame
from rti_rig.core.errors import RtiRigError
from rti_rig.core.geometry import angle_between_deg, az_el_from_direction
from rti_rig.core.image_files import linear_tiff_white_level, read_linear_tiff
from rti_rig.core.rig_geometry import ArmGeometry, DomeGeometry, LampGeometry, in_band
from rti_rig.core.schedule import LightSchedule, LightStep
from rti_rig.core.shell_words import shell_word, shown_path
from rti_rig.planner import adaptive_until
from rti_rig.planner.adaptive import (
    ESTIMATE_SCALE,
    SIM_ESTIMATE_SCALE,
    START_FLOOR_DEG,
    START_LIGHTS,
    SurfaceState,
    choose_in_design,
    choose_next,
    estimate_error_deg,
    object_model,
    start_subset,
)
from rti_rig.planner.adaptive_bias import NearLamps, simulate_error_deg
from rti_rig.planner.adaptive_relight import OBJECTIVES
from rti_rig.planner.adaptive_until import (
    choose_until,
    misfit_decides,
    misfit_deg,
    reaches_target,
    unsolved_fraction,
    upper_error_deg,
)
from rti_rig.planner.objectives import ARM_CANDIDATES, candidates_for, snap_unique
from rti_rig.planner.uniform import band_run_options, select_uniform_leds
from rti_rig.runtime.session import labelled_white

#: Width (px) of the grey copies the decisions are fitted on (a 24-MP image is shrunk once).
FIT_PX = 128
#: Pixels sampled from the fit for the chooser.
SAMPLE = 2000
#: Noise floor of one observation relative to the stack's bright level (quantisation, sensor).
NOISE_FLOOR = 0.003
#: An observation is explained by the fit within max(k × the pixel's RMS residual, a floor
#: relative to the stack's bright level); beyond it, a highlight or a cast shadow.
OUTLIER_K = 3.0
OUTLIER_FLOOR = 0.02
#: An adaptive run that gives only --until-error on an arm stops at this many lights at most.
ARM_MAX_LIGHTS = 100
#: 4: the design objective (``normals``/``relight``) in the settings and every decision;
#: 5: the fitted design (``planner.adaptive_optimal``) offered beside the floors, a decision
#: that takes it recording ``"design": "fitted"`` (a /4 session's choices would differ: its
#: resume is refused, before anything on disk changes); 7: with only --until-error, each light
#: chosen within the design for a guessed N that grows (``planner.adaptive_until``), recorded
#: as ``guessed_lights`` with the design's floor and scores (a /5 session chose by the bound);
#: the fitted relight design (``planner.adaptive_relight_design``) offered to
#: ``--objective relight`` beside the floors, its simulated PSNR recorded as
#: ``design_psnr_db["fitted"]`` and a decision that takes it recording ``"design": "fitted"``
#: (a /5 relight session's choices would differ); a design's reason giving the estimate
#: beside the simulated error. (6 was written by development builds that had only some of
#: these changes: refused like any other.) 8: the object model the designs are simulated on
#: solves the pixels the robust fit left unsolved by least squares where three lit lights
#: determine them, and counts them as evidence for its lobe, shadows and noise
#: (``planner.adaptive_bias.solve_unsolved``): a /7 session on a tilted object could have
#: chosen on a level-plane model; the stop claims --until-error only when the *upper*
#: estimate (the point estimate × ``planner.adaptive_until.UPPER_FACTOR``) is under it, and
#: every decision, the stop and the result record both estimates and the factor
#: (``upper_error_deg``, ``upper_factor``; a /7 session stopped on the point estimate); the
#: settings record every decision constant (``constants``, checked on resume), and a relight
#: design with no light left out records a null PSNR. 9: with N known and ``--objective
#: relight``, the starting lights are matched only among the default layout's lights at or
#: above ``START_FLOOR_DEG`` (``planner.adaptive.START_ABOVE_FLOOR``, ``start_subset``; a /8
#: relight session could start on a light below 20°), and the relight score clips the object
#: model's renderings at white and judges every design on the same held-out lights
#: (``planner.adaptive_relight.SATURATION``, ``SHARED_HELD_OUT``): a resume of a /8 relight
#: session would shoot other lights. (A development build of 2026-11-25 wrote /9 with the new
#: start but not the new score: its sessions lack those two constants and are refused by the
#: constants check.)
FORMAT = "rti-rig-adaptive/9"
#: Format 9 with ``--min-lights``: the same decisions, a stop held until the minimum. Its own
#: label so that a build that does not know the minimum refuses the session by name instead of
#: resuming it without (and claiming the target at 4 lights). This build continues both.
FORMAT_MIN_LIGHTS = "rti-rig-adaptive/9+min-lights"
#: Whether designs (``--lights N``) are scored by a robust fit simulated on this object's
#: model (gloss, cast shadows, noise: ``planner.adaptive_bias``) rather than the variance bound.
BIAS_AWARE = True
#: With only --until-error (N unknown): choose within the design for a guessed N that grows
#: (``planner.adaptive_until``; format 7) rather than the bound's best light one at a time.
UNTIL_DESIGN = True


def small_grey(pixels: NDArray, white_level: float = 65535.0) -> NDArray[np.float32]:
    """A frame shrunk to :data:`FIT_PX` wide (area average), grey, in units of white."""
    px = np.asarray(pixels)
    h, w = px.shape[:2]
    step = w // (4 * FIT_PX)
    if step > 1:  # a 24-MP frame: every step-th pixel first (an area average of 16 at the end)
        px = np.ascontiguousarray(px[::step, ::step])
        h, w = px.shape[:2]
    if w > FIT_PX:
        size = (FIT_PX, max(1, round(h * FIT_PX / w)))
        px = cv2.resize(px, size, interpolation=cv2.INTER_AREA)
    g = px.astype(np.float32)
    if g.ndim == 3:
        g = g.mean(axis=2)
    return g / np.float32(white_level)


@contextmanager
def _decision_fit() -> Iterator[None]:
    """The chooser's own fits on the images so far, their trust warnings silenced.

    Why: each decision fits a small sample of the first few lights, which is ill-conditioned
    by nature (4 lights of a narrow band always are): ``run --adaptive --max-elevation-deg
    10`` on the simulated arm printed a raw ``IllConditionedFitWarning`` with this module's
    path three times per image. Those fits only rank the next light; what the finished
    light set is worth is judged by the QA verdict and by ``rti-rig fit``, which say it."""
    from rti_rig.reconstruct.errors import FitTrustWarning

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", FitTrustWarning)
        yield


def fit_state(images: NDArray[np.float32], lights: NDArray[np.float64]) -> SurfaceState | None:
    """What the images so far say of the surface, for the chooser (None: not yet solvable).

    Robust photometric stereo on the small grey stack; a fixed pixel sample (same pixels every
    time, so decisions are deterministic). Pixels the fit cannot solve yet (fewer than three
    lights reach them) are kept with a level normal and their brightest observation as albedo:
    they are where the next light is most needed.
    """
    if len(lights) < 3:
        return None
    return fit_sample(sample_pixels(images), lights)


def sample_pixels(images: NDArray) -> NDArray[np.float32]:
    """The chooser's pixel sample of each image (K, P) — the same pixels every time (a decision
    is a function of the images), so a session samples each image once, as it arrives."""
    flat = np.asarray(images, dtype=np.float32)
    flat = flat.reshape(flat.shape[0], -1)
    return np.ascontiguousarray(flat[:, sample_index(flat.shape[1])])


def camera_sample(pixels: NDArray, white_level: float = 65535.0) -> NDArray[np.float32]:
    """The chooser's pixel sample (:func:`sample_index`) of a whole frame at the camera's
    resolution, grey, in units of white: what the stop's unsolved share and misfit bound are
    taken on (``planner.adaptive_until.misfit_deg``). Why not the small image's: an area average to
    :data:`FIT_PX` lights a shadowed pit with its lit rim, so a pixel a user's fit cannot solve
    (or solves from a penumbra) looked solved and clean there — on the shipped arm under a 15°
    ceiling 1.1 % of the camera's pixels were unsolved at 12 lights against 0.3 % of the small
    image's. Indexing only the sampled pixels costs nothing on a 24-MP frame."""
    px = np.asarray(pixels)
    h, w = px.shape[:2]
    rows, cols = np.unravel_index(sample_index(h * w), (h, w))
    picked = px[rows, cols].astype(np.float32)  # (P,) or (P, C): no copy of the frame
    grey = picked.mean(axis=1) if picked.ndim == 2 else picked
    return grey / np.float32(white_level)


def sample_index(pixels: int) -> NDArray[np.intp]:
    """The flat indices of the chooser's pixel sample in an image of ``pixels`` pixels."""
    rng = np.random.default_rng(0)
    return np.sort(rng.choice(pixels, min(SAMPLE, pixels), replace=False))


def relief_px(images: NDArray, lights: NDArray[np.float64]) -> NDArray[np.float64] | None:
    """The object's relief (height in pixels) from the small grey images so far: the robust
    fit's normals on every pixel, integrated (Frankot–Chellappa) — what cast shadows from
    lights not tried yet are marched over (``planner.adaptive_bias``). None: not solvable."""
    from rti_rig.planner.topography import _frankot_chellappa
    from rti_rig.reconstruct import ReconstructionError, fit_photometric_stereo

    try:
        # least squares: the relief only places cast shadows, and it is 10× cheaper on every pixel
        with _decision_fit():
            ps = fit_photometric_stereo(np.asarray(images, dtype=np.float32), lights, robust=False)
    except ReconstructionError:
        return None
    n = np.where(ps.valid[..., None], ps.normals, np.float32([0.0, 0.0, 1.0])).astype(np.float64)
    nz = np.maximum(n[..., 2], 0.2)  # slopes of at most ~78°
    p, q = -n[..., 0] / nz, -n[..., 1] / nz
    # the mean slope (a tilted object) integrated apart: the FFT integration is periodic
    mp, mq = float(p.mean()), float(q.mean())
    rows, cols = np.indices(p.shape)
    return _frankot_chellappa(p - mp, q - mq) + mp * cols - mq * rows


def fit_sample(
    obs: NDArray[np.float32],
    lights: NDArray[np.float64],
    where: tuple[NDArray[np.intp], NDArray[np.intp]] | None = None,
    height: NDArray[np.float64] | None = None,
) -> SurfaceState | None:
    """:func:`fit_state` on the pixel sample (K, P) of the images so far (``where``: the
    sample's rows and columns in the image whose relief is ``height``, if known)."""
    from rti_rig.reconstruct import ReconstructionError, fit_photometric_stereo

    k = len(lights)
    if k < 3:
        return None
    try:
        with _decision_fit():
            ps = fit_photometric_stereo(obs[:, None, :], lights, robust=True)
    except ReconstructionError:
        return None
    seen = obs.max(axis=0) > ps.dark_threshold  # not dark under every light so far
    if not seen.any():
        return None
    obs = obs[:, seen]
    valid = ps.valid.ravel()[seen]
    normals = ps.normals.reshape(-1, 3)[seen].astype(np.float64)
    normals[~valid] = (0.0, 0.0, 1.0)
    albedo = ps.albedo.reshape(-1)[seen].astype(np.float64)
    albedo = np.where(valid, albedo, obs.max(axis=0))
    resid = ps.residual.ravel()[seen].astype(np.float64)
    ref = float(np.percentile(obs, 99)) or 1.0
    dof = max(k - 3, 1)
    noise = np.sqrt((NOISE_FLOOR * ref) ** 2 + resid**2 * k / dof)
    # kept: lit (above the dark threshold) and explained by the fit — a highlight above it, or a
    # cast shadow below it, by more than the fit's own outlier rule, is what the chooser must
    # expect again from lights near that one (planner.adaptive.predicted_weight)
    g = (ps.normals.reshape(-1, 3)[seen] @ np.asarray(lights, dtype=np.float32).T).T  # (K, P)
    pred = np.maximum(g, 0.0) * ps.albedo.reshape(-1)[seen]
    tol = np.maximum(OUTLIER_K * resid, OUTLIER_FLOOR * ref)
    explained = np.abs(obs - pred) <= tol
    lit = ((obs > ps.dark_threshold) & (explained | ~valid)).T
    return SurfaceState(
        normals,
        albedo,
        noise,
        lit,
        np.asarray(lights, dtype=np.float64),
        obs=obs,
        valid=valid,
        dark=float(ps.dark_threshold),
        noise_floor=NOISE_FLOOR * ref,
        rows=None if where is None else where[0][seen],
        cols=None if where is None else where[1][seen],
        height=height,
        residual=resid,
        used=ps.used_lights.ravel()[seen].astype(np.int64),
    )


def warm_up_fit() -> None:
    """Load (the first time on a machine: compile) the robust fit's kernel before the session
    begins, so that its first decision does not stall between two lights."""
    from rti_rig.reconstruct.robust_ps import warm_up

    warm_up()


def robust_fit(
    obs: NDArray[np.float32], lights: NDArray[np.float64]
) -> tuple[NDArray, NDArray] | None:
    """The robust fit the benchmarks score, on an (L, P) sample: normals (P, 3), valid (P,) —
    what the bias-aware design score (``planner.adaptive_bias``) runs on simulated images;
    None when the fit refuses the light set (only that: any other error propagates)."""
    from rti_rig.reconstruct import ReconstructionError, fit_photometric_stereo

    try:
        with _decision_fit():
            ps = fit_photometric_stereo(obs[:, None, :], lights, robust=True)
    except ReconstructionError:
        return None
    return ps.normals.reshape(-1, 3), ps.valid.ravel()


def relight_fit(
    obs: NDArray[np.float32], lights: NDArray[np.float64], held: NDArray[np.float64], basis: str
) -> NDArray | None:
    """The relighting fit the benchmarks score (``fit_hsh``/``fit_ptm``, as
    ``benchmarks.planner_real_data.relight_model`` fits it) on an (L, P) sample, relit to the
    held-out lights (T, 3) and clamped at 0 as the models relight: (T, P) — what the relight
    design score (``planner.adaptive_relight``) runs on simulated images; None when the fit
    refuses the light set."""
    from rti_rig.core.rti_bases import design_matrix
    from rti_rig.reconstruct import ReconstructionError, fit_hsh, fit_lambert, fit_ptm

    stack = np.asarray(obs, dtype=np.float32)[:, None, :]
    try:
        with warnings.catch_warnings():  # a ridge-regularised fit is scored as it is
            warnings.simplefilter("ignore")
            if basis == "ptm":
                model = fit_ptm(stack, lights)
            elif basis.startswith("hsh"):
                model = fit_hsh(stack, lights, int(basis[-1]))
            else:
                model = fit_lambert(stack, lights, ill_conditioned="regularise")
    except ReconstructionError:
        return None
    coef = model.coefficients.reshape(model.n_coefficients, -1).astype(np.float64)
    return np.maximum(design_matrix(basis, held) @ coef, 0.0)


MoveTimes = Callable[[NDArray[np.float64] | None], NDArray[np.float64] | None]


class AdaptiveChooser:
    """The decision loop, independent of the controller (the benchmarks drive it directly).

    ``candidates`` (C, 3): the lights the rig can give; ``start``: candidate indices of the
    starting layout; ``move_times(current direction) -> (C,)`` seconds, or None for a dome.
    """

    def __init__(
        self,
        candidates: NDArray[np.float64],
        start: list[int],
        max_lights: int,
        until_error_deg: float | None = None,
        capture_s: float = 1.0,
        move_times: MoveTimes | None = None,
        scale: float | None = None,
        design_lights: int | None = None,
        bias_aware: bool | None = None,
        objective: str = "normals",
        upper_factor: float | None = None,
        min_lights: int | None = None,
        band: tuple[float, float] | None = None,
        unsolved_deg: float | None = None,
        lamps: LampGeometry | None = None,
        misfit_noise_k: float | None = None,
    ) -> None:
        #: the misfit bound's allowance for noise (None: this build's
        #: ``adaptive_until.MISFIT_NOISE_K``; a resume passes the session's own)
        self.misfit_noise_k = (
            adaptive_until.MISFIT_NOISE_K if misfit_noise_k is None else float(misfit_noise_k)
        )
        #: the last estimate's misfit bound from the images (°; None: none taken yet, or no
        #: pixel with a residual)
        self.misfit: float | None = None
        #: each image's sample at the camera's resolution (:func:`camera_sample`), when the
        #: caller gives it: what the unsolved share and the misfit bound are taken on
        self.camera_samples: list[NDArray[np.float32]] = []
        #: the lamps' distance and the frame's field on the object (None: not known, the
        #: estimate renders directional lights): the stop's estimate renders point lamps at
        #: that distance (``planner.adaptive_bias.NearLamps``); the choice of light does not
        self.lamps = lamps
        #: the elevation band (°) the candidates were cut to (None: every elevation): words
        #: of the decisions' evidence only (each design named by the floor the band applied,
        #: ``planner.adaptive.applied_floor``), never a choice
        self.band = band
        #: with --until-error: the fewest lights the stop may claim the target at (None: no
        #: minimum). The normal error is not the only thing a session is for: a PTM needs 6
        #: lights and an HSH fit 5 (RTI_FILE_LIGHTS), and a stop at 4 gives a normal map and
        #: no RTI.
        self.min_lights = min_lights
        #: the stop's upper estimate's simulated term = the point estimate × this (None: this
        #: build's ``adaptive_until.UPPER_FACTOR``, read now; a resume passes the session's own)
        self.upper_factor = adaptive_until.UPPER_FACTOR if upper_factor is None else upper_factor
        #: what each pixel no image solves yet adds to the upper estimate (°; None: this
        #: build's ``adaptive_until.UNSOLVED_DEG``; a resume passes the session's own)
        self.unsolved_deg = (
            adaptive_until.UNSOLVED_DEG if unsolved_deg is None else float(unsolved_deg)
        )
        #: the fraction of seen pixels the last estimated state left unsolved (None: no
        #: estimate yet): the upper estimate's second term, set with each estimate
        self.unsolved: float | None = None
        #: the design score and the estimate: a robust fit simulated on this object's model
        #: (None: BIAS_AWARE), else the Lambertian variance bound
        self.bias_aware = BIAS_AWARE if bias_aware is None else bias_aware
        #: what the designs (``--lights N``) are chosen for: ``normals`` (the simulated normal
        #: error) or ``relight`` (the simulated relighting PSNR: ``planner.adaptive_relight``)
        if objective not in OBJECTIVES:
            raise ValueError(f"unknown objective {objective!r}")
        if objective == "relight" and (design_lights is None or not self.bias_aware):
            raise ValueError("the relight objective chooses designs of N lights by simulation")
        self.objective = objective
        if scale is None:
            scale = SIM_ESTIMATE_SCALE if self.bias_aware else ESTIMATE_SCALE
        self.candidates = np.asarray(candidates, dtype=np.float64)
        #: the number of lights the design is for (``--lights N``); None: light by light
        self.design_lights = design_lights
        self.start = list(start)
        self.max_lights = max_lights
        self.until_error_deg = until_error_deg
        self.capture_s = capture_s
        self.move_times = move_times
        self.scale = scale
        self.samples: list[NDArray[np.float32]] = []  # each image's pixel sample
        self.images: list[NDArray[np.float32]] = []  # the small grey images (bias-aware)
        #: the floor of the design the last decision chose in (None: none yet)
        self.floor: float | None = None
        self.lights: list[NDArray[np.float64]] = []
        self.used: list[int] = []
        self.stop_evidence: dict[str, Any] | None = None

    def observe(
        self,
        candidate: int,
        direction: NDArray[np.float64],
        image: NDArray,
        camera: NDArray[np.float32] | None = None,
    ) -> None:
        """Take a captured image: ``image`` the small grey copy the decisions are fitted on,
        ``camera`` its sample at the camera's resolution (:func:`camera_sample`; None: the
        small image's own sample is used for the stop's evidence too, as a benchmark's 96-px
        scene is its own full resolution)."""
        self.used.append(int(candidate))
        self.lights.append(np.asarray(direction, dtype=np.float64))
        self.samples.append(sample_pixels(np.asarray(image)[None])[0])
        if camera is not None:
            self.camera_samples.append(np.asarray(camera, dtype=np.float32))
        if self.bias_aware:  # the small image itself, for the relief (cast shadows)
            self.images.append(np.asarray(image, dtype=np.float32))

    def state(self) -> SurfaceState | None:
        if len(self.samples) < 3:
            return None
        lights = np.stack(self.lights)
        if not self.bias_aware or len(self.images) != len(self.samples):
            return fit_sample(np.stack(self.samples), lights)
        images = np.stack(self.images)
        shape = images.shape[1:3]
        where = np.unravel_index(sample_index(shape[0] * shape[1]), shape)
        return fit_sample(np.stack(self.samples), lights, where, relief_px(images, lights))

    def raw_estimate(self, state: SurfaceState) -> float:
        """The uncalibrated error estimate (°) of the lights so far: the robust fit simulated
        on this object's model (bias included), or the bound's mean angle."""
        if self.bias_aware:
            model = object_model(state)
            if model is not None:
                return simulate_error_deg(model, state.lights, robust_fit, near=self.near(state))
        return estimate_error_deg(state, 1.0)

    def near(self, state: SurfaceState) -> NearLamps | None:
        """The lamps' geometry at the state's pixels (None: no lamp geometry given, or the
        state does not place its pixels): each pixel's place on the object plane, the small
        image spanning ``lamps.field_width_mm``. From the state's own rows and columns: its
        pixels are the sampled ones not dark under every light, in sample order, so a
        position per sampled pixel would slide past the first dark one."""
        if self.lamps is None or not self.images or state.rows is None or state.cols is None:
            return None
        h, w = self.images[0].shape[:2]
        per_px = self.lamps.field_width_mm / w
        rows, cols = np.asarray(state.rows), np.asarray(state.cols)
        xy = np.stack([(cols - (w - 1) / 2) * per_px, ((h - 1) / 2 - rows) * per_px], 1)
        return NearLamps(self.lamps.distance_mm, xy.astype(np.float64))

    def estimate(self, state: SurfaceState) -> float:
        """The calibrated estimate of the mean normal error (°) now: ``scale`` × raw. Notes
        the images' own evidence too, which the upper estimate weighs: the unsolved fraction
        (:attr:`unsolved`) and the misfit bound (:attr:`misfit`), both at the camera's
        resolution when the images' camera samples are given (:meth:`image_evidence`): every
        figure the stop compares is of the same images."""
        self.unsolved, self.misfit = self.image_evidence(state)
        return self.scale * self.raw_estimate(state)

    def image_evidence(self, state: SurfaceState) -> tuple[float, float | None]:
        """The unsolved share of the seen pixels and the misfit bound (°) of the robust fit
        (``planner.adaptive_until.misfit_deg``), on the camera-resolution samples when every
        image gave one (fitted as the state is: :func:`fit_sample`), else on the state's own
        (the small images'). The share is the larger of the camera's and the small images':
        the upper estimate is then never below what it was before the camera's was read, so
        a session begun before it replays on --resume as it was decided (a step it shot past
        is never found to be a stop)."""
        share = unsolved_fraction(state.valid)
        if self.camera_samples and len(self.camera_samples) == len(self.lights):
            camera = fit_sample(np.stack(self.camera_samples), np.stack(self.lights))
            if camera is not None:  # else (refused at full size): the small images' evidence
                state = camera
                share = max(share, unsolved_fraction(camera.valid))
        if state.residual is None or state.used is None or state.valid is None:
            return share, None
        bound = misfit_deg(
            state.residual,
            state.used,
            state.albedo,
            state.valid,
            state.lit,
            state.lights,
            self.misfit_noise_k,
        )
        return share, bound

    def upper(self, estimate_deg: float) -> float:
        """The upper estimate (°) the stop compares with the target: the larger of the point
        estimate × ``upper_factor`` and the images' misfit bound, plus the unsolved pixels'
        share at ``unsolved_deg`` each (``planner.adaptive_until.upper_error_deg``)."""
        return upper_error_deg(
            estimate_deg, self.upper_factor, self.unsolved or 0.0, self.unsolved_deg, self.misfit
        )

    def stop_terms(self, estimate_deg: float | None) -> dict[str, Any]:
        """What the stop compares, for the record: the point estimate, the upper one and the
        factor between them (None estimates before anything can be fitted)."""
        upper = None if estimate_deg is None else self.upper(estimate_deg)
        # to 4 places, or as many more as keep it on its side of the target: rounded to 4 first,
        # an upper estimate within 5e-5 of a target of 4 places could be recorded (and printed)
        # level with the target on the wrong side
        places = 4
        if upper is not None and self.until_error_deg is not None:
            places = max(4, places_against(upper, self.until_error_deg))
        return {
            "estimated_error_deg": None if estimate_deg is None else round(estimate_deg, 4),
            "upper_error_deg": None if upper is None else round(upper, places),
            "upper_factor": self.upper_factor,
            "unsolved_fraction": (
                None if estimate_deg is None or self.unsolved is None else round(self.unsolved, 4)
            ),
            "unsolved_deg": self.unsolved_deg,
            "misfit_deg": (
                None if estimate_deg is None or self.misfit is None else round(self.misfit, 4)
            ),
        }

    def _cap_stop(self, est: float | None) -> dict[str, Any]:
        """The stop at the session's maximum, with what the stop compared; with
        --until-error, whether the last light reached the target too or the target is not
        claimed (so that a capped session is not read as having reached it)."""
        reason = self._cap_reason()
        if self.until_error_deg is not None and est is None:  # nothing could be fitted
            reason += (
                f" before --until-error {self.until_error_deg:g}° could be judged (no "
                "estimate: the images so far cannot be fitted; the target is not claimed)"
            )
        elif self.until_error_deg is not None and est is not None:
            if self._reaches(est):  # the last light reached the target as well
                reason = self._reached_reason(est)
            else:
                upper = self.stop_terms(est)["upper_error_deg"]
                places = places_against(upper, self.until_error_deg)
                reason += (
                    f" before --until-error {self.until_error_deg:g}° was reached (upper "
                    f"estimate {upper:.{places}f}°: the target is not claimed)"
                )
        return {"kind": "stop", "reason": reason, **self.stop_terms(est)}

    def _reaches(self, est: float) -> bool:
        """Whether the stop may claim --until-error (``adaptive_until.reaches_target``)."""
        assert self.until_error_deg is not None
        return reaches_target(
            est,
            self.until_error_deg,
            self.upper_factor,
            self.unsolved or 0.0,
            self.unsolved_deg,
            self.misfit,
        )

    def _past_minimum(self, index: int) -> bool:
        """Whether ``index`` lights are at least the --min-lights asked for (always, without)."""
        return self.min_lights is None or index >= self.min_lights

    def _reached_reason(self, est: float, index: int | None = None) -> str:
        # the figures as recorded (rounded to 4 places), so that the reason and the result's
        # line cannot print one upper estimate as 3.99° and 3.98° (3.98500… and 3.985)
        terms = self.stop_terms(est)
        assert self.until_error_deg is not None
        places = places_against(terms["upper_error_deg"], self.until_error_deg)
        reason = (
            f"upper estimate {terms['upper_error_deg']:.{places}f}° ("
            f"{first_term_words(terms, places)}{unsolved_words(terms)}) ≤ --until-error "
            f"{self.until_error_deg:g}°"
        )
        if self.min_lights is not None and index == self.min_lights:
            reason += f", at the --min-lights {self.min_lights} asked for"
        return reason

    def _cap_reason(self) -> str:
        # --lights N, or without it the rig's own cap: both are the session's maximum
        return f"reached its maximum of {self.max_lights} lights"

    def decide(self, index: int) -> tuple[int | None, dict[str, Any]]:
        """Candidate for step ``index`` (None: stop) and the evidence of the decision.

        BLAS runs on one thread: the decision's matrices are small, and on a busy machine
        BLAS's waiting threads cost more than they give (measured: 0.05–0.06 s against
        0.13–0.28 s for one decision at 18 lights, load average 4.5 on 2 cores)."""
        from threadpoolctl import threadpool_limits

        with threadpool_limits(limits=1, user_api="blas"):
            candidate, evidence = self._decide(index)
        evidence.setdefault("objective", self.objective)  # every decision says what it serves
        return candidate, evidence

    def _decide(self, index: int) -> tuple[int | None, dict[str, Any]]:
        t0 = time.perf_counter()
        if index < len(self.start) and index < self.max_lights:
            return self.start[index], {"kind": "start", "reason": "starting layout"}
        state = self.state()
        if index >= self.max_lights:
            est = None if state is None else self.estimate(state)
            self.stop_evidence = self._cap_stop(est)
            return None, self.stop_evidence
        if state is None:  # the starting layout cannot be fitted: fall back to coverage
            available = np.ones(len(self.candidates), dtype=bool)
            available[self.used] = False
            far = np.flatnonzero(available)
            if far.size == 0:
                self.stop_evidence = {
                    "kind": "stop",
                    "reason": "no candidate light left (the images so far cannot be fitted: "
                    "no estimate, nothing claimed)",
                    **self.stop_terms(None),
                }
                return None, self.stop_evidence
            dots = self.candidates[far] @ np.stack(self.lights).T if self.lights else None
            pick = int(far[0] if dots is None else far[np.argmin(dots.max(axis=1))])
            return pick, {"kind": "coverage", "reason": "fit not yet possible: farthest light"}
        est = self.estimate(state)
        reached = self.until_error_deg is not None and self._reaches(est)
        held = reached and not self._past_minimum(index)  # the target alone would stop here
        if reached and not held:
            # the target is claimed only when the upper estimate is under it
            self.stop_evidence = {
                "kind": "stop",
                "reason": self._reached_reason(est, index),
                **self.stop_terms(est),
            }
            return None, self.stop_evidence
        available = np.ones(len(self.candidates), dtype=bool)
        available[self.used] = False
        current = self.lights[-1] if self.lights else None
        move = None if self.move_times is None else self.move_times(current)
        if self.design_lights is not None:
            d = choose_in_design(
                state,
                self.candidates,
                available,
                self.design_lights,
                capture_s=self.capture_s,
                move_s=move,
                scale=self.scale,
                fit=robust_fit if self.bias_aware else None,
                incumbent=self.floor if self.bias_aware else None,
                objective=self.objective,
                relight=relight_fit if self.objective == "relight" else None,
                band=self.band,
            )
            self.floor = d.design_floor
        elif self.bias_aware and UNTIL_DESIGN:
            # N unknown: the design for a guessed N that grows (planner.adaptive_until)
            d = choose_until(
                state,
                self.candidates,
                available,
                self.max_lights,
                fit=robust_fit,
                incumbent=self.floor,
                capture_s=self.capture_s,
                move_s=move,
                scale=self.scale,
                band=self.band,
            )
            self.floor = d.design_floor
        else:
            d = choose_next(
                state,
                self.candidates,
                available,
                capture_s=self.capture_s,
                move_s=move,
                scale=self.scale,
            )
        if self.bias_aware and d.estimated_error_deg > 0:
            # the bound's predictions after each candidate, rescaled to the estimate now (the
            # simulated one, bias included): a ratio, so the candidates keep their ranking
            ratio = est / d.estimated_error_deg
            d = replace(
                d,
                estimated_error_deg=est,
                predicted_error_deg=(
                    None if d.predicted_error_deg is None else d.predicted_error_deg * ratio
                ),
                runner_up=[
                    {**r, "predicted_error_deg": round(r["predicted_error_deg"] * ratio, 4)}
                    for r in d.runner_up
                ],
            )
        if d.candidate is None:
            self.stop_evidence = {"kind": "stop", **d.evidence(), **self.stop_terms(est)}
            return None, self.stop_evidence
        return d.candidate, {
            "kind": "adaptive",
            **d.evidence(),
            **self.stop_terms(est),  # what the stop compared before this light (not reached,
            # or reached and held by --min-lights: said)
            **({"held": f"--min-lights {self.min_lights}"} if held else {}),
            "decision_s": round(time.perf_counter() - t0, 4),
        }

    def conclude(self) -> dict[str, Any]:
        """The estimate after the last image, for the manifest."""
        from threadpoolctl import threadpool_limits

        state = self.state()
        with threadpool_limits(limits=1, user_api="blas"):
            est = None if state is None else self.estimate(state)
            distant = None if state is None or est is None else self._distant_estimate(state, est)
        return {
            "objective": self.objective,
            "lights_used": len(self.used),
            "max_lights": self.max_lights,
            "until_error_deg": self.until_error_deg,
            "min_lights": self.min_lights,
            # whether the stop claims --until-error (what the stop compared after the last
            # image; a capped or unfittable session does not)
            "target_claimed": bool(
                self.until_error_deg is not None and est is not None and self._reaches(est)
            ),
            **self.stop_terms(est),
            # a session run to its maximum is never asked for the step past it: the stop here
            "stop": self.stop_evidence or self._cap_stop(est),
            # the lamps the estimate rendered (None: distant), as the claim's note says them
            "lamps": None if self.lamps is None else self.lamps.record(),
            **({} if distant is None else {"distant_lamps_estimate_deg": round(distant, 4)}),
        }

    def _distant_estimate(self, state: SurfaceState, est: float) -> float | None:
        """With --until-error not reached and the lamps rendered: the estimate the same images
        would have under distant lamps (None: otherwise). Why: on the shipped arm the lamps'
        bias (0.88° at 100 lights) keeps the upper estimate above 1.5° at any light count;
        a session that ran to its maximum says how much of the gap is the lamps', which more
        lights do not close (``short_of_target_note``)."""
        if self.until_error_deg is None or self.lamps is None or self._reaches(est):
            return None
        model = object_model(state) if self.bias_aware else None
        if model is None:
            return None
        return self.scale * simulate_error_deg(model, state.lights, robust_fit)


# --- the rig side: candidates, starting layout, move times, the step source ---------------


def _capture_s(rig) -> float:  # type: ignore[no-untyped-def]
    t = rig.loaded.config.timing
    return t.light_switch_s + t.settle_s + rig.camera_config.exposure_s + t.readout_s + t.transfer_s


def _arm_motion_settings(loaded) -> Any:  # type: ignore[no-untyped-def]
    """The move-time model's settings: the servos' when configured, else the simulated arm's."""
    arm = loaded.config.arm
    if arm.dynamixel is not None:
        return arm.dynamixel
    joint = SimpleNamespace(
        joint_velocity_deg_s=arm.speed_deg_s, joint_acceleration_deg_s2=arm.acceleration_deg_s2
    )
    az = SimpleNamespace(min_deg=-180.0, max_deg=179.999, **vars(joint))
    el = SimpleNamespace(min_deg=0.0, max_deg=90.0, **vars(joint))
    return SimpleNamespace(
        azimuth=az,
        elevation=el,
        park_azimuth_deg=arm.park_azimuth_deg,
        park_elevation_deg=arm.park_elevation_deg,
        settle_time_s=0.0,
    )


#: every elevation a rig offers: no ``--min/--max-elevation-deg`` given. Private: the public
#: upper-case names here are decision constants, recorded in every manifest and compared on
#: resume (a new one refused every session begun before it); the band is the session's own,
#: recorded as such.
_FULL_BAND = (0.0, 90.0)


@dataclass(frozen=True)
class AdaptivePlan:
    """What the rig can do, for the adaptive loop: candidates and the starting layout."""

    candidates: NDArray[np.float64]
    leds: NDArray[np.intp] | None  # a dome's LED of each candidate
    start: list[int]
    max_lights: int
    #: ``--lights N``: the design is chosen for N lights as a whole; None: light by light
    design_lights: int | None = None
    #: the elevation band (°) every light is chosen in (``--min/--max-elevation-deg``)
    band: tuple[float, float] = _FULL_BAND


def _floor_for(geometry: DomeGeometry, n: int, floor_deg: float = START_FLOOR_DEG) -> float:
    """``floor_deg``, lowered to the elevation of the dome's ``n``-th highest LED where fewer
    than ``n`` are above it: a band asked for (``--max-elevation-deg 15`` over a 5° ring) may
    lie below the default floor, and the start is then the band's own layout. Unchanged
    wherever the floor leaves ``n`` LEDs (it had been an error otherwise)."""
    el = np.sort(np.degrees(np.arcsin(np.clip(geometry.directions[:, 2], -1.0, 1.0))))[::-1]
    return float(min(floor_deg, el[min(n, len(el)) - 1]))


#: The elevation span (°) within which the lights a start is taken from are one ring: there the
#: starting layout's elevations cannot spread it, and its azimuths must (:func:`_ring_start`).
#: A resume takes the session's own (``adaptive_constants.RESTORED_ON_RESUME``): one begun
#: before it existed (none recorded) resumes without it, as it began, and is not refused.
RING_SPAN_DEG = 2.0


def dome_start(
    geometry: DomeGeometry,
    k: int,
    n_total: int | None,
    objective: str = "normals",
    above_floor: bool | None = None,
    band: tuple[float, float] | None = None,
    ring_span_deg: float | None = RING_SPAN_DEG,
) -> list[int]:
    """LED indices of a dome's starting layout of ``k``: with ``n_total`` known, the ``k`` of
    the homogeneous layout of ``n_total`` (at the objective's default floor) closest to a
    homogeneous layout of ``k`` — so that the default design is that layout exactly
    (``above_floor``: as ``start_subset``'s, for the benchmarks' variants).

    ``band`` (an elevation band the session was cut to; None or every elevation: none): where
    the lights the start is taken from are one ring (within :data:`RING_SPAN_DEG`), the start
    is spread evenly round it (:func:`_ring_start`). The homogeneous layouts place their
    lights by a golden-angle spiral whose elevations spread them; on one ring only its
    azimuths are left, and four of them fall within 137.5° (`--adaptive --lights 5
    --min-elevation-deg 60` on `simulated_dome.toml` started at 0°, 60°, 120° and 300°,
    three on one side and none within 180° of 210°). ``ring_span_deg`` None: never (a session
    begun before the rule, resumed as it began)."""
    banded = band is not None and tuple(band) != _FULL_BAND and ring_span_deg is not None
    if n_total is None or n_total <= k:
        if banded and _one_ring(geometry.directions, ring_span_deg):
            return _ring_start(geometry.directions, k)
        return [int(i) for i in select_uniform_leds(geometry, k, _floor_for(geometry, k))]
    from rti_rig.planner import adaptive

    floor = _floor_for(geometry, n_total, adaptive.default_floor_for(objective))
    full = select_uniform_leds(geometry, n_total, floor)
    if banded and _one_ring(geometry.directions[full], ring_span_deg):
        return sorted(int(full[i]) for i in _ring_start(geometry.directions[full], k))
    pick = start_subset(geometry.directions[full], k, objective=objective, above_floor=above_floor)
    return [int(full[i]) for i in pick]


def _elevations_deg(dirs: NDArray[np.float64]) -> NDArray[np.float64]:
    return np.degrees(np.arcsin(np.clip(dirs[:, 2], -1.0, 1.0)))


def _one_ring(dirs: NDArray[np.float64], span_deg: float | None) -> bool:
    """Whether the lights ``dirs`` lie within ``span_deg`` of elevation (None: never)."""
    el = _elevations_deg(dirs)
    return span_deg is not None and bool(el.max() - el.min() <= span_deg)


def _ring_start(dirs: NDArray[np.float64], k: int) -> list[int]:
    """Indices of ``k`` of the ring of lights ``dirs`` matched one-to-one (least total angle)
    to ``k`` directions evenly spaced round it (every 360°/k, at its mean elevation), the
    target turned in steps of a 24th of that spacing to fit the ring's own LEDs best (the
    first best on a tie)."""
    from scipy.optimize import linear_sum_assignment

    if k >= len(dirs):
        return list(range(len(dirs)))
    el = np.radians(float(_elevations_deg(dirs).mean()))
    best: tuple[float, list[int]] | None = None
    for offset in np.arange(24) / 24.0:
        az = 2.0 * np.pi * (np.arange(k) + offset) / k
        target = np.stack(
            [np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.full(k, np.sin(el))], axis=1
        )
        cost = np.arccos(np.clip(target @ dirs.T, -1.0, 1.0))
        rows, cols = linear_sum_assignment(cost)
        total = float(cost[rows, cols].sum())
        if best is None or total < best[0] - 1e-9:
            best = (total, sorted(int(c) for c in cols))
    assert best is not None
    return best[1]


def images_sure(header: dict[str, Any]) -> int:
    """The images an adaptive session is sure to take, from its header (``AdaptiveSteps.
    header``, the manifest's ``adaptive``): its ``max_lights`` when the count is known, but
    with --until-error and no --lights (no design) only its starting lights, or --min-lights
    if larger — the stop may come at any light after those.

    Why: the disk was asked to hold the session's maximum (on simulated_dome ``--until-error
    8``: 48 images, 103.5 MB, for a session that stopped after 4, 6.5 MB), refusing sessions
    that fit; the rest is checked image by image (a session stopped by a full disk is kept
    and can be resumed)."""
    total = int(header["max_lights"])
    if header.get("until_error_deg") is None or header.get("design_lights") is not None:
        return total
    least = max(int(header.get("start_lights") or 0), int(header.get("min_lights") or 0))
    return min(total, least)


def images_before_rig(  # type: ignore[no-untyped-def]
    loaded,
    offered: int | None,
    lights: int | None,
    until_error_deg: float | None,
    min_lights: int | None,
    band: tuple[float, float] = _FULL_BAND,
) -> tuple[int, int]:
    """The images a new adaptive session is sure to take and the most it may take, from its
    request and rig config alone, as :func:`images_sure` counts them once the rig is built:
    its ``--lights`` (checked against what the rig offers) or its cap, the config's
    ``default_lights`` or every light offered; with --until-error and no --lights, its
    starting lights (or --min-lights if larger). ``offered``: a dome's lights in the band
    (None on an arm, whose lights in reach are counted here before its lighting rules, which
    need the rig, drop any: the figure is then at most the session's).

    Why: the disk check of an adaptive session had waited for the rig (the dome's port
    opened, the fit warmed up, ~13 s on emulated_dome) when a planned run's refusal comes
    before it; what the session needs is known from its request."""
    if offered is None:  # an arm: its lights in reach, before its lighting rules
        from rti_rig.app.config import rig_geometry
        from rti_rig.planner.uniform import arm_below

        geometry = rig_geometry(loaded)
        assert isinstance(geometry, ArmGeometry)
        within = len(candidates_for(arm_below(geometry, band[1]), band[0]).directions)
        cap = min(ARM_MAX_LIGHTS, within)
    else:
        within = cap = offered
    default = None if lights is not None else default_max_lights(loaded, until_error_deg)
    if default is not None:
        cap = min(cap, default)
    most = min(lights, within) if lights is not None else cap
    header = {
        "max_lights": most,
        "until_error_deg": until_error_deg,
        "min_lights": min_lights,
        "start_lights": min(START_LIGHTS, most),
        "design_lights": most if lights is not None else None,
    }
    return images_sure(header), most


def default_max_lights(loaded, until_error_deg: float | None) -> int | None:  # type: ignore[no-untyped-def]
    """The maximum of an adaptive session given neither ``--lights`` nor ``--until-error``:
    the rig config's ``default_lights``, as ``--lights`` documents its default and a planned
    run uses it (an arm's 24; a dome's ``default_lights`` if set). None — every light the rig
    offers, on an arm :data:`ARM_MAX_LIGHTS` — with ``--until-error``, whose N is unknown, and
    on a dome without ``default_lights``. ``--adaptive`` alone on an arm had shot 100 lights,
    four times the 24 its config and ``--lights``'s help promise."""
    if until_error_deg is not None:
        return None
    cfg = loaded.config
    section = cfg.arm if cfg.arm is not None else cfg.dome
    default = getattr(section, "default_lights", None)
    return None if default is None else int(default)


def adaptive_plan(  # type: ignore[no-untyped-def]
    rig,
    lights: int | None,
    start_lights: int = START_LIGHTS,
    design: bool | None = None,
    objective: str = "normals",
    band: tuple[float, float] = _FULL_BAND,
    default_max: int | None = None,
    positions: NDArray[np.float64] | None = None,
    ring_span_deg: float | None = RING_SPAN_DEG,
) -> AdaptivePlan:
    """Candidates the rig can really run (each checked by the rig's own lighting rules) and a
    homogeneous starting layout of ``start_lights``; with ``lights`` given (``design`` not
    False) the rest is chosen as a design of that many lights, starting from the objective's
    default floor. Without ``lights``, the session's maximum is ``default_max`` (the rig
    config's ``default_lights``, :func:`default_max_lights`) where given, else every light
    the rig offers (an arm: :data:`ARM_MAX_LIGHTS`), never more than the candidates.

    ``band`` (``--min/--max-elevation-deg``): only the lights between these elevations are
    candidates, so every light of the session — the start, each decision, each design — is in
    it (a gilded object's highlights kept off the camera by a 45° ceiling). The rig is seen as
    that band alone: a dome as its LEDs in the band, an arm with its band cut at the ceiling.

    ``positions`` (a dome's, one per LED): the LED positions to decide on instead of the
    rig's — on a resume, those the session recorded, which the rig's differ from by rounding
    alone (:func:`rig_identity.same_rig`). ``ring_span_deg``: as :func:`dome_start`'s (a
    resume passes the session's own)."""
    from rti_rig.planner import adaptive
    from rti_rig.planner.uniform import arm_below

    lo, hi = band
    geometry = rig.geometry
    if positions is not None and isinstance(geometry, DomeGeometry):
        geometry = DomeGeometry(np.asarray(positions, dtype=np.float64), geometry.names)
    if isinstance(geometry, DomeGeometry):
        cands = candidates_for(geometry, lo, max_elevation_deg=hi)
        dirs, leds = cands.directions, cands.leds
        assert leds is not None
        cap = len(dirs)
        # the band's LEDs as a dome of their own: its LED i is candidate i
        sub = DomeGeometry(dirs, tuple(geometry.names[int(i)] for i in leds))
    else:
        assert isinstance(geometry, ArmGeometry)
        arm = arm_below(geometry, hi)
        dirs, leds = _arm_candidates(rig, geometry, band), None
        cap = ARM_MAX_LIGHTS
    if default_max is not None:
        cap = min(cap, default_max)
    max_lights = min(lights if lights is not None else cap, len(dirs))
    k0 = min(start_lights, max_lights)
    # a count known in advance — --lights, or without it the config's default_lights (no
    # --until-error) — is designed for as a whole: --adaptive alone on an arm (24 lights) had
    # grown its guess 6, 9, 12, … as if N were unknown, 20 % worse than --lights 24
    known = lights is not None or default_max is not None
    n_design = max_lights if (known and design is not False) else None
    if isinstance(geometry, DomeGeometry):
        start = dome_start(
            sub, k0, n_design, objective, band=(float(lo), float(hi)), ring_span_deg=ring_span_deg
        )
    else:
        from rti_rig.planner.objectives import Candidates

        floor = START_FLOOR_DEG if n_design is None else adaptive.default_floor_for(objective)
        # the floor as before, moved only where it leaves no band (a ceiling at or below it:
        # then the middle of the band, so that the start is the band's own layout)
        reach_lo, top = arm.elevation_band(lo)
        start_floor = max(floor, lo)
        if start_floor >= top:
            start_floor = (reach_lo + top) / 2
        targets = arm.homogeneous(n_design or k0, start_floor)
        snapped = snap_unique(targets, Candidates(dirs, None, None))
        if n_design is not None and n_design > k0:
            pick = start_subset(dirs[np.asarray(snapped)], k0, objective=objective)
            snapped = [snapped[i] for i in pick]
        start = [int(i) for i in snapped]
    return AdaptivePlan(dirs, leds, start, max_lights, n_design, (float(lo), float(hi)))


class AdaptiveSteps:
    """The controller's step source for an adaptive session (see the module docstring)."""

    def __init__(  # type: ignore[no-untyped-def]
        self,
        rig,
        plan: AdaptivePlan,
        until_error_deg: float | None,
        objective: str = "normals",
        upper_factor: float | None = None,
        min_lights: int | None = None,
        unsolved_deg: float | None = None,
        lamps: LampGeometry | str | None = "rig",
        misfit_noise_k: float | None = None,
    ) -> None:
        self.plan = plan
        self.until_error_deg = until_error_deg
        self.min_lights = min_lights
        self.objective = objective
        move: MoveTimes | None = None
        self._park = None
        if isinstance(rig.geometry, ArmGeometry):
            settings = _arm_motion_settings(rig.loaded)
            park = rig.geometry.park_direction
            self._park = park

            def move(current):  # type: ignore[no-untyped-def]
                here = park if current is None else current
                return np.array([move_time_s(here, d, settings) for d in plan.candidates])

        self.chooser = AdaptiveChooser(
            plan.candidates,
            plan.start,
            plan.max_lights,
            until_error_deg,
            capture_s=_capture_s(rig),
            move_times=move,
            design_lights=plan.design_lights,
            objective=objective,
            upper_factor=upper_factor,
            min_lights=min_lights,
            band=plan.band,
            unsolved_deg=unsolved_deg,
            # "rig": the rig's own (the composition root's ``[lamps]`` or scene); a resume
            # passes the session's
            lamps=getattr(rig, "lamps", None) if lamps == "rig" else lamps,
            misfit_noise_k=misfit_noise_k,
        )
        self._pending: dict[int, int] = {}
        self._outcome: dict[str, Any] | None = None
        self._move = move  # for a refused resume's words (:meth:`_timing_differences`)
        #: whether --lights was given: a design for the config's default_lights (``--adaptive``
        #: alone) is recorded as design_lights too, and its resume with the line that began
        #: it (no --lights) is the same request (recorded: ``header()['lights_given']``)
        self.lights_given = plan.design_lights is not None

    @property
    def total(self) -> int:
        return self.plan.max_lights

    @property
    def sure_total(self) -> int:
        """The lights this session is sure to take (:func:`images_sure`)."""
        return images_sure(self.header())

    def start_schedule(self) -> LightSchedule:
        """The starting layout, recorded as the session's schedule in the manifest."""
        return LightSchedule(tuple(self._step(c) for c in self.plan.start), method="adaptive")

    def header(self) -> dict[str, Any]:
        return {
            "format": FORMAT if self.min_lights is None else FORMAT_MIN_LIGHTS,
            "max_lights": self.plan.max_lights,
            "until_error_deg": self.until_error_deg,
            "min_lights": self.min_lights,
            "start_lights": len(self.plan.start),
            "design_lights": self.plan.design_lights,
            "lights_given": self.lights_given,
            "objective": self.objective,
            "candidates": len(self.plan.candidates),
            "min_elevation_deg": self.plan.band[0],
            "max_elevation_deg": self.plan.band[1],
            "fit_px": FIT_PX,
            "estimate_scale": self.chooser.scale,
            "upper_factor": self.chooser.upper_factor,
            "unsolved_deg": self.chooser.unsolved_deg,
            "misfit_noise_k": self.chooser.misfit_noise_k,
            "lamps": None if self.chooser.lamps is None else self.chooser.lamps.record(),
            "constants": decision_constants(),
        }

    def _step(self, candidate: int) -> LightStep:
        d = self.plan.candidates[candidate]
        led = None if self.plan.leds is None else int(self.plan.leds[candidate])
        return LightStep((float(d[0]), float(d[1]), float(d[2])), led=led)

    def next_step(self, index: int) -> tuple[LightStep, dict[str, Any]] | None:
        candidate, evidence = self.chooser.decide(index)
        if candidate is None:
            return None
        self._pending[index] = candidate
        return self._step(candidate), evidence

    def observe(self, index: int, frame: Frame, record) -> None:  # type: ignore[no-untyped-def]
        # in units of the white the TIFF's label states, as --resume reads it back (a replay
        # of 12-bit data is weighed against 4095: against 65535 its clipped highlights had
        # passed for light well within range)
        white = labelled_white(frame)
        self.chooser.observe(
            self._pending.pop(index),
            np.asarray(record.actual_direction),
            small_grey(frame.pixels, white),  # as --resume reads it back from the linear TIFF
            camera_sample(frame.pixels, white),  # the stop's evidence at the camera's resolution
        )

    def replay(self, folder) -> None:  # type: ignore[no-untyped-def]
        """Show the chooser the steps already on disk (``--resume``), in index order, and check
        that each would be decided again as it was (else the session cannot continue as it
        began).

        A step is decided again as it was when the same light is chosen: on a dome the same
        LED at its position to within :data:`rig_identity.POSITION_TOLERANCE_RAD` (a
        re-measured ``.lp`` that differs by rounding is the same rig; they had been compared
        at 1e-9, so such a session could never continue). After ``--accept-rig-change`` the
        steps already taken were decided on the rig as it was, which this one no longer is:
        each is checked against what was recorded (its light, on this rig, and its image,
        which the reopen verified) and not against a decision on the changed rig (which had
        refused every such resume); the chooser is told each light where it really was, and
        decides the remaining steps on the rig as it is now."""
        done = folder.done
        refuse_broken_run(Path(folder.root), folder.total_steps)(done)
        other_rig = _decided_on_another_rig(folder, len(done))
        for i in range(len(done)):
            rec = done[i]
            # decided on this rig in every case: the chooser's state (the design it is in)
            # grows from its own decisions on the images so far
            candidate, _ = self.chooser.decide(i)
            if i < other_rig:
                candidate = self._recorded_candidate(folder, i, rec)
            elif candidate is None or not self._same_light(candidate, rec):
                # against the config the session began with, whose times decided this step
                timing = self._timing_differences((folder.manifest.get("rig") or {}).get("config"))
                if timing:  # the config's times changed: restoring them continues the session
                    raise RtiRigError(
                        f"{shown_path(folder.root)}: step {i + 1} is not decided as it was: an "
                        "adaptive session weighs each light by the time it costs (the capture and, "
                        "on an arm, the move to it), and the rig config now gives other times ("
                        + "; ".join(timing)
                        + "). Nothing was recorded or captured. Put those settings back as the "
                        "session began to continue it, or start a new session"
                    )
                raise RtiRigError(
                    f"{shown_path(folder.root)}: step {i + 1} was decided differently when the "
                    "session began (another rig config, software version or image on disk, or "
                    "the session's manifest.json or journal.jsonl edited since); it cannot be "
                    "continued deterministically. Nothing was recorded or captured: if one of "
                    "those was changed, put it back as it was (the files from a backup copy of "
                    "the folder) and resume again, else start a new session"
                )
            tiff = Path(folder.root) / rec.linear_image
            pixels = read_linear_tiff(tiff)
            white = linear_tiff_white_level(tiff) or 65535  # as the run weighed it
            self.chooser.observe(
                candidate,
                np.asarray(rec.actual_direction),
                small_grey(pixels, white),
                camera_sample(pixels, white),
            )
        if other_rig:
            self._keep_start_unused(folder, len(done))
        elif not getattr(folder, "rig_change", None) and (
            timing := self._timing_differences(_last_run_config(folder.manifest))
        ):
            # the steps taken replayed as they were, but the rest would be chosen for the new
            # times: a resume on a slowed arm had gone on without a word, and finished another
            # session than the one begun (whether it was refused hung on whether a step taken
            # happened to be decided otherwise)
            raise RtiRigError(
                f"{shown_path(folder.root)}: the rig config now gives other times than this "
                "session's lights were chosen with ("
                + "; ".join(timing)
                + "). An adaptive session weighs each light by the time it costs (the capture "
                "and, on an arm, the move to it), so its remaining lights would be chosen "
                "otherwise and it would not be the session it began as. Nothing was recorded or "
                "captured. Put those settings back as the session began to continue it, or start "
                "a new session"
            )

    def _same_light(self, candidate: int, rec) -> bool:  # type: ignore[no-untyped-def]
        """Whether ``candidate`` is the light step ``rec`` recorded: the same LED (a dome) at
        the same position to within rounding."""
        from rti_rig.app.rig_identity import POSITION_TOLERANCE_RAD

        if self.plan.leds is not None and int(self.plan.leds[candidate]) != rec.led:
            return False
        angle = angle_between_deg(self.plan.candidates[candidate], rec.planned_direction)
        return float(np.radians(angle)) <= POSITION_TOLERANCE_RAD

    def _recorded_candidate(self, folder, i: int, rec) -> int:  # type: ignore[no-untyped-def]
        """The candidate of the light step ``i`` recorded, on the changed rig: a dome's LED by
        its index, an arm's direction by the nearest candidate. Refused when a dome's LED is no
        longer among the lights (its band), naming it."""
        if self.plan.leds is None:
            d = np.asarray(rec.planned_direction, dtype=np.float64)
            return int(np.argmax(self.plan.candidates @ d))
        where = np.flatnonzero(self.plan.leds == rec.led)
        if where.size == 0:
            raise RtiRigError(
                f"{shown_path(folder.root)}: step {i + 1} was shot with LED index {rec.led}, which "
                "the changed rig accepted with --accept-rig-change no longer offers this session "
                "(outside its elevation band, or gone). Nothing was recorded or captured. "
                f"Resume with the session's own config (rti-rig run --resume {folder.root}), "
                "or start a new session on the changed rig"
            )
        return int(where[0])

    def _keep_start_unused(self, folder, done: int) -> None:  # type: ignore[no-untyped-def]
        """Refuse a resume within the starting layout whose remaining starting lights, on the
        changed rig, include one already shot (the start is placed on the rig's positions, so
        a real move can place it on other LEDs): the session would shoot it twice."""
        rest = self.chooser.start[done:]
        twice = sorted(set(rest) & set(self.chooser.used))
        if twice:
            raise RtiRigError(
                f"{shown_path(folder.root)}: on the changed rig accepted with --accept-rig-change "
                "the starting layout is other LEDs, and one of its remaining lights was already "
                "shot (LED index "
                + ", ".join(str(self._step(c).led) for c in twice)
                + "). Nothing was recorded or captured. Resume with the session's own config "
                f"(rti-rig run --resume {folder.root}), or start a new session on the changed rig"
            )

    def _timing_differences(self, recorded: Any) -> list[str]:
        """On an arm, the times a decision weighs (capture, moves) that differ between the rig
        config ``recorded`` in the session's manifest (its first run's or its last run's) and
        this one, in words; empty if they agree, on a dome, or if they cannot be told. The rig
        identity leaves timing and motion out (they do not change the images), so a resume on
        a slowed arm got as far as re-deciding its steps and was refused as "another rig
        config", with "start a new session" as the remedy, where putting the speed back
        continues it."""
        from rti_rig.app.config import parse_rig_config

        if self._move is None or not isinstance(recorded, dict):
            # a dome's lights all cost one capture time: a time per second ranks them alike,
            # so another time cannot be why a dome's step is decided otherwise
            return []
        try:
            then = parse_rig_config(recorded, "manifest.json")
        except Exception:  # a manifest of another build: nothing to say beyond the refusal
            return []
        out: list[str] = []
        t = then.timing
        capture_then = t.light_switch_s + t.settle_s + then.camera.exposure_s + t.readout_s
        capture_then += t.transfer_s
        capture_now = self.chooser.capture_s
        if not np.isclose(capture_then, capture_now, rtol=1e-9, atol=1e-12):
            out.append(f"time per capture {capture_then:.2f} s → {capture_now:.2f} s: [timing]")
        if then.arm is not None:
            settings = _arm_motion_settings(SimpleNamespace(config=then))
            # as the decision saw it: from the last light, or from the park
            here = self.chooser.lights[-1] if self.chooser.lights else None
            now = self._move(here)
            start = here if here is not None else self._park
            before = np.array([move_time_s(start, d, settings) for d in self.plan.candidates])
            if now is not None and not np.allclose(before, now, rtol=1e-9, atol=1e-12):
                out.append(
                    f"arm moves, the longest from the last light {before.max():.1f} s → "
                    f"{now.max():.1f} s: [arm] speed, acceleration or settle time"
                )
        return out

    def conclude(self) -> dict[str, Any]:
        """The outcome (``AdaptiveChooser.conclude``), computed once: the controller asks for
        it before the session completes and records it; the CLI's summary reads it again."""
        if self._outcome is None:
            self._outcome = self.chooser.conclude()
        return self._outcome


def refuse_other_times(manifest: dict[str, Any], loaded: Any, root: Path) -> None:
    """Refuse, before the session folder is opened, a resume of an unfinished adaptive session
    on an arm whose config gives other times than its last run's: the time per capture, each
    joint's speed and acceleration, the settle time. Nothing is said of a complete session
    (nothing is left to choose), nor where that config is unknown (:func:`_last_run_config`);
    what else moves the move times (the joints' limits, the park) is left to the check of the
    move times themselves once the steps taken are replayed (``AdaptiveSteps.replay``), which
    refuses only what changes them.

    Why before: that check alone came after "differs … in nothing the images depend on" and
    "Resuming S: 7 of 16 images verified", two lines saying the resume was fine, and after the
    reopen had set aside any file it could not verify."""
    from rti_rig.app.config import parse_rig_config

    if (manifest.get("runner") or {}).get("finish_reason") == "completed":
        return
    recorded = _last_run_config(manifest)
    if loaded.config.arm is None or not isinstance(recorded, dict):
        return  # a dome's lights all cost one capture time: no time ranks them otherwise
    try:
        then = parse_rig_config(recorded, "manifest.json")
    except Exception:  # a manifest of another build: the replay's own check still holds
        return
    if then.arm is None:
        return
    now_said, then_said = _time_settings(loaded.config), _time_settings(then)
    changed = [
        f"{name} {then_said[(name, unit)]:g} → {value:g}{unit}"
        for (name, unit), value in now_said.items()
        if (name, unit) in then_said
        and not np.isclose(then_said[(name, unit)], value, rtol=1e-9, atol=1e-12)
    ]
    if changed:
        raise RtiRigError(
            f"{shown_path(root)}: the rig config gives other times than this session's last run "
            "(" + "; ".join(changed) + "). An adaptive session weighs each light by the time it "
            "costs (the capture and, on an arm, the move to it), so its remaining lights would "
            "be chosen otherwise and it would not be the session it began as. Nothing was read, "
            "recorded or captured. Put those settings back as the session began to continue it, "
            "or start a new session"
        )


def _time_settings(config: Any) -> dict[tuple[str, str], float]:
    """What an arm's decisions weigh as time, by the config's words and a unit: the capture
    ([timing] and [camera] exposure_s summed), and the motion: ``[arm] speed_deg_s`` and
    ``acceleration_deg_s2``, or each servo joint's speed and acceleration as its
    ``[arm.dynamixel]`` settings give them, and their settle time."""
    t = config.timing
    capture = t.light_switch_s + t.settle_s + config.camera.exposure_s + t.readout_s + t.transfer_s
    out = {("time per capture ([timing], [camera] exposure_s)", " s"): float(capture)}
    arm = config.arm
    if arm.dynamixel is None:
        out[("[arm] speed_deg_s", "")] = float(arm.speed_deg_s)
        out[("[arm] acceleration_deg_s2", "")] = float(arm.acceleration_deg_s2)
        return out
    servos = arm.dynamixel
    for joint in ("azimuth", "elevation"):
        j = getattr(servos, joint)
        said = f"[arm.dynamixel.{joint}]"
        out[(f"{said} speed (profile_velocity_rpm)", " °/s")] = float(j.joint_velocity_deg_s)
        out[(f"{said} acceleration (profile_acceleration_rev_min2)", " °/s²")] = float(
            j.joint_acceleration_deg_s2
        )
    out[("[arm.dynamixel] settle_time_s", " s")] = float(servos.settle_time_s)
    return out


def _last_run_config(manifest: dict[str, Any]) -> dict[str, Any] | None:
    """The rig config the session's last run read: recorded with each resume since
    2026-12-05; the first run's (the rig record) where the last run's config digest is the
    first's; None where an earlier resume ran on another config whose text was not recorded
    (its steps may stand on other times: the check cannot be made, and a resume that had gone
    on must still go on)."""
    first = (manifest.get("rig") or {}).get("config")
    runs = manifest.get("runs") or []
    if not runs:
        return first if isinstance(first, dict) else None
    last = runs[-1]
    if isinstance(last.get("config"), dict):
        return last["config"]
    if last.get("config_sha256") == runs[0].get("config_sha256") and isinstance(first, dict):
        return first
    return None


def places_against(value: float, target: float) -> int:
    """Decimal places (2 to 12) at which ``value`` printed stands on the same side of
    ``target`` as it does: an upper estimate of 0.3175° had been printed "0.32° ≤ --until-error
    0.318°", a comparison the reader sees is false. The stop records its figure at these
    places where they are more than 4 (:meth:`stop_terms`)."""
    for places in range(2, 12):
        shown = float(f"{value:.{places}f}")
        if (shown <= target) == (value <= target):
            return places
    return 12


def _decided_on_another_rig(folder, done: int) -> int:  # type: ignore[no-untyped-def]
    """How many of the steps already taken were decided on a rig other than this one: all of
    them when this resume accepts a change (``--accept-rig-change``), else those taken before
    the last resume that accepted one (its run records ``rig_change`` and the steps it found
    done), else none."""
    if getattr(folder, "rig_change", None):
        return done
    runs = (getattr(folder, "manifest", None) or {}).get("runs") or []
    changed = [int(r.get("resumed_with_steps_done") or 0) for r in runs if r.get("rig_change")]
    return min(max(changed, default=0), done)


def estimate_phrase(result: dict[str, Any], reason: str = "") -> str:
    """The result's estimates in words, for the final message: the point estimate and the
    upper one, with the factor between them — said to be what --until-error was compared with
    only when the session had a target. ``reason`` is the stop's reason printed before it:
    a figure it already gives is not given again ("" when it gives both), as the summary line
    had said the upper estimate twice, once in the reason and once after it."""
    est = result.get("estimated_error_deg")
    if est is None:
        return "estimated mean normal error n/a"
    up = result.get("upper_error_deg")
    text = f"estimated mean normal error {est:.2f}°"
    if up is None:
        return text
    factor = result.get("upper_factor", up / est if est else 0)
    plus = unsolved_words(result)
    if result.get("until_error_deg") is not None:
        role = ": what --until-error is compared with"
    elif result.get("objective", "normals") == "normals":
        role = ": what --until-error would be compared with"
    else:  # --until-error goes with normals only: a relight session is never compared
        role = ""
    # the reason prints them at the places that keep the target's side (places_against)
    target = result.get("until_error_deg")
    places = 2 if target is None else places_against(up, float(target))
    upper_said = f"upper estimate {up:.{places}f}°" in reason
    if upper_said and f"estimate {est:.{places}f}° ×" in reason:
        return ""  # the reason gives both figures and the factor
    if misfit_decides(float(est), factor, result.get("misfit_deg")):
        # the upper estimate is not ×factor of the point estimate: say what it is
        first = first_term_words(result)
        if upper_said:
            return f"{text} (the upper estimate is {first}{plus}{role})"
        return f"{text}, upper estimate {up:.2f}° ({first}{plus}{role})"
    if upper_said:
        return f"{text} (the upper estimate is ×{factor:g} of it{plus}{role})"
    return f"{text}, upper estimate {up:.2f}° (×{factor:g}{plus}{role})"


def first_term_words(terms: dict[str, Any], places: int = 2) -> str:
    """The upper estimate's first term in words: the point estimate × its factor, or, when the
    images' misfit bound is the larger (``planner.adaptive_until.misfit_decides``), that
    bound, with the estimate it exceeds — said, so that an upper estimate far above factor ×
    estimate is read for what it is (pixels the fit does not explain, not a misprint)."""
    est = float(terms["estimated_error_deg"])
    factor = float(terms.get("upper_factor") or adaptive_until.UPPER_FACTOR)
    misfit = terms.get("misfit_deg")
    simulated = f"estimate {est:.{places}f}° × {factor:g}"
    if not misfit_decides(est, factor, misfit):
        return simulated
    return (
        f"misfit bound {float(misfit):.{places}f}° of pixels the fit does not explain, above "
        f"the {simulated}"
    )


def unsolved_words(terms: dict[str, Any]) -> str:
    """The upper estimate's unsolved term in words, to follow its factor ("" when no pixel is
    unsolved): said, so that an upper estimate far above factor × estimate is read for what
    it is (pixels no image determines yet) and not as a misprint."""
    share, each = terms.get("unsolved_fraction"), terms.get("unsolved_deg")
    if not share or not each:  # none unsolved, or a session weighing them at 0°: no term
        return ""
    # a share under 0.1 % to two significant digits: "0.0 %" had read as none
    percent = f"{100 * share:.1f}" if share >= 0.001 else f"{100 * share:.2g}"
    return f" + {percent} % of pixels unsolved × {each:g}°"


#: The fewest lights `rti-rig fit` writes each relighting file from (the file, its model, the
#: lights: a PTM's coefficients; an HSH of order 1 once its held-out error can be measured:
#: rti_rig.app.usecases.fit_rti_order), read from ``core.fit_minimums``. Words of a note, never
#: of a decision: a resume does not compare it (``adaptive_constants.ADVICE_ONLY``).
RTI_FILE_LIGHTS = (
    ("fit.ptm", "a PTM", fit_minimums.FIT_MINIMUMS.ptm),
    ("fit.rti", "an HSH fit", fit_rti_order.HSH_FEWEST_LIGHTS),
)


def header_band(header: dict[str, Any]) -> tuple[float, float]:
    """The elevation band an adaptive session's manifest header records; every elevation for
    a session begun before adaptive sessions took a band (the keys absent)."""
    lo, hi = header.get("min_elevation_deg"), header.get("max_elevation_deg")
    return (
        _FULL_BAND[0] if lo is None else float(lo),
        _FULL_BAND[1] if hi is None else float(hi),
    )


def claim_caveat(
    result: dict[str, Any],
    band: tuple[float, float],
    lamps: dict[str, Any] | None = None,
    simulated: bool = False,
    replay: bool = False,
) -> str | None:
    """What a claimed ``--until-error`` target does not cover (None: nothing claimed).
    ``lamps``: the lamp geometry the estimate rendered (None: distant lamps); ``simulated``:
    the rig's scene is rendered (its lamps are its scene's: no ``[lamps]`` to advise);
    ``replay``: the rig is a recorded acquisition's ``.lp``, which has no config to give
    ``[lamps]`` in (the advice to give it could not be followed: QA, 2026-12-06).

    Why: the upper estimate is calibrated on the simulator's scenes at 96 px, under directional
    lights, over every elevation. Through the front door on the shipped rigs
    (``python -m benchmarks.until_error_configs``, docs/adaptive.md "The stop's claim on the
    shipped rigs"), with the unsolved pixels counted, the claim held on the simulated dome
    under every band tried, but the arm's lamps at 400 mm measured 2.7× its upper estimate
    until the estimate rendered them (:class:`rti_rig.planner.adaptive_bias.NearLamps`; then
    no claim broke over every elevation), and a ceiling of 15° on the arm 1.8–3.3× (pixels a cast
    shadow darkens in some lights, kept by the fit) until the upper estimate weighed the images'
    misfit bound (then no claim broke, and none at 1.5° or 0.8° was made under 15° on the
    arm): said with the claim, since a band no calibration covered may hold what neither term
    sees."""
    if not result.get("target_claimed"):
        return None
    lo, hi = band
    banded = (
        f"this band ({lo:g}°–{hi:g}°) was never calibrated: under a ceiling of 15° the "
        "simulated arm had measured up to 3.3× an upper estimate from its object model alone "
        "(cast shadows the fit keeps, which the upper estimate now bounds from the images' "
        "residuals); "
        if (lo, hi) != _FULL_BAND
        else ""
    )
    if lamps is None and simulated:
        near = "its scene's lights are directional, as the estimate assumes"
    elif lamps is None:
        near = (
            "it assumes lamps far from the object (a fit reads each light as one direction: "
            "the simulated arm's lamps at 400 mm had measured 2.7× an estimate that assumed "
            "so); "
            + (
                "a recorded acquisition's .lp gives no lamp distance to render, so lamps a few "
                "field-widths from the object are not in the estimate"
                if replay
                else "give the config's [lamps] distance_mm and field_width_mm for the "
                "estimate to render yours"
            )
        )
    else:
        near = (
            f"it renders the lamps as points {lamps['distance_mm']:g} mm away over a "
            f"{lamps['field_width_mm']:g} mm field, as the rig's config or scene gives them "
            "(the estimate is only as right as those two figures)"
        )
    return (
        "the target is claimed on an estimate calibrated under directional lights over every "
        f"elevation: {banded}{near}. Check the normals on an object you know before relying on "
        'the figure (docs/adaptive.md, "The stop\'s claim on the shipped rigs")'
    )


def few_lights_note(
    result: dict[str, Any], start_with: Callable[[int], str] | None = None
) -> str | None:
    """What a session whose --until-error target was reached before it had the lights of an
    RTI file gives and does not give, and how to ask for more (None: nothing to say — no
    target, not reached, or lights enough). The target is a normal error; a user who came for
    a PTM or an .rti learns it here, not when `fit` skips them. The advice never exceeds the
    session's maximum (``--lights`` or the rig's lights). A minimum asked for is no reason to
    be silent: one below an RTI file's lights (``--min-lights 4``, below the 4 starting lights
    that a loose target stops at) had silenced the note of a session with no RTI file.

    ``start_with(m)``: the ``rti-rig run`` command that starts that session with
    ``--min-lights m`` (the rig config, this session's options, a free --out), said last so it
    pastes whole; "start a session with --min-lights 6" had left the rest to find."""
    used = int(result.get("lights_used") or 0)
    if not result.get("target_claimed"):
        return None
    # what the fit makes of them, from the rules the fit applies (the lights an adaptive
    # session chooses determine a normal: it refuses --allow-no-normals)
    auto = fit_minimums.AutoFit(used, normals_determined=True)
    made = {"fit.ptm": auto.ptm, "fit.rti": auto.rti}
    short = [(name, what, n) for name, what, n in RTI_FILE_LIGHTS if not made[name]]
    if not short:
        return None
    needs = " and ".join(f"{what} needs {n}" for _, what, n in short)
    files = " and ".join(name for name, _, _ in short)
    makes = (
        f"will write the normal map without {files}"
        if auto.normal_map
        else f"with its default --model auto will write nothing ({auto.least} lights are its "
        "fewest); `rti-rig fit --model ps` writes the normal map"
    )
    text = f"{used} lights reached the normal-error target, but {needs}: `rti-rig fit` {makes}."
    cap = int(result.get("max_lights") or 0)
    reachable = [(name, n) for name, _, n in short if n <= cap]
    beyond = [name for name, _, n in short if n > cap]
    if beyond:
        verb = "needs" if len(beyond) == 1 else "need"
        text += (
            f" {' and '.join(beyond)} {verb} more than this session's maximum of {cap} lights "
            "(--lights, or the lights the rig offers)."
        )
    if reachable:
        names = " and ".join(name for name, _ in reachable)
        fewest = max(n for _, n in reachable)
        text += f" To get {names}, start a session with --min-lights {fewest}"
        text += f": {start_with(fewest)}" if start_with is not None else "."
    return text


def short_of_target_note(
    result: dict[str, Any],
    offered: int,
    start_more: Callable[[], str] | None = None,
    most: int | None = None,
) -> str | None:
    """What a session that ran to its maximum without reaching its --until-error target is
    to do next (None: no target, the target reached, or the session stopped otherwise).

    ``offered``: the lights the session could choose from (the rig's, in its band);
    ``start_more()``: the ``rti-rig run`` command that starts the session again without its
    ``--lights`` (the rig's own maximum, a free --out). Why: the run ended "the target is not
    claimed" and nothing more: a user who wanted the target had to find that a resume keeps
    the session's maximum, and which command shoots on; where the rig has no more lights,
    no command would, and that is said instead of leaving one to be tried.

    ``most``: the largest maximum any session on the rig takes (an arm's
    :data:`ARM_MAX_LIGHTS`; None: every light offered). Why: the virtual arm offers 120
    lights, an arm's session stops at 100, and a 100-light session short of its target had been
    told a new session would shoot "up to the 120 lights" (it stops at 100 again)."""
    until = result.get("until_error_deg")
    if until is None or result.get("target_claimed"):
        return None
    used, cap = int(result.get("lights_used") or 0), int(result.get("max_lights") or 0)
    up = result.get("upper_error_deg")
    if used < cap or up is None:  # stopped otherwise (nothing left to fit, no estimate)
        return None
    text = (
        f"--until-error {until:g}° was not reached in this session's maximum of {cap} lights "
        f"(upper estimate {up:.2f}°); its {used} images are kept as they are."
    )
    distant = result.get("distant_lamps_estimate_deg")
    if distant is not None:
        would = adaptive_until.upper_error_deg(
            float(distant),
            result.get("upper_factor"),
            float(result.get("unsolved_fraction") or 0.0),
            result.get("unsolved_deg"),
            result.get("misfit_deg"),
        )
        text += (
            f" Under lamps far from the object the same images would estimate {distant:.2f}° "
            f"(upper {would:.2f}°): "
            + (
                "the lamps' nearness is what keeps the target out of reach, and more lights "
                "reduce it slowly (a fit reads one direction per light: a bias, not noise; on "
                "the shipped simulated arm the estimate was 1.16° at 4 lights and still 0.88° at "
                '100; docs/adaptive.md, "Lamps near the object").'
                if would <= until
                else "the lamps' nearness is part of the gap, not all of it."
                if would < float(up) - 0.005
                else "the lamps' nearness is not what keeps the target out of reach."
            )
        )
    reach = offered if most is None else min(offered, most)
    if cap < reach and start_more is not None:
        text += (
            " The session is complete (a resume adds no light); to shoot toward the target "
            f"with up to the {reach} lights a session on this rig can take, start a new "
            "session (it shoots its lights from the start; more lights are not known to reach "
            f"it): {start_more()}"
        )
    elif cap >= reach:
        every = (
            f"every light this rig offers here ({offered})"
            if reach == offered
            else f"the most a session on this rig takes ({reach} of the {offered} it offers)"
        )
        text += f" They are {every}: no session on it can shoot more toward the target."
    return text


def check_objective(
    objective: str,
    lights: int | None,
    until_error_deg: float | None,
    run: str = "rti-rig run",
    count: int = fit_minimums.PLAN_DEFAULT_LIGHTS,
    band: tuple[float, float] = _FULL_BAND,
    in_band: int | None = None,
) -> None:
    """Refuse an objective the adaptive session cannot serve, before anything is opened.

    ``relight`` chooses the *design* of N lights by its simulated relighting PSNR, so it needs
    ``--lights N``; ``--until-error`` is a criterion on the estimated mean *normal* error (the
    only error the session estimates and that is calibrated against measured error), so it is
    refused with ``relight`` rather than given a relighting meaning nobody calibrated.

    The way out is a whole command: ``run`` (:func:`run_words`, the rig config and the run's
    own ``--out``) with ``count`` lights, the count the rig takes in ``band``
    (:func:`hint_count`): "--lights 12, say" was refused on a dome of fewer LEDs in the band,
    and a bare option left the rest of the command to find. ``in_band``: a dome's LEDs in
    ``band`` (None on an arm); a band holding fewer than ``count`` gets no command, which
    pasted would be refused for that band in turn: the refusal says so instead."""
    if objective not in OBJECTIVES:
        raise RtiRigError(
            f"--objective {objective}: an adaptive session chooses its lights for "
            f"{' or '.join(OBJECTIVES)}"
        )
    if objective != "relight":
        return
    counted = f"{run} {adaptive_options(None, lights or count, None, objective)}"
    counted += band_options(band)
    if in_band is not None and in_band < (lights or count):
        counted = (
            f"--lights, in a band holding that many of the dome's LEDs (the band asked holds "
            f"{in_band})"
        )
    if until_error_deg is not None:
        raise RtiRigError(
            "--until-error goes with --objective normals only: it stops on the estimated mean "
            "normal error, which a session chosen for relighting does not aim at (no relighting "
            f"error estimate is calibrated). Give --objective relight a count: {counted} (or "
            "drop --objective for --until-error)"
        )
    if lights is None:
        raise RtiRigError(
            "--objective relight chooses a design of a given number of lights by its simulated "
            f"relighting: give the count with --lights: {counted}"
        )


def hint_count(geometry: object, band: tuple[float, float]) -> int:
    """The ``--lights`` an adaptive hint gives: what a plan's hint gives on this rig in
    ``band`` (:func:`~rti_rig.core.rig_geometry.hint_light_count`: 12, or a dome's LEDs in the
    band), at least one more than the starting layout (an adaptive session's fewest)."""
    from rti_rig.core.rig_geometry import hint_light_count

    return max(START_LIGHTS + 1, hint_light_count(geometry, *band))


def check_until_error(until_error_deg: float | None) -> None:
    """Refuse an ``--until-error`` that is no angle above 0° and below 90° (before anything
    opens). Why below 90°: every pixel the camera sees faces it within 90°, so a normal map
    that says nothing (each normal at the camera) errs by less; a target of 200° had been
    "claimed" at the starting lights, as `bench tradeoff --target-deg` already refused."""
    if until_error_deg is not None and not (0.0 < until_error_deg < 90.0):  # NaN fails both
        raise RtiRigError(
            f"--until-error {until_error_deg:g}: give the target as a finite positive angle in "
            "degrees, below 90 (a normal map that says nothing errs by less): the mean normal "
            "error to stop at, such as 2"
        )


def check_min_lights(
    min_lights: int | None,
    lights: int | None,
    until_error_deg: float | None,
    run: str = "rti-rig run",
    band: tuple[float, float] = _FULL_BAND,
) -> None:
    """Refuse a --min-lights that cannot mean anything, before anything is opened: it bounds
    the --until-error stop from below, so it needs --until-error and must not exceed
    --lights.

    ``run``: the advised command's start (:func:`run_words`); without ``--until-error`` or
    ``--lights`` the advice is that command with the guide's target
    (:data:`HINT_UNTIL_ERROR_DEG`): "add --until-error DEG" pasted was refused as no number."""
    if min_lights is None:
        return
    if min_lights < 1:
        raise RtiRigError(f"--min-lights {min_lights}: give a positive number of lights")
    if until_error_deg is None:
        # what the session does without it is said for what the user gave (an advice naming
        # --lights to a user who gave none had read as an option they had given)
        target = adaptive_options(HINT_UNTIL_ERROR_DEG, None, min_lights) + band_options(band)
        without = (
            f"with --lights {lights} alone the session shoots {lights} lights"
            if lights is not None
            # the command last: printed before ", or leave", its last word read "6," selected
            # to the comma, which pasted was refused as no whole number
            else "leave --min-lights out, or add --until-error (the target the stop claims, in "
            f"degrees; {HINT_UNTIL_ERROR_DEG:g} as the guide shows): {run} {target}"
        )
        raise RtiRigError(
            f"--min-lights {min_lights} goes with --until-error (it is the fewest lights the "
            f"stop may claim the target at); {without}"
        )
    if lights is not None and min_lights > lights:
        raise RtiRigError(
            f"--min-lights {min_lights} is above --lights {lights}, the session's maximum: "
            "give a minimum at most the maximum"
        )


def _check_min_within(
    min_lights: int,
    offered: int,
    band: tuple[float, float],
    advice: Callable[[int], str],
) -> None:
    """``--min-lights M`` above what the rig offers (in the band) is refused; ``advice(M)``:
    what follows "give at most …", the band that would hold M (a dome's,
    :func:`_widen_to_hold`; an arm's, :func:`_arm_widen_to_hold`), asked only when the request
    is refused."""
    if min_lights > offered:
        widen = advice(min_lights)
        raise RtiRigError(
            f"--min-lights {min_lights}: this rig offers {offered} lights{_band_words(band)} "
            f"an adaptive session can use; give at most {offered}{widen}"
        )


def _widen_to_hold(need: int, band: tuple[float, float], el: NDArray[np.float64]) -> str:
    """`` (or widen the band to hold N: --max-elevation-deg C)`` for a band asked for, where a
    dome's LED elevations ``el`` (°) say which would (an arm's refusal words its own,
    :func:`_arm_widen_to_hold`); nothing over every elevation. Why: "widen
    --min/--max-elevation-deg" gave no value."""
    if tuple(band) == _FULL_BAND:
        return ""
    wider = _band_holding(el, need, band)
    if wider is None:  # the dome has fewer LEDs in all: no band holds them
        return ""
    return f" (or widen the band to hold {need}:{band_options(wider)})"


def _band_words(band: tuple[float, float]) -> str:
    """`` between 0° and 45° elevation`` for a band asked for; nothing for every elevation."""
    if tuple(band) == _FULL_BAND:
        return ""
    return f" between {band[0]:g}° and {band[1]:g}° elevation"


def _check_lights_within(
    lights: int | None,
    offered: int,
    band: tuple[float, float],
    advice: Callable[[int], str],
) -> None:
    """``--lights N`` above what the rig offers is refused, as a planned session's is (it was
    capped without a word: 100 asked of a 48-LED dome ran 48); ``advice`` as
    :func:`_check_min_within`'s."""
    if lights is not None and lights > offered:
        widen = advice(lights)
        raise RtiRigError(
            f"--lights {lights}: this rig offers {offered} lights{_band_words(band)} an "
            f"adaptive session can use; give at most {offered}{widen}"
        )


@dataclass(frozen=True)
class NothingToChoose:
    """Why a dome offers an adaptive session nothing to choose, and what would hold it: the
    facts :func:`_nothing_to_choose` decides and :func:`_nothing_to_choose_words` words.

    Why apart: one function had both decided and worded the refusal and its two ways out
    (the band that holds the session, the planned run of the band's lights), so what was
    advised could be read only from the sentence it was in."""

    #: The lights the band holds (no more than the starting layout's).
    offered: int
    band: tuple[float, float]
    #: The dome's LED elevations (°).
    elevations: NDArray[np.float64]
    #: The lights this session needs, and the option that asked for them (None: an adaptive
    #: session's own minimum, one more than its start).
    need: int
    need_from: str | None
    #: What the advised band is to hold: ``need``, or the dome's every LED where it has fewer.
    hold: int
    #: The band nearest ``band`` that holds ``hold`` (None: none to advise).
    wider: tuple[float, float] | None
    #: The ``--lights``/``--min-lights`` the advised command keeps (what a session can take).
    advised_lights: int | None
    advised_min_lights: int | None


def _nothing_to_choose(
    elevations: NDArray[np.float64],
    offered: int,
    lights: int | None,
    until_error_deg: float | None,
    band: tuple[float, float],
    min_lights: int | None,
) -> NothingToChoose | None:
    """What leaves an adaptive session nothing to choose on a dome whose LEDs are at
    ``elevations`` (°), ``offered`` of them in ``band``; None where there is something.

    ``--until-error`` alone is kept where its estimate can say whether these lights reach the
    target (3 lights or more: photometric stereo's); with fewer it could judge nothing (a
    1-light session ran, "the target is not claimed"). The advised ``--lights``/
    ``--min-lights`` are what a session can take: at least 5 (a ``--lights 4`` kept was
    refused "give at least 5") and at most the dome's LEDs (``--lights 14`` of a 12-LED dome
    was left with no command)."""
    if offered > START_LIGHTS:
        return None
    if lights is None and until_error_deg is not None and offered >= fit_minimums.NORMAL_MIN_LIGHTS:
        return None
    need = max(START_LIGHTS + 1, lights or 0, min_lights or 0)
    # the option that asked for more than an adaptive session's own minimum, if one did
    need_from = None if need == START_LIGHTS + 1 else "lights" if need == lights else "min-lights"
    # what the advised band is to hold: no band holds more than the dome's LEDs (a --lights 14
    # on a 12-LED dome had been left with no command, or only a test shot of the band's one)
    hold = min(need, len(elevations))
    wider = _band_holding(elevations, hold, band) if hold > START_LIGHTS else None
    return NothingToChoose(
        offered=offered,
        band=band,
        elevations=elevations,
        need=need,
        need_from=need_from,
        hold=hold,
        wider=wider,
        # a --lights 4 kept as given was refused: "give at least 5"
        advised_lights=None if lights is None else min(max(lights, START_LIGHTS + 1), hold),
        advised_min_lights=None if min_lights is None else min(min_lights, hold),
    )


def _nothing_to_choose_words(
    facts: NothingToChoose,
    config: str,
    until_error_deg: float | None,
    objective: str,
    out: str = "DIR",
) -> str:
    """The refusal of ``facts``, with its ways out as commands of the user's own options
    (``config``: the rig config, ``out``: the run's own ``--out``, nothing written to it yet,
    both quoted for a shell; ``--out DIR`` had been printed, which pasted ran into a folder
    named DIR).

    The advice is the band that holds the session (:func:`_band_holding`), and the planned
    run of the band's lights as the other way: the planned run alone had been advised,
    ``--lights 1`` on the Nab dome below 20°, a session no fit can use."""
    offered, band, el, need = facts.offered, facts.band, facts.elevations, facts.need
    noun = "light" if offered == 1 else "lights"
    session = (
        f"an adaptive session needs at least {need}"
        if facts.need_from is None
        else f"this adaptive session (--{facts.need_from} {need}) needs {need}"
    )
    words = [
        f"this rig offers {offered} {noun}{_band_words(band)} (its {len(el)} LEDs are at "
        f"{el.min():.1f}°–{el.max():.1f}° elevation), and {session}: it starts from "
        f"{START_LIGHTS} and chooses the next ones: there is none left to choose here"
    ]
    wider = facts.wider
    if wider is not None:
        asked = adaptive_options(
            until_error_deg,
            facts.advised_lights,
            facts.advised_min_lights,
            objective,  # kept, as an arm's advice keeps it ('relight' had become the default)
        )
        lead = (
            f"Widen the band to hold {need}"
            if facts.hold == need
            else f"No band holds {need} (the dome has {len(el)} LEDs): ask for {facts.hold} in "
            "one that holds them"
        )
        words.append(
            f"{lead}: rti-rig run {config} --out {out} {asked}"
            f"{band_options(wider)} ({_held(el, wider)} lights"
            f"{_band_words(wider) or ' at every elevation'})"
        )
    if offered:
        # the band's lights (the bare `rti-rig run RIG --out DIR` fires every LED, those the
        # band keeps out above a gilded object's ceiling too)
        in_band = "" if tuple(band) == _FULL_BAND else " " + band_run_options(offered, *band)
        caveat = (
            f" (a test shot only: normals need {fit_minimums.NORMAL_MIN_LIGHTS} lights)"
            if offered < fit_minimums.NORMAL_MIN_LIGHTS
            else ""
        )
        them = "it" if offered == 1 else f"its {offered}"
        shoot = (
            f"shoot {them} with a planned run"
            if wider is not None
            else "Shoot them all with a planned run"
        )
        words.append(f"{shoot}: rti-rig run {config} --out {out}{in_band}{caveat}")
    return ". ".join(words[:2]) + "".join(f"; or {w}" for w in words[2:])


def _refuse_nothing_to_choose(  # type: ignore[no-untyped-def]
    loaded,
    offered: int,
    lights: int | None,
    until_error_deg: float | None,
    band: tuple[float, float] = _FULL_BAND,
    min_lights: int | None = None,
    objective: str = "normals",
    out_dir: Path | None = None,
) -> None:
    """Refuse ``--adaptive`` (or ``--lights N`` with it) on a rig offering no more lights than
    the starting layout: there is nothing left to choose (``out_dir``: the run's ``--out``, for
    the commands it advises). ``--lights 4`` was refused with "give
    at least 5" and ``--lights 5`` with "give at most 4", sending the user round in a circle,
    while ``--adaptive`` alone ran the lights as a planned run would, labelled adaptive.
    Decided by :func:`_nothing_to_choose`, worded by :func:`_nothing_to_choose_words`."""
    if offered > START_LIGHTS:
        return  # before the rig's geometry is read: most rigs offer more
    from rti_rig.app.config import rig_geometry

    _, el = az_el_from_direction(rig_geometry(loaded).directions)
    facts = _nothing_to_choose(el, offered, lights, until_error_deg, band, min_lights)
    if facts is not None:
        config = shell_word(str(loaded.path))
        out = "DIR" if out_dir is None else shell_word(str(out_dir))
        raise RtiRigError(_nothing_to_choose_words(facts, config, until_error_deg, objective, out))


def _held(el: NDArray[np.float64], band: tuple[float, float]) -> int:
    """How many of the elevations ``el`` (°) ``band`` holds, as :func:`candidates_for` counts."""
    return int(in_band(el, band[0], band[1]).sum())


def _band_holding(
    el: NDArray[np.float64], need: int, band: tuple[float, float]
) -> tuple[float, float] | None:
    """The band nearest ``band`` (whole degrees) that holds ``need`` of the LEDs at elevations
    ``el``: its ceiling raised (the floor kept), else its floor lowered (the ceiling kept), else
    every elevation; None when the dome has fewer than ``need`` LEDs."""
    lo, hi = band
    above = np.sort(el[el >= lo - 1e-9])
    if hi < 90.0 and len(above) >= need:
        ceiling = min(90.0, float(np.ceil(above[need - 1] - 1e-9)))
        return lo, ceiling
    below = np.sort(el[el <= hi + 1e-9])[::-1]
    if lo > 0.0 and len(below) >= need:
        return float(np.floor(below[need - 1] + 1e-9)), hi
    if len(el) >= need:
        return _FULL_BAND
    return None


def _arm_candidates(  # type: ignore[no-untyped-def]
    rig, geometry: ArmGeometry, band: tuple[float, float]
) -> NDArray[np.float64]:
    """An arm's candidate directions in ``band`` that its rig's own lighting rules accept:
    the lights an adaptive session on it chooses from (:func:`adaptive_plan`)."""
    from rti_rig.planner.uniform import arm_below

    dirs = candidates_for(arm_below(geometry, band[1]), band[0]).directions
    ok = [rig.lighting.problem(LightStep(tuple(d))) is None for d in dirs]
    return dirs[np.asarray(ok, dtype=bool)]


def _arm_widen_to_hold(  # type: ignore[no-untyped-def]
    rig,
    loaded,
    need: int,
    offered: int,
    band: tuple[float, float],
    asked: Callable[[int], str],
    out_dir: Path | None = None,
) -> str:
    """The advice after "give at most ``offered``" for an arm asked ``need`` lights in
    ``band``: the band widened to hold them where one would (its ceiling raised to the top,
    else its floor lowered to 0, else every elevation: counted with the rig's own rules), else
    why none would and the working command, ``asked(offered)`` being the session's options with
    ``offered`` in place of the count refused.

    Why: the dome's refusal names the band that holds the session; an arm's said "widen
    --min/--max-elevation-deg" with no value, and a wider band holds no more lights on an arm:
    its candidates are :data:`ARM_CANDIDATES` directions spread over whatever band is asked,
    so widening only spreads them further apart (the virtual arm offers 120 below 30° and 120
    at every elevation)."""
    lo, hi = band
    tried: list[tuple[float, float]] = []
    for wider in ((lo, 90.0), (0.0, hi), _FULL_BAND):
        if wider == tuple(band) or wider in tried:
            continue
        tried.append(wider)
        try:
            held = len(_arm_candidates(rig, rig.geometry, wider))
        except RtiRigError:  # a band the arm cannot light at all
            continue
        if held >= need:
            return f" (or widen the band to hold {need}:{band_options(wider)})"
    config = shell_word(str(loaded.path))
    out = "DIR" if out_dir is None else shell_word(str(out_dir))  # the run's own --out
    widening = "; a wider band holds no more on this arm" if tuple(band) != _FULL_BAND else ""
    return (
        f"{widening} (an arm's lights are its {ARM_CANDIDATES} candidate directions spread over "
        f"the band asked, {offered} of them within its reach and lighting rules): rti-rig run "
        f"{config} --out {out} {asked(offered)}{band_options(band)}"
    )


def _check_lights_range(
    lights: int | None,
    until_error_deg: float | None,
    leds: int | None,
    band: tuple[float, float] = _FULL_BAND,
    el: NDArray[np.float64] | None = None,
) -> None:
    """Refuse an adaptive ``--lights N`` no session can take, with the range it can: at least
    one more than the start, at most a dome's LEDs (``leds``; an arm's are known later, from
    its rig, :func:`_check_lights_within`), before any refusal advises a command.

    Why: a band too narrow was refused first, repeating the N asked ("this adaptive session
    (--lights 14) needs 14") and advising another count in its command, so the user learnt
    only from the advice that their own --lights was out of range, and not what range was.

    With a band (``band``, the dome's LED elevations ``el``) that holds fewer than the count
    advised, the advice gives a band that holds it: "give at most 12" had been said under
    ``--max-elevation-deg 20`` (1 LED), and ``--lights 12`` was then refused for the band,
    the user refused twice (QA, 2026-12-06)."""
    if lights is None:
        return
    top = leds if leds is not None and leds > START_LIGHTS else None
    if lights > START_LIGHTS and (top is None or lights <= top):
        return
    # the options as given, worded as every adaptive refusal words them (this one had built
    # its own, "--until-error … --lights 4", without the target the user gave)
    asked = adaptive_options(until_error_deg, lights, None)
    if top is None:
        raise RtiRigError(
            f"{asked}: an adaptive session starts from {START_LIGHTS} lights "
            f"and chooses from there; give at least {START_LIGHTS + 1}"
        )
    advised = START_LIGHTS + 1 if lights <= START_LIGHTS else top
    wider = (
        _band_holding(el, advised, band)
        if el is not None and tuple(band) != _FULL_BAND and _held(el, band) < advised
        else None
    )
    raise RtiRigError(
        f"{asked}: an adaptive session on this dome takes {START_LIGHTS + 1} to {top} lights "
        f"(it starts from {START_LIGHTS} and chooses the next ones from the dome's {top} LEDs): "
        + (f"give at least {advised}" if lights <= START_LIGHTS else f"give at most {advised}")
        + (
            ""
            if wider is None
            else f", in a band that holds {advised} (this one{_band_words(band)} holds "
            f"{_held(el, band)}):"  # type: ignore[arg-type]
            + (
                band_options(wider)
                if tuple(wider) != _FULL_BAND
                else " every elevation (drop --min-elevation-deg and --max-elevation-deg)"
            )
        )
    )


def open_adaptive_session(  # type: ignore[no-untyped-def]
    loaded,
    out_dir: Path,
    lights: int | None,
    until_error_deg: float | None,
    objective: str = "normals",
    min_lights: int | None = None,
    band: tuple[float, float] = _FULL_BAND,
    check_room: Callable[[int, int], None] | None = None,
):
    """Check the request and the folder, open the rig, plan the start, make the folder
    (``band``: the elevations every light is chosen between, :func:`adaptive_plan`).

    ``check_room``: called with the images the session is sure to take and its most
    (:func:`images_before_rig`) once the request and the folder pass, before the rig is built;
    it raises to refuse the session (the disk cannot hold them).

    Returns (rig, starting schedule, folder, step source); the rig is closed if anything after
    opening it fails.
    """
    from rti_rig.app.compose import build_rig
    from rti_rig.runtime.controller import validate_schedule
    from rti_rig.runtime.session import SessionFolder

    check_until_error(until_error_deg)
    from rti_rig.app.config import rig_geometry

    geometry = rig_geometry(loaded)
    # the options on their own first: a refusal below advises a command that repeats them, and
    # one that repeated '--until-error 3 --objective relight' (or '--objective foo') was refused
    # in turn when pasted
    run = run_words(loaded.path, out_dir)
    in_band = (
        _held(az_el_from_direction(geometry.directions)[1], band)
        if isinstance(geometry, DomeGeometry)
        else None
    )
    # the config's default_lights is the count --adaptive alone designs for (adaptive_plan):
    # --objective relight had been told to "give the count with --lights" where it is known
    counted = lights if lights is not None else default_max_lights(loaded, until_error_deg)
    check_objective(
        objective, counted, until_error_deg, run, hint_count(geometry, band), band, in_band
    )
    check_min_lights(min_lights, lights, until_error_deg, run, band)
    offered: int | None = None
    elevations: NDArray[np.float64] | None = None  # a dome's LEDs' (°)
    if isinstance(geometry, DomeGeometry):  # a dome's lights are known from its config: before
        # counted as candidates_for counts, but a band holding none is refused with a band
        # that holds the session (it had been "widen --min-elevation-deg /
        # --max-elevation-deg", with no value that would do)
        elevations = az_el_from_direction(geometry.directions)[1]
        offered = _held(elevations, band)
        if len(elevations) <= START_LIGHTS:  # no --lights would do: one refusal, no circle
            _refuse_nothing_to_choose(
                loaded, offered, lights, until_error_deg, band, min_lights, objective, out_dir
            )
    _check_lights_range(
        lights, until_error_deg, None if elevations is None else len(elevations), band, elevations
    )
    if offered is not None:  # --lights N is one a session can take: a band advised keeps it
        _refuse_nothing_to_choose(
            loaded, offered, lights, until_error_deg, band, min_lights, objective, out_dir
        )
    if offered is not None and elevations is not None:  # a dome's (an arm's are known later)
        dome_el = elevations

        def held_by(need: int) -> str:
            return _widen_to_hold(need, band, dome_el)

        _check_lights_within(lights, offered, band, held_by)
        if min_lights is not None:
            _check_min_within(min_lights, offered, band, held_by)
    SessionFolder.check_new(out_dir)
    if check_room is not None:  # the disk, before the rig is built (as a planned run's)
        check_room(*images_before_rig(loaded, offered, lights, until_error_deg, min_lights, band))
    warm_up_fit()  # the robust kernel loaded (or compiled) now, not after the fourth light
    rig = build_rig(loaded)
    try:
        plan = adaptive_plan(
            rig,
            lights,
            objective=objective,
            band=band,
            default_max=None if lights is not None else default_max_lights(loaded, until_error_deg),
        )
        if (
            min_lights is not None
            and min_lights > plan.max_lights
            and plan.max_lights < len(plan.candidates)
        ):
            # a minimum the session's own maximum cannot reach though the rig offers more (an
            # arm's 100 lights with --until-error alone, of 120 in reach): it had been
            # accepted, 100 shot and the target claimed below the minimum asked, with no
            # word (a minimum above the lights offered is refused below, with a band to widen)
            most = plan.max_lights
            without = "" if lights is not None else " without --lights"
            raise RtiRigError(
                f"--min-lights {min_lights}: this adaptive session shoots at most {most} lights "
                f"(the most it takes on this rig{without}); give at most {most}: {run} "
                f"{adaptive_options(until_error_deg, lights, most, objective)}{band_options(band)}"
            )
        if not isinstance(geometry, DomeGeometry):  # an arm's reachable lights need the rig's
            in_reach = len(plan.candidates)  # own rules

            def options(lights_now: int | None, min_now: int | None) -> str:
                """The session's options as given, with these counts."""
                return adaptive_options(until_error_deg, lights_now, min_now, objective)

            def widen(asked: Callable[[int], str]) -> Callable[[int], str]:
                return lambda need: _arm_widen_to_hold(
                    rig, loaded, need, in_reach, band, asked, out_dir
                )

            _check_lights_within(
                lights,
                in_reach,
                band,
                # a --min-lights above the count advised is lowered with it: the command
                # given had kept it, and was refused in turn as a minimum above the maximum
                widen(lambda n: options(n, None if min_lights is None else min(min_lights, n))),
            )
            if min_lights is not None:
                _check_min_within(min_lights, in_reach, band, widen(lambda n: options(lights, n)))
        source = AdaptiveSteps(rig, plan, until_error_deg, objective, min_lights=min_lights)
        source.lights_given = lights is not None
        schedule = source.start_schedule()
        validate_schedule(rig, schedule)  # the starting layout, before anything moves
        folder = SessionFolder.create(out_dir, source.total)
    except BaseException:
        rig.close_said()  # its failures said, never in place of the error raised
        raise
    return rig, schedule, folder, source


def refuse_other_format(header: dict, root: Path) -> None:
    """Refuse an adaptive session begun under another decision format (its choices would
    differ from the ones already made: /4 never offered the fitted design), by name and with
    what to do — from the manifest alone, before the folder or the rig is touched."""
    if header.get("format") not in (FORMAT, FORMAT_MIN_LIGHTS):
        raise RtiRigError(
            f"{shown_path(root)}: this adaptive session was begun with format "
            f"{header.get('format')!r}, and this version of rti-rig continues only {FORMAT!r} "
            f"and {FORMAT_MIN_LIGHTS!r} "
            "(its choices would differ from the ones already made). The images are kept: "
            "`rti-rig export-lp` and `rti-rig fit` use them as they are; start a new session to "
            "shoot more"
        )


def refuse_other_constants(header: dict, root: Path) -> None:
    """Refuse a session whose recorded decision constants differ from this build's (its
    choices would not be repeated), naming them — from the manifest alone. A session of this
    format that recorded none was written by a development build: refused too."""
    recorded = header.get("constants")
    if not isinstance(recorded, dict):  # every session of this format records them
        raise RtiRigError(
            f"{shown_path(root)}: this adaptive session's settings do not record its decision "
            "constants (a development build of this format wrote it): this build cannot tell "
            "whether it would repeat its choices. The images are kept: `rti-rig export-lp` and "
            "`rti-rig fit` use them as they are; start a new session to shoot more"
        )
    differ = constant_differences(recorded, decision_constants())
    if differ:
        raise RtiRigError(
            f"{shown_path(root)}: this adaptive session was begun with other decision constants "
            f"({describe_differences(differ)}): this build would not repeat its choices. The "
            "images are kept: `rti-rig export-lp` and `rti-rig fit` use them as they are; "
            "continue it with the build that began it, or start a new session to shoot more"
        )


def check_resume_objective(manifest: dict, root: Path, objective: str | None) -> str:
    """The objective an interrupted session was begun with; a different ``objective`` asked
    for is refused (from the manifest alone, before anything on disk is touched)."""
    header = manifest.get("adaptive")
    if header is None:
        if objective is None:
            return "normals"
        raise RtiRigError(
            f"{shown_path(root)}: --objective goes with an adaptive session, and this one is not: "
            f"drop --objective {objective}"
        )
    refuse_other_format(header, root)
    refuse_other_constants(header, root)
    refuse_damaged_settings(header, root)
    began = header.get("objective")
    if began not in OBJECTIVES:
        raise RtiRigError(
            f"{shown_path(root)}: the manifest's adaptive settings do not say which objective the "
            f"session was chosen for ({began!r}); it cannot continue as it began"
        )
    if objective is not None and objective != began:
        raise RtiRigError(
            f"{shown_path(root)}: this adaptive session was begun with --objective {began}; its "
            f"lights so far were chosen for {began}, and a resume repeats and continues those "
            f"decisions. Drop --objective {objective} to continue it for {began}, or start a new "
            f"session for {objective}"
        )
    return str(began)


def refuse_broken_run(root: Path, total_steps: int) -> Callable[[dict[int, Any]], None]:
    """A check of the steps verified on disk (``SessionFolder.reopen``'s ``check_done``): an
    adaptive session continues only from an unbroken run of steps, since each light after a
    missing image was chosen from it. Refused before the resume moves anything, with what to
    do (a QA verdict of "reshoot image_003" invites deleting it and resuming)."""

    def check(done: dict[int, Any]) -> None:
        gaps = [i for i in range(max(done, default=-1) + 1) if i not in done]
        if not gaps:
            return
        from rti_rig.runtime.session import image_names

        every = image_names(total_steps)
        names = ", ".join(every[i] for i in gaps)
        which = (
            f"step {gaps[0] + 1} ({names}) is missing or differs from its journaled checksum"
            if len(gaps) == 1
            else f"steps {', '.join(str(i + 1) for i in gaps)} ({names}) are missing or differ "
            "from their journaled checksums"
        )
        raise RtiRigError(
            f"{shown_path(root)}: {which}, but later steps are on disk. The lights "
            "after a step were chosen from its image, so an adaptive session cannot reshoot it "
            "in place; nothing in the folder was changed. Put the step's original files back "
            "(its JPEG, linear/ TIFF and any raw/ original, as the journal lists them with "
            "their checksums; an earlier resume sets files it cannot verify aside in "
            "recovered/) and resume again, or start a new session with another --out"
        )

    return check


def _recorded_positions(rig, folder) -> NDArray[np.float64] | None:  # type: ignore[no-untyped-def]
    """A dome's LED positions as the session recorded them (its rig identity, kept by the
    resume where the rig's differ by rounding alone), or None: an arm, a session recorded
    before the positions were, or another number of LEDs."""
    recorded = getattr(folder, "rig_identity", None) or {}
    dirs = recorded.get("light_directions")
    if not isinstance(rig.geometry, DomeGeometry) or not isinstance(dirs, list):
        return None
    arr = np.asarray(dirs, dtype=np.float64)
    return arr if arr.shape == rig.geometry.directions.shape else None


def resume_adaptive_source(rig, folder, objective: str | None = None) -> AdaptiveSteps:  # type: ignore[no-untyped-def]
    """The step source of an interrupted adaptive session, brought up to its last step
    (``objective``: the one the user asks for, if any — it must be the session's own)."""
    header = folder.manifest["adaptive"]
    refuse_other_format(header, Path(folder.root))
    began = check_resume_objective(folder.manifest, Path(folder.root), objective)
    plan = adaptive_plan(
        rig,
        header["max_lights"],
        header["start_lights"],
        design=header.get("design_lights") is not None,
        objective=began,
        band=header_band(header),
        positions=_recorded_positions(rig, folder),
        # the session's own (none recorded: begun before the rule, resumed without it)
        ring_span_deg=(header.get("constants") or {}).get("app.usecases.adaptive.RING_SPAN_DEG"),
    )
    if plan.max_lights != header["max_lights"] or len(plan.candidates) != header["candidates"]:
        # what to do, not only what is wrong (it had ended "it cannot continue as it began",
        # after a note that the rig change was accepted)
        raise RtiRigError(
            f"{shown_path(folder.root)}: the rig now offers {len(plan.candidates)} candidate "
            f"lights, the session began with {header['candidates']}: an adaptive session chooses "
            "among the rig's lights, and a resume re-decides every step already taken among them, "
            "so it cannot continue as it began. Nothing was recorded or captured. Resume with the "
            f"session's own config (rti-rig run --resume {folder.root}), or start a new session "
            "on the changed rig"
        )
    # the stop's factor the session began with (its target means the same to the end)
    source = AdaptiveSteps(
        rig,
        plan,
        header.get("until_error_deg"),
        began,
        header.get("upper_factor"),
        min_lights=header.get("min_lights"),  # absent in sessions begun before it existed
        # absent in sessions begun before the term: judged with this build's (their claims
        # had left the unsolved pixels out; adaptive_constants.RESTORED_ON_RESUME)
        unsolved_deg=header.get("unsolved_deg"),
        # the lamps the session's stop was judged with (absent in sessions begun before the
        # stop rendered near lamps: the rig's, as the unsolved term above)
        lamps=recorded_lamps(header["lamps"]) if "lamps" in header else "rig",
        # absent in sessions begun before the misfit bound: judged with this build's, as the
        # unsolved term above (the images can only hold a claim back)
        misfit_noise_k=header.get("misfit_noise_k"),
    )
    source.lights_given = lights_given(header)
    source.replay(folder)
    return source


def recorded_lamps(record: dict[str, Any] | None) -> LampGeometry | None:
    """The lamp geometry a session's settings recorded (None: distant lamps)."""
    if record is None:
        return None
    return LampGeometry(float(record["distance_mm"]), float(record["field_width_mm"]))


def lights_given(header: dict[str, Any]) -> bool:
    """Whether the session recorded by ``header`` was begun with ``--lights`` (absent in
    sessions begun before ``--adaptive`` alone was designed for ``default_lights``: then a
    design meant ``--lights``)."""
    return bool(header.get("lights_given", header.get("design_lights") is not None))


def lights_asked(header: dict[str, Any]) -> int | None:
    """The ``--lights`` the session recorded by ``header`` began with (None: not given)."""
    design = header.get("design_lights")
    return int(design) if design is not None and lights_given(header) else None
