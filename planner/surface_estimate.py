"""What one preview says about the surface: the planner's model of the object.

Every objective of the planner scores lights against a surface, and this module is where that
surface comes from, kept apart from the choice of lights (:mod:`rti_rig.planner.make_plan`) so it
can be estimated, inspected and tested on its own (the tests and the benchmarks do):

1. :func:`rti_rig.planner.topography.planning_image` — downsample early, linearise, reduce to
luminance;
2. the preview's light: ``preview_light`` (azimuth, elevation in degrees, frame of
   docs/conventions.md) or
   :func:`rti_rig.planner.topography.estimate_light`;
3. a relief: the user's ONNX depth model (:func:`rti_rig.planner.topography.depth_from_onnx`) or the
   weight-free :func:`rti_rig.planner.topography.shape_from_shading` — or, with no preview at all, a
   level, matte surface (:func:`flat_surface`);
4. its scale from the preview's shading and then normals (:mod:`rti_rig.planner.normals`), shrunk by
   how much of the preview they explain (:func:`relief_trust`).

:func:`sample_surface` then draws the seeded pixel sample the objectives score, with cast-shadow
maps, the highlight model of the declared material and copies under plausible global tilts
(:func:`hedge_global_tilt`), which one image cannot show.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from rti_rig.core.errors import ScheduleError
from rti_rig.core.shell_words import shown_path
from rti_rig.planner.light_origin import LightOrigin
from rti_rig.planner.normals import (
    ReliefFit,
    fit_relief_scale,
    normals_from_height,
    sanitize_height,
)
from rti_rig.planner.objectives import (
    GLOSSY_SPECULAR,
    GLOSSY_WIDTH_DEG,
    Candidates,
    SurfaceSample,
    cast_shadow_visibility,
    check_material,
)
from rti_rig.planner.topography import (
    DepthModelSpec,
    depth_from_onnx,
    estimate_light,
    given_light,
    planning_image,
    shape_from_shading,
)

#: Pixels sampled for the objectives.
SAMPLE_PIXELS = 256

#: A preview with more than this fraction of clipped pixels carries no shading to read.
MAX_SATURATED_FRACTION = 0.95


@dataclass(frozen=True, eq=False)
class SurfaceEstimate:
    """What one preview says about the surface, at planning resolution."""

    image: NDArray[np.float64]
    light: NDArray[np.float64]
    light_origin: LightOrigin
    relief_px: NDArray[np.float64]
    normals: NDArray[np.float64]
    fit: ReliefFit
    relief_source: str
    nonfinite_repaired: int
    #: normals of the fitted relief before the trust shrinkage (what the paper's k-means sees)
    fitted_normals: NDArray[np.float64] | None = None
    #: why the zenith was assumed, no light direction being had from the image
    #: (:attr:`planner.topography.LightEstimate.why_zenith`); None unless ``light_origin`` is
    #: :attr:`LightOrigin.ZENITH_ASSUMED`
    light_why_zenith: str | None = None


def relief_trust(fit: ReliefFit) -> float:
    """How far to believe the fitted relief: the R² of the preview's shading fit, in [0, 1].

    The relief's slopes are multiplied by it (shrinkage towards the flat surface, the prior of
    RTI targets). On the real painted icon of the benchmark the unshrunk shape-from-shading
    relief (R² ≈ 0.1) misled the planner into worse layouts than assuming a flat surface.
    """
    return float(np.clip(fit.explained, 0.0, 1.0))


def estimate_surface(
    preview: NDArray,
    preview_light: tuple[float, float] | None = None,
    depth_model: Path | None = None,
    depth_spec: DepthModelSpec | None = None,
    light_origin: LightOrigin = LightOrigin.GIVEN,
) -> SurfaceEstimate:
    """Steps 1–4 of the pipeline (see module docstring).

    ``light_origin``: where ``preview_light`` came from (given or recorded), carried into the
    estimate; without a ``preview_light`` the light is estimated and the origin says how."""
    image = planning_image(preview)
    peak = float(image.max()) if image.size else 0.0
    if not peak > 1e-6:
        raise ScheduleError(
            "the preview is black: no light reached the sensor, so it says nothing about the "
            "surface; retake it with a longer exposure, or plan without a preview "
            "(--method optimal or uniform)"
        )
    if float(np.mean(image >= 0.995)) > MAX_SATURATED_FRACTION:
        raise ScheduleError(
            "the preview is saturated almost everywhere, so its shading is lost; retake it "
            "with a shorter exposure, or plan without a preview (--method optimal or uniform)"
        )
    why_zenith = None
    if preview_light is not None:
        light, origin, albedo = given_light(preview_light), light_origin, None
    else:
        est = estimate_light(image)
        light, origin, albedo = est.direction, LightOrigin.ESTIMATED, None
        if est.why_zenith is not None:
            origin, why_zenith = LightOrigin.ZENITH_ASSUMED, est.why_zenith
    if depth_model is not None:
        raw = depth_from_onnx(preview, Path(depth_model), depth_spec, out_shape=image.shape)
        source = f"depth model {shown_path(Path(depth_model).name)}"
        height, bad = sanitize_height(raw, source)
    else:
        height, bad = shape_from_shading(image, light, albedo), 0
        source = "shape from shading"
    fit = fit_relief_scale(height, image, light)
    # shrink the relief by the share of the preview it explains: a preview that is mostly
    # albedo (a painting) must not be read as steep relief (see docs/research/planner.md)
    relief = fit.scale * relief_trust(fit) * height
    return SurfaceEstimate(
        image,
        light,
        origin,
        relief,
        normals_from_height(relief),
        fit,
        source,
        bad,
        normals_from_height(fit.scale * height),
        light_why_zenith=why_zenith,
    )


#: Side (pixels) of the stand-in planning image when there is no preview.
FLAT_SIDE_PX = 16


def flat_surface() -> SurfaceEstimate:
    """What the ``optimal`` planner assumes without a preview: a level, matte surface.

    The model alone (shadows of the tilt hedge, noise propagation, the reflectance prior) then
    chooses the lights. On the real dome and on the simulator's scenes this did as well as
    planning from a preview (docs/research/planner.md), so a preview shot is optional for
    ``optimal``.
    It is exactly what a uniform grey preview yields (tested, down to 1×1): no relief, no
    highlight hint.
    """
    relief = np.zeros((FLAT_SIDE_PX, FLAT_SIDE_PX))
    normals = normals_from_height(relief)
    fit = ReliefFit(scale=0.0, albedo=0.0, explained=0.0, rms_slope_deg=0.0, bright_outliers=0.0)
    return SurfaceEstimate(
        np.full_like(relief, 0.5),
        np.array([0.0, 0.0, 1.0]),
        LightOrigin.ZENITH_ASSUMED,
        relief,
        normals,
        fit,
        "none (no preview: a level surface)",
        0,
        normals,
        light_why_zenith="there is no preview",
    )


def sample_surface(
    surface: SurfaceEstimate,
    candidates: Candidates,
    held_out: NDArray[np.float64],
    n_pixels: int = SAMPLE_PIXELS,
    seed: int = 0,
    material: str = "auto",
) -> SurfaceSample:
    """A seeded pixel sample with cast-shadow maps for the candidates and held-out lights.

    ``material`` (:data:`rti_rig.planner.objectives.MATERIALS`) sets the highlight model: ``auto``
    from the preview's bright outliers, ``matte`` none, ``glossy`` the declared lobe.
    """
    check_material(material)
    h, w = surface.image.shape
    rng = np.random.default_rng(seed)
    count = min(n_pixels, h * w)
    flat = rng.choice(h * w, count, replace=False)
    rows, cols = np.divmod(flat, w)
    normals = surface.normals.reshape(-1, 3)[flat]
    lit_c = cast_shadow_visibility(surface.relief_px, rows, cols, candidates.directions)
    lit_t = cast_shadow_visibility(surface.relief_px, rows, cols, held_out)
    width = None
    if material == "glossy":
        specular, width = GLOSSY_SPECULAR, GLOSSY_WIDTH_DEG
    elif material == "matte":
        specular = 0.0
    else:
        # the hint's ceiling is the declared glossy strength
        hint = 10.0 * (surface.fit.bright_outliers - 0.005)
        specular = float(np.clip(hint, 0.0, GLOSSY_SPECULAR))
    normals, weights = hedge_global_tilt(normals)
    copies = len(normals) // count
    return SurfaceSample(
        normals,
        weights,
        np.tile(lit_c, (copies, 1)),
        held_out,
        np.tile(lit_t, (copies, 1)),
        specular,
        highlight_width_deg=width,
        base_count=count,
    )


#: Global tilts the planner hedges against (degrees from the camera axis) and their share.
TILT_PRIOR_DEG = 25.0
TILT_PRIOR_AZIMUTHS = 6
TILT_PRIOR_SHARE = 0.3


def hedge_global_tilt(
    normals: NDArray[np.float64],
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The sampled normals plus copies under plausible global tilts, and their weights.

    One image cannot show a global tilt: a tilted plane shades uniformly, exactly like a level
    plane of another albedo, so shape from shading (and a relative-depth network) returns it
    level. Planning for the level surface alone puts low lights where a tilted object would
    leave them in attached shadow, and three such lights leave every pixel unsolvable (on the
    simulated 50°-tilted scene at N = 3: 49.9° mean error without the hedge, 2.5° with it). So
    ``1 - TILT_PRIOR_SHARE`` of the weight stays on the estimate and the rest is spread over
    copies tilted by ``TILT_PRIOR_DEG`` towards ``TILT_PRIOR_AZIMUTHS`` azimuths. The constants
    were chosen on the simulator's quick trade-off scenes (share 0.3 and 25° had the smallest
    worst-case ratio to uniform of the variants tried); they are not tuned on real data.
    """
    n = len(normals)
    out = [normals]
    weights = [np.full(n, 1.0 - TILT_PRIOR_SHARE)]
    t = np.radians(TILT_PRIOR_DEG)
    for k in range(TILT_PRIOR_AZIMUTHS):
        phi = 2.0 * np.pi * k / TILT_PRIOR_AZIMUTHS
        axis = np.array([-np.sin(phi), np.cos(phi), 0.0])  # tilts +z towards azimuth phi
        kx = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
        rot = np.eye(3) + np.sin(t) * kx + (1 - np.cos(t)) * (kx @ kx)
        out.append(normals @ rot.T)
        weights.append(np.full(n, TILT_PRIOR_SHARE / TILT_PRIOR_AZIMUTHS))
    return np.concatenate(out), np.concatenate(weights)


def tilt_stats(normals: NDArray[np.float64]) -> tuple[float, float]:
    """RMS and 90th-percentile tilt of ``normals`` from the camera axis (degrees)."""
    tilt = np.degrees(np.arccos(np.clip(normals[..., 2], -1.0, 1.0))).ravel()
    return float(np.sqrt(np.mean(tilt**2))), float(np.percentile(tilt, 90))
