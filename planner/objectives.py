"""What a light layout is worth for a given surface: the planner's two objectives.

Everything here is evaluated over a *sample of the preview's normals* and a finite set of
*candidate lights* (a dome's LEDs; a dense reachable set for an arm), so a layout is a set of
candidate indices and its cost a number that can be compared and optimised.

* ``normals`` — surface inspection and normal maps. The Cramér–Rao bound of the per-pixel
  Lambertian least-squares fit (algorithms notes, section 3): ``E[θ²] = (σ/ρ)² tr(P M⁻¹ P)``
  with ``M = Σ_k w_k l_k l_kᵀ`` over the lights that really reach the pixel and
  ``P = I - n nᵀ``. The weights ``w_k`` remove attached shadows (soft, near-grazing light is
  unreliable), cast shadows (marched over the preview's relief) and, when the preview shows
  highlights, lights whose mirror direction points at the camera.
* ``relight`` — interactive relighting with a linear basis (PTM or HSH). The expected
  relighting error on held-out directions is bias² (how badly the basis, fitted on the chosen
  lights, reproduces the surface's shadowed, possibly glossy reflectance) plus variance
  (``σ² · mean_t a_tᵀ (AᵀA)⁻¹ a_t``, the noise propagation of the fit).

The reflectance model (Lambert + shadows + an optional highlight lobe) is simple on purpose:
it has to rank layouts, not render images.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property
from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray

from rti_rig.core.errors import ScheduleError
from rti_rig.core.geometry import angle_between_deg, az_el_from_direction, fibonacci_cap
from rti_rig.core.rig_geometry import ArmGeometry, DomeGeometry, in_band
from rti_rig.core.rti_bases import N_COEFFICIENTS, design_matrix
from rti_rig.planner import rank_one

Objective = Literal["normals", "relight"]
OBJECTIVES: tuple[str, ...] = ("normals", "relight")

#: Image noise relative to albedo assumed by the bounds (≈ 34 dB): it sets the balance
#: between the variance and bias terms of the relighting objective.
NOISE_REL = 0.02

#: Assumed RMS deviation of real reflectance from Lambert, relative to albedo, for the model
#: bias term of the normals objective (chosen a priori, not fitted to any benchmark).
BIAS_REL = 0.05

#: Image noise that grows in proportion to the signal, relative to it (``signal_noise`` of the
#: planner, off by default): the spread of an uncalibrated dome's LED intensities (the same for
#: every pixel of one image) and the quantisation and compression of 8-bit gamma-encoded images,
#: whose steps in linear units grow with brightness. Observation k of a pixel then has variance
#: ``σ² + (signal_noise · ρ n·l_k)²``: a light striking the surface head-on is worth less than
#: the additive model says, and the planner takes more oblique lights. This value was chosen
#: among 2, 5 and 10 % on the real dome's paired draws (docs/research/planner.md), not derived.
SIGNAL_NOISE_JPEG_DOME = 0.05

#: What the user may declare about the object's surface (``material`` of the planner):
#: ``auto`` reads the highlight strength from the preview's bright outliers (the default),
#: ``matte`` models no highlight, ``glossy`` models a strong, broad one whatever the preview
#: shows. One preview of a flat glossy object does not show its gloss (the gilded icon of
#: docs/research/planner.md reads ≈ 0), but its owner knows it.
MATERIALS: tuple[str, ...] = ("auto", "matte", "glossy")

#: Highlight lobe widths (degrees between the half vector and the normal) the preview's hint
#: is modelled with: the light weights of the normals objective and the reflectance of the
#: relight objective.
HIGHLIGHT_WEIGHT_WIDTH_DEG = 15.0
HIGHLIGHT_MODEL_WIDTH_DEG = 10.0

#: A declared glossy surface: the hint's ceiling strength on a 30° lobe. Chosen between 0.5 on
#: 25° and 0.8 on 30° on the simulator's polished coin and an ad hoc run of the real gilded
#: dome's paired draws, where both lowered the normal error at every N (docs/research/planner.md).
GLOSSY_SPECULAR = 0.8
GLOSSY_WIDTH_DEG = 30.0

#: From this many pixel rows up, a swap scan gathers the arrays of the candidates it scores
#: (below, scoring them all costs less than the gathering).
POOL_MIN_PIXELS = 64

#: At most this many positions of a layout have their scans' per-pixel inverses computed at
#: once (:meth:`NormalsObjective._inverses_at`) ...
INVERSE_BATCH = 16

#: ... from this many lights: with fewer, swaps come often for the few scans of a sweep and
#: the search stops part-way through one, so too much of a batch went unused (on this machine
#: the shipped arm at 9 lights and the 48-LED dome at 24 scanned 8–10 % slower batched; the
#: arm at 36 and the 200-LED dome at 100, 13 % and 8 % faster).
INVERSE_BATCH_MIN_LIGHTS = 32

#: Sampled normals used for the bias term (it varies smoothly with the normal).
BIAS_PIXELS = 128

#: Below this n·l a light is treated as (softly) shadowed: grazing light carries little signal
#: and is where shadow boundaries, foreshortening and inter-reflections spoil the model.
GRAZING_COS = 0.15

#: Cap of the per-pixel squared angular error (rad²): an unobservable normal is "90° wrong".
MAX_ERR2 = (np.pi / 2) ** 2

#: Dense candidate count for an arm's continuous reachable band.
ARM_CANDIDATES = 120

#: Held-out directions for the relighting objective.
HELD_OUT = 160

#: Relighting models considered, with the light count each needs to be well determined
#: (≥ 1.5× its coefficients, algorithms notes section 3: below that the fit over-fits).
MODEL_MIN_LIGHTS = {"lambert": 3, "hsh1": 6, "ptm": 9, "hsh2": 14, "hsh3": 24}


@dataclass(frozen=True, eq=False)
class Candidates:
    """Light directions the rig can use; ``leds[i]``/``names[i]`` when it is a dome."""

    directions: NDArray[np.float64]
    leds: NDArray[np.intp] | None
    names: tuple[str, ...] | None

    def __len__(self) -> int:
        return len(self.directions)


def candidates_for(
    geometry: DomeGeometry | ArmGeometry,
    min_elevation_deg: float = 0.0,
    extra: NDArray[np.float64] | None = None,
    max_elevation_deg: float = 90.0,
) -> Candidates:
    """The rig's usable lights between the elevation floor and ceiling (a dome's LEDs; an
    arm's dense band).

    ``extra`` adds directions (e.g. a homogeneous layout) to an arm's set, so that a layout
    computed elsewhere is exactly representable.
    """
    if isinstance(geometry, DomeGeometry):
        _, el = az_el_from_direction(geometry.directions)
        idx = np.flatnonzero(in_band(el, min_elevation_deg, max_elevation_deg))
        if len(idx) == 0:
            raise ScheduleError(
                f"the dome has no LED between {min_elevation_deg:g}° and "
                f"{max_elevation_deg:g}° elevation; widen --min-elevation-deg / "
                "--max-elevation-deg"
            )
        return Candidates(
            geometry.directions[idx], idx.astype(np.intp), tuple(geometry.names[i] for i in idx)
        )
    lo, hi = geometry.elevation_band(min_elevation_deg)
    hi = min(hi, max_elevation_deg)
    if hi <= lo:
        raise ScheduleError(
            f"--max-elevation-deg {max_elevation_deg:g} leaves the arm no band above "
            f"{lo:g}°; raise it"
        )
    dense = fibonacci_cap(ARM_CANDIDATES, lo, hi)
    if extra is not None and len(extra):
        dense = np.concatenate([np.asarray(extra, dtype=np.float64).reshape(-1, 3), dense])
    return Candidates(dense[geometry.reachable(dense)], None, None)


def snap_unique(targets: NDArray[np.float64], candidates: Candidates) -> NDArray[np.intp]:
    """Candidate indices for ``targets`` (one each, no repeats), minimising the total angle."""
    if len(targets) > len(candidates):
        raise ScheduleError(
            f"asked for {len(targets)} lights but only {len(candidates)} are available"
        )
    from scipy.optimize import linear_sum_assignment  # 0.3 s to import: only when needed

    cost = angle_between_deg(targets[:, None, :], candidates.directions[None, :, :])
    rows, cols = linear_sum_assignment(cost)
    out = np.empty(len(targets), dtype=np.intp)
    out[rows] = cols
    return out


@dataclass(frozen=True, eq=False)
class SurfaceSample:
    """What the planner knows of the surface: sampled normals, their weights, shadow maps.

    ``lit_candidates[p, k]`` / ``lit_held_out[p, t]`` are 1 where light k / t reaches pixel p
    without a cast shadow (from the preview's relief) and 0 where it is blocked;
    ``specular`` (0..1) is the strength of the highlight lobe, from the preview's hint or the
    user's declared material (``rti_rig.planner.surface_estimate.sample_surface``).
    """

    normals: NDArray[np.float64]
    weights: NDArray[np.float64]
    lit_candidates: NDArray[np.float64]
    held_out: NDArray[np.float64]
    lit_held_out: NDArray[np.float64]
    specular: float = 0.0
    #: highlight lobe width (degrees) for both the light weights and the modelled reflectance;
    #: None keeps :data:`HIGHLIGHT_WEIGHT_WIDTH_DEG` / :data:`HIGHLIGHT_MODEL_WIDTH_DEG`
    highlight_width_deg: float | None = None
    #: how many leading rows are the estimated surface itself (the rest: hedge copies of it,
    #: :func:`rti_rig.planner.surface_estimate.hedge_global_tilt`); None means every row
    base_count: int | None = None
    #: a binned sample's (:func:`rti_rig.planner.pixel_bins.bin_pixels`): the weights of its
    #: leading rows in the bias term's sub-sample; None: the first rows of the estimated surface
    bias_weights: NDArray[np.float64] | None = None


#: Lights whose shadow rays are marched together (bounds the (pixels, steps, lights) arrays).
MARCH_GROUP = 16


def cast_shadow_visibility(
    height_px: NDArray[np.float64],
    rows: NDArray[np.intp],
    cols: NDArray[np.intp],
    directions: NDArray[np.float64],
    max_steps: int = 32,
) -> NDArray[np.float64]:
    """1 where a light from ``directions[k]`` reaches pixel (rows[p], cols[p]), else 0.

    Marches from each pixel towards the light over the relief (height in pixel units) and
    reports a cast shadow when the terrain rises above the ray. Nearest-pixel lookups and a
    bounded march: this ranks layouts, it does not render.
    """
    h, w = height_px.shape
    d = np.asarray(directions, dtype=np.float64)
    horiz = np.hypot(d[:, 0], d[:, 1])
    step_x = np.where(horiz > 1e-9, d[:, 0] / np.maximum(horiz, 1e-9), 0.0)
    step_y = np.where(horiz > 1e-9, d[:, 1] / np.maximum(horiz, 1e-9), 0.0)
    rise = d[:, 2] / np.maximum(horiz, 1e-9)  # height gained per pixel travelled
    t = np.arange(1, max_steps + 1, dtype=np.float64)
    h0 = height_px[rows, cols]
    vis = np.ones((len(rows), len(d)))
    if len(rows) == 0:
        return vis
    # a ray that has climbed from the lowest sampled pixel to within 0.5 px of the highest
    # terrain cannot be blocked any further on: only the steps before are marched (none on a
    # level surface or for a light that gets there in one step; the march is otherwise the same)
    reach = (float(height_px.max()) - float(h0.min()) - 0.5) / np.maximum(rise, 1e-12)
    steps = np.where(rise > 0, np.clip(np.ceil(reach) - 1, 0, max_steps), max_steps)
    steps = steps.astype(np.intp)
    # marched together in groups of similar step counts (a step past a light's own count
    # cannot find it blocked, so a group marches as far as its longest)
    marched = np.flatnonzero((horiz >= 1e-6) & (steps > 0))
    marched = marched[np.argsort(steps[marched], kind="stable")]
    for group in np.array_split(marched, max(1, -(-len(marched) // MARCH_GROUP))):
        if len(group) == 0:
            continue
        tk = t[: int(steps[group].max())][None, :, None]  # (1, T, 1)
        cc = np.rint(cols[:, None, None] + tk * step_x[group]).astype(np.intp)  # (P, T, G)
        rr = np.rint(rows[:, None, None] - tk * step_y[group]).astype(np.intp)
        inside = (cc >= 0) & (cc < w) & (rr >= 0) & (rr < h)
        hh = height_px[np.clip(rr, 0, h - 1), np.clip(cc, 0, w - 1)]
        ray = h0[:, None, None] + tk * rise[group]
        vis[:, group] = ~np.any(inside & (hh > ray + 0.5), axis=1)
    return vis


def _attached(normals: NDArray, directions: NDArray) -> NDArray[np.float64]:
    """Soft attached-shadow weight: 0 facing away, ramping to 1 past :data:`GRAZING_COS`."""
    return np.clip((normals @ directions.T) / GRAZING_COS, 0.0, 1.0)


def _highlight(normals: NDArray, directions: NDArray, width_deg: float) -> NDArray:
    """Strength of a mirror highlight seen by the camera (+z) for each normal and light."""
    half = directions + np.array([0.0, 0.0, 1.0])
    half = half / np.linalg.norm(half, axis=-1, keepdims=True)
    cos = np.clip(normals @ half.T, -1.0, 1.0)
    return np.exp(-((np.degrees(np.arccos(cos)) / width_deg) ** 2))


def light_weights(sample: SurfaceSample, directions: NDArray[np.float64]) -> NDArray:
    """Per-pixel, per-light usefulness for the normal fit (P, K) — see module notes."""
    w = _attached(sample.normals, directions) * sample.lit_candidates
    if sample.specular > 0:
        width = sample.highlight_width_deg or HIGHLIGHT_WEIGHT_WIDTH_DEG
        w = w * (1.0 - sample.specular * _highlight(sample.normals, directions, width))
    return w


def reflectance(
    sample: SurfaceSample, directions: NDArray[np.float64], lit: NDArray[np.float64]
) -> NDArray[np.float64]:
    """Modelled radiance (P, K) per unit albedo: shadowed Lambert plus a highlight lobe."""
    cos = np.clip(sample.normals @ directions.T, 0.0, None)
    f = cos * lit
    if sample.specular > 0:
        width = sample.highlight_width_deg or HIGHLIGHT_MODEL_WIDTH_DEG
        f = f + sample.specular * _highlight(sample.normals, directions, width) * lit * (cos > 0)
    return f


def merge_identical_pixels(
    normals: NDArray[np.float64], w: NDArray[np.float64], wts: NDArray[np.float64], n_first: int
) -> tuple[NDArray[np.intp], NDArray[np.float64], NDArray[np.float64]]:
    """One row per distinct pixel (normal and candidate weights equal bit for bit).

    Returns the rows kept (each group's first pixel, in order of first appearance), the
    group's summed weight ``wts``, and the normalised weights of the groups met among the first
    ``n_first`` pixels (those groups come first: the bias term's sub-sample stays a prefix).
    Every per-pixel term of :class:`NormalsObjective` depends on the pixel only through its
    normal and weights, so the weighted mean over the groups is the mean over the pixels.
    """
    key = np.ascontiguousarray(np.concatenate([normals, w], axis=1))
    seen: dict[bytes, int] = {}
    group = np.array([seen.setdefault(row.tobytes(), len(seen)) for row in key], dtype=np.intp)
    first = np.unique(group, return_index=True)[1].astype(np.intp)  # each group's earliest row
    merged = np.bincount(group, weights=wts, minlength=len(seen))
    head = group[:n_first]
    firsts = np.bincount(head, weights=wts[:n_first], minlength=int(head.max()) + 1)
    return first, merged, firsts / firsts.sum()


class NormalsObjective:
    """Expected RMS normal error (degrees) of the Lambertian fit over the sample.

    Two parts, per sampled normal ``n`` (unit albedo):

    * variance — the Cramér–Rao bound ``σ² tr(P M⁻¹ P)`` with ``M = Σ w_k l_k l_kᵀ`` (module
      notes), where ``w_k`` also carries the signal-proportional noise ``s`` when one is given
      (``w_k / (1 + (s/σ)² (n·l_k)²)``, see :data:`SIGNAL_NOISE_JPEG_DOME`: the information
      of a fit that weights each observation by its noise; the reconstruction's robust fit
      weights them equally, so this ranks layouts, it does not predict that fit's error);
    * model bias — real surfaces are not Lambertian, and a sparse set of lights fits a
      Lambertian normal that differs from the one the dense dome would give. The deviation
      from Lambert is unknown from one preview, so it is modelled as a random smooth function
      of the light direction, ``g(l) = Σ β_j h_j(l)`` over the 9 order-2 hemispherical
      harmonics with independent ``β_j ~ N(0, τ²)``; the fitted ``b`` then moves by
      ``(G_S - G_all) β`` with ``G = M⁻¹ Σ w_k l_k h_kᵀ``, whose expected squared tangential
      size is ``τ² ‖P (G_S - G_all)‖²_F``. This favours layouts whose Lambertian fit agrees
      with the fit on every usable light (the reference an RTI user compares against).
    """

    name = "normals"

    #: Index pairs of the 6 distinct entries of a symmetric 3×3 (xx, xy, xz, yy, yz, zz).
    PAIRS = ((0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2))

    def __init__(
        self,
        sample: SurfaceSample,
        candidates: Candidates,
        bias_rel: float = BIAS_REL,
        gain_rel: float = 0.0,
        merge_pixels: bool = True,
    ) -> None:
        self.sample = sample
        self.candidates = candidates
        self.bias_rel = bias_rel
        self.gain_rel = gain_rel
        d = candidates.directions
        w = light_weights(sample, d)  # (P, K)
        if gain_rel > 0:
            # observation variance σ²(1 + (g/σ)² (n·l)²) in units of σ²: weight = 1/variance
            shading = np.clip(sample.normals @ d.T, 0.0, None)
            w = w / (1.0 + (gain_rel / NOISE_REL) ** 2 * shading * shading)
        wts = sample.weights / sample.weights.sum()
        if sample.bias_weights is not None:
            # a binned sample (:mod:`rti_rig.planner.pixel_bins`): its rows are distinct and it
            # says which lead the bias term and with what weights
            rows = np.arange(len(w))
            wts_bias = sample.bias_weights / sample.bias_weights.sum()
        else:
            # the bias term is smooth over normals: a sub-sample of the (random) pixels
            # suffices ... taken from the estimated surface itself, never from its tilted
            # hedge copies (with fewer sampled pixels than BIAS_PIXELS they would otherwise
            # slip in)
            n_bias = min(sample.base_count or len(sample.normals), BIAS_PIXELS)
            # pixels that are the same to this objective (same normal, same weight for every
            # candidate: a level preview's or a flat region's) are scored once, with their
            # summed weight — the same cost, in a fraction of the time (no preview: 1792 → 7)
            if merge_pixels:
                rows, wts, wts_bias = merge_identical_pixels(sample.normals, w, wts, n_bias)
            else:
                rows, wts_bias = np.arange(len(w)), wts[:n_bias] / wts[:n_bias].sum()
        w = w[rows]
        self.n = sample.normals[rows]
        self.wts = wts
        self.n_bias = len(wts_bias)
        self.wts_bias = wts_bias
        x, y, z = self.n.T
        # entries of P = I - n nᵀ paired with adj(M): diagonal once, off-diagonal twice
        proj = np.stack([1 - x * x, 1 - y * y, 1 - z * z, -2 * x * y, -2 * x * z, -2 * y * z])
        self.projector = (proj, proj.astype(np.float32))
        self.tau2 = (bias_rel * np.sqrt(2 * np.pi / 9)) ** 2  # RMS deviation = bias_rel
        self.dirs = d
        # candidate k's information at pixel p is w_pk l_k l_kᵀ: its 6 distinct entries are
        # d6[k] * w_kp[k, p], so a layout's information is one small matrix product
        # (6 × N) @ (N × P), never a (6, K, P) array (:attr:`outer` builds that on demand)
        self.w_kp = np.ascontiguousarray(w.T)  # (K, P): also the rank-one scans' weights
        self.d6 = np.ascontiguousarray(np.stack([d[:, i] * d[:, j] for i, j in self.PAIRS], 1))
        self.l6 = rank_one.quadratic_coefficients(d)
        self.hsh = design_matrix("hsh2", d)  # (K, 9)
        self._sums: tuple[bytes, NDArray, NDArray | None] | None = None
        self._among: tuple[bytes, tuple[NDArray, ...]] | None = None
        self._w32: NDArray[np.float32] | None = None
        self._l_max2 = float(np.max(np.sum(d * d, axis=1), initial=0.0))  # ‖l‖² ≤ this
        self._inverse_batch: tuple[bytes, int, int, tuple[NDArray, ...], list] | None = None
        self._batch_size = 1
        if self.tau2 > 0:
            every = np.arange(len(d))
            all_m = self._information(every)[:, : self.n_bias]  # (6, P_bias)
            self.g_all = self._solve(all_m[:, None], self._cross_sum(every)[:, None])[:, 0]

    def _information(self, chosen: NDArray[np.intp]) -> NDArray[np.float64]:
        """Entries (6, P) of ``M = Σ_k w_pk l_k l_kᵀ`` over the lights ``chosen``."""
        return self.d6[chosen].T @ self.w_kp[chosen]

    def _cross_sum(self, chosen: NDArray[np.intp]) -> NDArray[np.float64]:
        """The bias pixels' cross terms ``Σ_k w_pk l_k h_kᵀ`` over ``chosen``: (3, P_bias, 9)."""
        wb = self.w_kp[chosen, : self.n_bias]  # (N, P_bias)
        h = self.hsh[chosen]
        return np.stack([(wb * self.dirs[chosen, i, None]).T @ h for i in range(3)])

    def _outer_at(self, k: NDArray[np.intp] | slice, pix: NDArray[np.intp] | slice) -> NDArray:
        """Information entries (6, K', P') of the candidates ``k`` at the pixels ``pix``."""
        return self.d6[k].T[:, :, None] * self.w_kp[k][:, pix][None]

    def _cross_at(self, k: NDArray[np.intp] | slice, pix: NDArray[np.intp] | slice) -> NDArray:
        """Cross terms (3, K', P', 9) of the candidates ``k`` at the bias pixels ``pix``."""
        wb = self.w_kp[k, : self.n_bias][:, pix]  # (K', P')
        return self.dirs[k].T[:, :, None, None] * (wb[:, :, None] * self.hsh[k][:, None, :])[None]

    @cached_property
    def outer(self) -> NDArray[np.float64]:
        """Every candidate's information entries per pixel (6, K, P) (for analyses; the search
        never builds it)."""
        return np.ascontiguousarray(self._outer_at(slice(None), slice(None)))

    @cached_property
    def cross(self) -> NDArray[np.float64]:
        """Every candidate's cross terms at the bias pixels (3, K, P_bias, 9) (for analyses)."""
        return np.ascontiguousarray(self._cross_at(slice(None), slice(None)))

    @staticmethod
    def _adjugate(m: NDArray[np.float64]) -> tuple[tuple[NDArray, ...], NDArray]:
        a, b, c, d, e, f = m[0] + 1e-9, m[1], m[2], m[3] + 1e-9, m[4], m[5] + 1e-9
        c00, c11, c22 = d * f - e * e, a * f - c * c, a * d - b * b
        c01, c02, c12 = c * e - b * f, b * e - c * d, b * c - a * e
        det = a * c00 + b * c01 + c * c02
        return (c00, c01, c02, c11, c12, c22), det

    def _solve(self, m: NDArray, r: NDArray) -> NDArray[np.float64]:
        """``M⁻¹ R`` for entries ``m`` (6, B, P) and ``r`` (3, B, P, 9) → (3, B, P, 9)."""
        (c00, c01, c02, c11, c12, c22), det = self._adjugate(m)
        inv_det = np.where(det > 1e-12, 1.0 / np.where(det > 1e-12, det, 1.0), 0.0)
        rows = ((c00, c01, c02), (c01, c11, c12), (c02, c12, c22))
        return np.stack(
            [
                (row[0][..., None] * r[0] + row[1][..., None] * r[1] + row[2][..., None] * r[2])
                * inv_det[..., None]
                for row in rows
            ]
        )

    def _variance(self, m: NDArray[np.float64], pix: NDArray[np.intp] | None = None) -> NDArray:
        """Squared angular error (rad²) of noise from information entries ``m`` (6, B, P) (of
        the pixels ``pix`` when given)."""
        # closed-form adjugate of the symmetric 3×3 (batched np.linalg.inv is ~20× slower):
        # tr(P M⁻¹ P) = Σ_ij adj(M)_ij P_ij / det(M), P = I - n nᵀ (weights precomputed)
        (c00, c01, c02, c11, c12, c22), det = self._adjugate(m)
        q = self.projector[1 if m.dtype == np.float32 else 0]
        q = q if pix is None else q[:, pix]
        num = c00 * q[0]
        for c, qq in ((c11, q[1]), (c22, q[2]), (c01, q[3]), (c02, q[4]), (c12, q[5])):
            num += c * qq
        ok = det > 1e-12
        num *= NOISE_REL**2
        num /= np.where(ok, det, 1.0)
        return np.clip(np.where(ok, num, MAX_ERR2), 0.0, MAX_ERR2)

    def _bias(
        self, m: NDArray[np.float64], r: NDArray[np.float64], pix: NDArray[np.intp] | None = None
    ) -> NDArray:
        """Expected squared tangential bias (rad²) on the first pixels (or the bias pixels
        ``pix``), (B, P_bias)."""
        nb = self.n[: self.n_bias] if pix is None else self.n[pix]
        g_all = self.g_all if pix is None else self.g_all[:, pix]
        delta = self._solve(m, r) - g_all[:, None]  # (3, B, P_bias, 9)
        along = nb[:, 0, None] * delta[0] + nb[:, 1, None] * delta[1] + nb[:, 2, None] * delta[2]
        tang = np.sum(delta * delta, axis=(0, -1)) - np.sum(along * along, axis=-1)
        return np.clip(self.tau2 * tang, 0.0, MAX_ERR2)

    def _total(self, m: NDArray[np.float64], r: NDArray | None) -> NDArray[np.float64]:
        """RMS error in degrees for batched information ``m`` (6, B, P) and cross terms ``r``."""
        err2 = self._variance(m) @ self.wts
        if r is not None:
            err2 = err2 + self._bias(m[..., : self.n_bias], r) @ self.wts_bias
        return np.degrees(np.sqrt(err2))

    def cost(self, chosen: NDArray[np.intp]) -> float:
        # the sums are kept: the exchange search costs a layout, then scans it
        m, r = self._chosen_sums(np.asarray(chosen, dtype=np.intp))
        return float(self._total(m[:, None], None if r is None else r[:, None])[0])

    @property
    def candidate_count(self) -> int:
        return len(self.dirs)

    #: How the exchange search scans, fastest first: a proposed swap that the exact cost does
    #: not confirm earns a scan at the next level (:mod:`rti_rig.planner.optimal`).
    scan_levels = ({}, {"single": False}, {"exact": True})

    #: :meth:`swap_costs` takes ``below`` (the exchange search passes the cost to beat).
    bounded_scans = True

    def _weights_among(self, among: NDArray[np.intp]) -> tuple[NDArray, ...]:
        """The single-precision scan weights (K', P) of the candidates ``among``, their
        weights at the bias pixels (K', P_bias), the bias scan's per-candidate forms
        (:func:`rti_rig.planner.rank_one.candidate_forms`) and the largest weight, kept while
        they are the same (the unused candidates do not change until a swap is accepted)."""
        key = np.asarray(among, dtype=np.intp).tobytes()
        if self._among is None or self._among[0] != key:
            k = np.asarray(among, dtype=np.intp)
            if self._w32 is None:
                self._w32 = self.w_kp.astype(np.float32)
            forms = rank_one.candidate_forms(self.dirs[k], self.hsh[k], self.l6[k])
            w32 = self._w32[k]
            self._among = (
                key, (w32, self.w_kp[k, : self.n_bias], *forms, float(w32.max(initial=0.0)))
            )  # fmt: skip
        return self._among[1]

    def _inverses_at(
        self, chosen: NDArray[np.intp], position: int, total_m: NDArray[np.float64]
    ) -> tuple[tuple[NDArray, ...], Any]:
        """:func:`rti_rig.planner.rank_one.inverses` of the layout ``chosen`` without its light
        at ``position`` and its bias pixels' :func:`rti_rig.planner.rank_one.bias_prep_batch`
        (None when one is ill-conditioned), computed for the next few positions at once (a
        sweep scans them in order until a swap is accepted: 1 after a swap, twice as many each
        time the layout outlives a batch, at most :data:`INVERSE_BATCH`); the same values as
        one by one."""
        key = np.asarray(chosen, dtype=np.intp).tobytes()
        batch = self._inverse_batch
        if batch is not None and batch[0] == key and batch[1] <= position < batch[2]:
            j = position - batch[1]
            return tuple(a[:, j] if a.ndim == 3 else a[j] for a in batch[3]), batch[4][j]
        size = 1 if batch is None or batch[0] != key else min(2 * self._batch_size, INVERSE_BATCH)
        self._batch_size = size
        stop = min(position + size, len(chosen))
        lights = np.asarray(chosen, dtype=np.intp)[position:stop]
        base = total_m[:, None, :] - self._outer_at(lights, slice(None))  # (6, B, P)
        inv = rank_one.inverses(base, self.n)
        prep: list = [None] * len(lights)
        total_r = self._chosen_sums(chosen)[1]
        nb = self.n_bias
        if total_r is not None and np.all(inv[1][:, :nb] > rank_one.WELL_CONDITIONED):
            every = np.arange(nb)  # gathered as a scan gathers its well-conditioned pixels
            rb = total_r[:, None] - self._cross_at(lights, slice(None))  # (3, B, Pb, 9)
            prep = rank_one.bias_prep_batch(
                inv[0][:, :, every], inv[3][:, :, every], self.n[every], rb[:, :, every],
                self.g_all[:, every],
            )  # fmt: skip
        self._inverse_batch = (key, position, stop, inv, prep)
        return self._inverses_at(chosen, position, total_m)

    def _chosen_sums(self, chosen: NDArray[np.intp]) -> tuple[NDArray, NDArray | None]:
        """Information and cross terms of the layout ``chosen`` (kept while it is unchanged:
        a sweep scans every position of one layout until a swap is accepted)."""
        key = np.asarray(chosen, dtype=np.intp).tobytes()
        if self._sums is None or self._sums[0] != key:
            chosen = np.asarray(chosen, dtype=np.intp)
            r = self._cross_sum(chosen) if self.tau2 > 0 else None
            self._sums = (key, self._information(chosen), r)
        return self._sums[1], self._sums[2]

    def swap_costs(
        self,
        chosen: NDArray[np.intp],
        position: int,
        exact: bool = False,
        among: NDArray[np.intp] | None = None,
        single: bool = True,
        below: float | None = None,
    ) -> NDArray[np.float64]:
        """Cost of replacing ``chosen[position]`` by each candidate (K,), in one batch; with
        ``among``, only those candidates are scored (the others cost inf: the exchange search
        leaves out the lights already chosen, half the candidates at 100 of 200 LEDs).

        By rank-one updates (:mod:`rti_rig.planner.rank_one`; pixels whose information without
        that light is near-singular are evaluated directly) unless ``exact``: then every pixel
        and candidate is evaluated directly (the reference). A pooled scan (``among`` over many
        pixel rows: a preview's) runs its well-conditioned pixels in single precision unless
        ``single`` is False. The exchange search re-scans in double precision, then exactly,
        when a proposed swap's cost is not confirmed (:attr:`scan_levels`).

        ``below`` (a cost): only the candidates that could cost less matter to the caller;
        a single-precision scan may return ``inf`` for those it proves cannot (the others'
        costs unchanged, bit for bit: :func:`rti_rig.planner.rank_one.scan`).
        """
        total_m, total_r = self._chosen_sums(chosen)
        out_light = np.asarray(chosen, dtype=np.intp)[position : position + 1]
        base = total_m - self._outer_at(out_light, slice(None))[:, 0]  # (6, P)
        rb = None if total_r is None else total_r - self._cross_at(out_light, slice(None))[:, 0]
        # few pixel rows (a level surface: 7): scoring every candidate is cheaper than
        # gathering the pool's arrays; the others are masked below
        pooled = among is not None and self.w_kp.shape[-1] >= POOL_MIN_PIXELS
        k = np.asarray(among, dtype=np.intp) if pooled else slice(None)
        every = slice(None)
        if exact:
            r = None if rb is None else rb[:, None] + self._cross_at(k, every)  # (3, K, Pb, 9)
            costs = self._total(base[:, None, :] + self._outer_at(k, every), r)
        else:
            w32, w_bias, forms_in, h2, w_max = (
                self._weights_among(among) if pooled else (None, None, None, None, None)
            )
            bias = None
            if rb is not None:
                bias = rank_one.BiasTerms(
                    rb, self.g_all, self.hsh[k], self.wts_bias, self.tau2, w_bias, forms_in, h2
                )
            batched = pooled and len(chosen) >= INVERSE_BATCH_MIN_LIGHTS
            pre = self._inverses_at(chosen, position, total_m) if batched else None
            res = rank_one.scan(
                base, self.w_kp, self.dirs[k], self.l6[k], self.n, self.wts, NOISE_REL**2,
                MAX_ERR2, bias, rows=k if pooled else None, w32=w32 if single else None,
                below=None if below is None else np.radians(below) ** 2 * (1 + 1e-12),
                w_max=w_max, l_max2=self._l_max2,
                pre=pre[0] if pre else None, bias_pre=pre[1] if pre else None,
            )  # fmt: skip
            err2 = res.err2
            if len(res.bad):
                m = base[:, None, res.bad] + self._outer_at(k, res.bad)
                err2 = err2 + self._variance(m, res.bad) @ self.wts[res.bad]
            if rb is not None and len(res.bad_bias):
                pix = res.bad_bias
                m = base[:, None, pix] + self._outer_at(k, pix)
                r = rb[:, None, pix] + self._cross_at(k, pix)
                err2 = err2 + self._bias(m, r, pix) @ self.wts_bias[pix]
            costs = np.degrees(np.sqrt(err2))
        if among is None:
            return costs
        out = np.full(len(self.dirs), np.inf)
        keep = np.asarray(among, dtype=np.intp)
        out[keep] = costs if pooled else costs[keep]
        return out

    def describe(self, value: float) -> str:
        signal = f" + {100 * self.gain_rel:g}% of the signal" if self.gain_rel > 0 else ""
        return f"expected RMS normal error {value:.2f}° at {100 * NOISE_REL:g}% noise{signal}"


def models_for(n: int) -> list[str]:
    """Relighting bases that ``n`` lights can determine (see :data:`MODEL_MIN_LIGHTS`)."""
    ok = [m for m, k in MODEL_MIN_LIGHTS.items() if n >= k and m != "lambert"]
    return ok or ["lambert"]


class RelightObjective:
    """Expected relighting MSE (per unit albedo) on held-out directions, for a basis.

    For coefficients ``c`` fitted on the chosen lights the held-out bias is
    ``mean_t (a_tᵀ c - f_t)² = cᵀ G c - 2 cᵀ h + k`` with ``G = A_Tᵀ A_T / T``,
    ``h = A_Tᵀ f / T`` and ``k = mean f_t²``, so no held-out image is ever rendered.
    With ``c_p = Q f_p``, ``Q = (A_SᵀA_S)⁻¹ A_Sᵀ``, the weighted sum over pixels is
    ``tr(G Q Φ_S Qᵀ) - 2 tr(Q Ψ_S) + Σ w k`` where ``Φ = Σ_p w_p f_p f_pᵀ`` and
    ``Ψ = Σ_p w_p f_p h_pᵀ`` are summed over pixels once for every pair of candidates: a
    layout's cost then never touches the pixels, which keeps the exchange search's swap scans
    (hundreds of layouts per scan) independent of the sample size.

    As for normals, real reflectance deviates from the model in ways one preview cannot show;
    the deviation is modelled as a random smooth function (order-3 hemispherical harmonics,
    RMS :data:`BIAS_REL` of albedo) and its expected held-out error after the basis is fitted on
    the chosen lights is added: ``τ² ‖A_T (A_SᵀA_S)⁻¹ A_Sᵀ H_S - H_T‖²_F / T``. It rewards
    layouts whose fit generalises over the whole hemisphere.
    """

    name = "relight"

    def __init__(
        self,
        sample: SurfaceSample,
        candidates: Candidates,
        model: str,
        bias_rel: float = BIAS_REL,
    ) -> None:
        if model not in N_COEFFICIENTS:
            raise ValueError(f"unknown relighting model '{model}'")
        self.model = model
        self.sample = sample
        self.a_cand = design_matrix(model, candidates.directions)  # (K, p)
        a_test = design_matrix(model, sample.held_out)  # (T, p)
        f_test = reflectance(sample, sample.held_out, sample.lit_held_out)  # (P, T)
        t = len(a_test)
        wts = sample.weights / sample.weights.sum()
        self.gram = a_test.T @ a_test / t  # (p, p)
        h = f_test @ a_test / t  # (P, p)
        self.k = float(np.mean(f_test * f_test, axis=1) @ wts)
        f_cand = reflectance(sample, candidates.directions, sample.lit_candidates)  # (P, K)
        wf = f_cand * wts[:, None]
        self.phi = f_cand.T @ wf  # (K, K)
        self.psi = wf.T @ h  # (K, p)
        self.a_test = a_test
        self.dev_cand = design_matrix("hsh3", candidates.directions)  # (K, 16)
        self.dev_test = design_matrix("hsh3", sample.held_out)  # (T, 16)
        self.tau2 = bias_rel**2 * 2 * np.pi / 16  # RMS deviation over the hemisphere = bias_rel

    def _costs(self, idx: NDArray[np.intp]) -> NDArray[np.float64]:
        """Costs of the layouts ``idx`` (B, N) of candidate indices."""
        a = self.a_cand[idx]  # (B, N, p)
        p = a.shape[-1]
        ata = np.swapaxes(a, 1, 2) @ a + 1e-8 * np.eye(p)
        inv = np.linalg.inv(ata)  # (B, p, p)
        q = inv @ np.swapaxes(a, 1, 2)  # (B, p, N)
        phi = self.phi[idx[:, :, None], idx[:, None, :]]  # (B, N, N)
        psi = self.psi[idx]  # (B, N, p)
        quad = np.einsum("ij,bjn,bnm,bim->b", self.gram, q, phi, q, optimize=True)
        cross = np.einsum("bin,bni->b", q, psi)
        bias2 = np.clip(quad - 2.0 * cross + self.k, 0.0, None)
        var = NOISE_REL**2 * np.einsum("ij,bji->b", self.gram, inv)
        dev = self.dev_cand[idx]  # (B, N, 16)
        miss = self.a_test @ (q @ dev) - self.dev_test  # (B, T, 16)
        unmodelled = self.tau2 * np.mean(np.sum(miss * miss, axis=-1), axis=-1)
        return bias2 + var + unmodelled

    @property
    def candidate_count(self) -> int:
        return len(self.a_cand)

    def cost(self, chosen: NDArray[np.intp]) -> float:
        return float(self._costs(np.asarray(chosen, dtype=np.intp)[None])[0])

    def swap_costs(
        self,
        chosen: NDArray[np.intp],
        position: int,
        exact: bool = False,
        among: NDArray[np.intp] | None = None,
    ) -> NDArray[np.float64]:
        """Cost of replacing ``chosen[position]`` by each candidate (always double precision);
        with ``among``, only those candidates are scored (the others cost inf)."""
        k = len(self.a_cand)
        pool = np.arange(k) if among is None else np.asarray(among, dtype=np.intp)
        idx = np.repeat(np.asarray(chosen, dtype=np.intp)[None], len(pool), axis=0)
        idx[:, position] = pool
        with np.errstate(all="ignore"):
            costs = self._costs(idx)
        out = np.full(k, np.inf)
        out[pool] = np.where(np.isfinite(costs), costs, np.inf)
        return out

    def describe(self, value: float) -> str:
        psnr = -10 * np.log10(max(value, 1e-12))
        return f"expected relighting error {psnr:.1f} dB PSNR ({self.model.upper()})"


def check_signal_noise(signal_noise: float, objective: str) -> None:
    """Refuse a signal-proportional noise outside [0, 1) or with an objective that ignores it."""
    if not (np.isfinite(signal_noise) and 0.0 <= signal_noise < 1.0):
        raise ScheduleError(
            f"--signal-noise must be a fraction in [0, 1) (e.g. 0.05 for 5 %), got {signal_noise}"
        )
    if signal_noise > 0 and objective != "normals":
        raise ScheduleError(
            f"--signal-noise is modelled by the normals objective only; drop it for --objective "
            f"{objective}"
        )


def check_material(material: str) -> None:
    """Refuse a surface declaration the planner does not model."""
    if material not in MATERIALS:
        raise ScheduleError(
            f"--material {material!r} is not known; choose {', '.join(MATERIALS)} (glossy: "
            "polished metal, gilding, varnish)"
        )


def make_objective(
    objective: str,
    sample: SurfaceSample,
    candidates: Candidates,
    n: int,
    start: NDArray[np.intp],
    signal_noise: float = 0.0,
) -> NormalsObjective | RelightObjective:
    """The objective to optimise; for ``relight`` the basis that ``start`` fits best is chosen.

    ``signal_noise`` (relative to the signal, see :data:`SIGNAL_NOISE_JPEG_DOME`) is modelled by
    the ``normals`` objective only; the planner refuses it with any other objective
    (:func:`check_signal_noise`, called once before planning starts).
    """
    if objective == "normals":
        return NormalsObjective(sample, candidates, gain_rel=signal_noise)
    if objective == "relight":
        best: RelightObjective | None = None
        best_cost = float("inf")
        for model in models_for(n):
            obj = RelightObjective(sample, candidates, model)
            c = obj.cost(start)
            if c < best_cost:
                best, best_cost = obj, c
        assert best is not None
        return best
    raise ScheduleError(f"unknown objective '{objective}'; use one of {', '.join(OBJECTIVES)}")
