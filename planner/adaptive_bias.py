"""A bias-aware design score: each candidate design's error *simulated* on this object.

Why: the Cramér–Rao bound of the Lambertian fit (:mod:`rti_rig.planner.adaptive`) is a
variance bound; it ranks the elevation floors alike on every scene, while what decides the
best floor on a real object — gloss pulling the fit towards the highlight, cast shadows,
grazing light on a tilted surface — is bias, and the robust fit's own rules (which observations
it discards) decide how much of it survives. So, from the images captured so far, a small
global reflectance model of this object is fitted beyond Lambert, each design's observations
are simulated at the sampled pixels, the *same robust fit the benchmarks score* is run on them,
and the design is scored by the mean angle between the refitted and the modelled normals.

The model (:class:`ObjectModel`), fitted to the K captured observations of P sampled pixels:

* per pixel: the fitted normal and albedo (the "truth" of the simulation);
* a **specular lobe** shared by the object: ``ks (n·h)^e`` (Blinn–Phong about the half-way
  vector to the camera, +z), strength and exponent by least squares over a grid of exponents
  on the positive residuals of the Lambertian fit (what the robust fit discards as highlights);
* **cast shadows** per pixel: a captured light that faced the pixel but left it dark (or far
  below the fit) marks a horizon in its azimuth: a candidate light within
  :data:`SHADOW_AZ_DEG` of that azimuth and not higher than it is modelled as shadowed too
  (a relief's horizon rises monotonically as the light drops); and, given the relief
  integrated from the normals, shadows marched over it (:func:`soft_visibility`) — its depth
  optionally fitted to the captured shadows (:data:`FIT_RELIEF_GAIN`,
  :mod:`rti_rig.planner.adaptive_relief`; off: measured not to help, docs/adaptive.md);
* **noise**: the robust scale of the kept observations' residuals (at least the noise floor),
  and its dependence on the signal (:func:`fit_noise_model`: variance ``a + b × signal``, a
  camera's shot noise, fitted against what the model renders), with which the design
  scores' simulated observations and held-out photographs are drawn
  (:meth:`ObjectModel.noise_sd`) — not the stop's estimate, which keeps the constant it is
  calibrated with (:data:`ESTIMATE_SIGNAL_NOISE`).

Simulations use fixed seeds (common random numbers across designs): a decision stays a
deterministic function of the images, so ``--resume`` repeats it. The robust fit is passed in
(``fit``): the planner does not import :mod:`rti_rig.reconstruct` (layer rule); the use case
injects it.
"""

from __future__ import annotations

import functools
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

#: Exponents of the specular lobe tried (Blinn–Phong; 2/e ≈ GGX α²).
LOBE_EXPONENTS = (4.0, 8.0, 16.0, 32.0, 64.0, 128.0, 256.0, 512.0)
#: A lobe value at or below this is 0 (:func:`lobes`).
LOBE_FLOOR = 1e-9
#: A captured light's shadow extends to candidate lights within this azimuth difference.
SHADOW_AZ_DEG = 30.0
#: Pixels simulated per design (a fixed subset of the chooser's sample: every k-th).
SIM_PIXELS = 400
#: Noise draws per design (fixed seeds).
SIM_DRAWS = 2
#: Seed of the simulation's noise.
SIM_SEED = 20261124
#: The relief's cast-shadow march: steps (pixels) and how far the terrain must rise above the
#: ray (pixels) — shallow: the simulator's shadows of a tablet's impressions are 0.1–0.5 px deep.
MARCH_STEPS = 24
SOFT_PX = 1.0
#: Whether the relief's depth is fitted to the captured shadows (``planner.adaptive_relief``).
#: Off: measured (docs/adaptive.md, "Why the three losses remain") it does not flip the
#: tablet's ranking and makes the polished coin worse at 9 lights.
FIT_RELIEF_GAIN = False
#: Below this n·l a light is not expected to light the pixel (as the chooser's GRAZING_COS).
FACING_COS = 0.15
#: Whether the simulated noise depends on the signal (:func:`fit_noise_model`) rather than
#: being the one constant ``noise`` for every observation (docs/adaptive.md, "Signal-dependent
#: noise").
SIGNAL_NOISE = True
#: The noise fit's signal bins (quantiles of the kept observations' fitted signal) and the
#: fewest observations a bin needs; fewer than :data:`NOISE_MIN_BINS` such bins, or a signal
#: range of less than :data:`NOISE_MIN_SPAN` (ratio of the top bin's to the bottom bin's
#: signal), and the fit cannot separate ``a`` from ``b``: the constant is kept.
NOISE_BINS = 8
NOISE_BIN_MIN = 20
NOISE_MIN_BINS = 3
NOISE_MIN_SPAN = 2.0
#: Pixels the noise is fitted on (every k-th of the sample).
NOISE_PIXELS = 500
#: The largest slope ``b`` taken for a camera's shot noise (variance per unit signal, the
#: images' units: 1 = full scale): 1/b is the full-well capacity in electrons at full scale,
#: and 1000 is far below any camera's (phones ~5 000, DSLRs 20 000–60 000; the simulator's
#: 1.7·10⁻⁵ is ~60 000). A steeper slope is the model's misfit growing with the signal (the
#: industrial scene's gloss and shadows: b 0.05–1.1), not noise in the photographs: the
#: constant is kept. Set a priori from that physics, after the industrial scene lost with no
#: bound (docs/adaptive.md, "Signal-dependent noise").
NOISE_MAX_SLOPE = 1e-3
#: Whether the error *estimate* (``simulate_error_deg``: ``--until-error``'s stopping rule)
#: draws the signal-dependent noise too. Off: the estimate is calibrated
#: (``planner.adaptive.SIM_ESTIMATE_SCALE``) with the constant, which carries the model's
#: misfit as noise; with the signal-dependent noise the dark polished coin's estimate fell to
#: half its measured error and its 2° and 4° sessions stopped early (3.58° at 46 lights, 6.10°
#: at 15; docs/adaptive.md, "Signal-dependent noise"). The designs are ranked with it.
ESTIMATE_SIGNAL_NOISE = False
#: Median of a χ²₁ variable: a bin's variance is its median squared residual over this.
_CHI2_1_MEDIAN = 0.45493642311957283
#: Whether the pixels the robust fit left unsolved are modelled with their least-squares
#: normal (:func:`solve_unsolved`) rather than the level normal the chooser keeps for them.
SOLVE_UNSOLVED = True
#: The worst condition number of a pixel's lit lights that :func:`solve_unsolved` solves (the
#: robust fit's ``COND_LIMIT`` is 100; the planner may not import it): 3× it, so that the
#: tilted plane's starting lights (~116) are solved, while at ~420 the noise amplified by the
#: conditioning left the solved normals further off than the level fallback (measured by a
#: second reader: 23° against 18° on a synthetic plane at σ = 0.003).
UNSOLVED_COND_LIMIT = 300.0
#: Whether observations at white (at or above :data:`CLIP_LEVEL`, the images in units of white)
#: are read as what a clipped pixel says, "at least this", rather than as measured values: left
#: out of :func:`solve_unsolved`'s least squares and of the noise, and kept in the lobe's fit as
#: lower bounds (:func:`fit_censored_lobe`). Why asked: on the polished coin's starting images at
#: 9 and 12 lights, clipped over much of the coin, the least squares took white for a measured
#: value and the lobe was fitted to 456 unclipped observations (ks 4e-5: a matte coin;
#: docs/adaptive.md, "Probes of 2026-12-05", fault 3). A variant measured by ``benchmarks.adaptive
#: --clipped-censored``, not what ships.
CLIPPED_CENSORED = False
#: An observation at or above this (in units of white) is clipped: the camera's top code, less
#: the rounding of an area average of 16-bit codes.
CLIP_LEVEL = 0.999

#: ``fit(obs (L, P), lights (L, 3)) -> (normals (P, 3), valid (P,))``: the robust fit, or None
#: when it refuses the light set (ill-conditioned). Any other error is a bug and propagates:
#: scoring it 90° would silently steer every decision to the default design.
FitFn = Callable[[NDArray[np.float32], NDArray[np.float64]], tuple[NDArray, NDArray] | None]


@dataclass(frozen=True)
class ObjectModel:
    """What the images so far say of this object beyond Lambert (see the module notes)."""

    normals: NDArray[np.float64]  # (P, 3)
    albedo: NDArray[np.float64]  # (P,)
    spec_strength: float  # ks, in the images' units
    spec_exponent: float
    noise: float  # per observation, images' units (the constant: shadows' threshold, evidence)
    shadow_el: NDArray[np.float64]  # (P, S) elevation (°) of each shadowing light, -inf: none
    shadow_az: NDArray[np.float64]  # (P, S) its azimuth (°)
    lights: NDArray[np.float64]  # (K, 3) captured
    shadowed: NDArray[np.bool_]  # (P, K) captured observation found cast-shadowed
    #: (height in pixels, rows (P,), cols (P,)): the relief cast shadows are marched over
    relief: tuple[NDArray, NDArray, NDArray] | None = None
    #: the gain of the relief's detail fitted to the captured shadows (1: as integrated)
    relief_gain: float = 1.0
    #: the noise's variance ``noise_var0 + noise_slope × signal`` (:func:`fit_noise_model`);
    #: ``noise_var0`` None: the constant ``noise`` for every observation
    noise_var0: float | None = None
    noise_slope: float = 0.0
    #: rendered columns, by light (see :func:`render`)
    rendered: dict = field(default_factory=dict, compare=False, repr=False)

    def noise_sd(self, clean: NDArray) -> NDArray[np.float64] | float:
        """The noise's deviation of observations whose noise-free value is ``clean`` (any
        shape; a float when the model's noise is the constant)."""
        if self.noise_var0 is None:
            return self.noise
        var = self.noise_var0 + self.noise_slope * np.maximum(np.asarray(clean, np.float64), 0.0)
        return np.sqrt(var)

    def evidence(self) -> dict[str, float]:
        out = {
            "spec_strength": round(self.spec_strength, 5),
            "spec_exponent": self.spec_exponent,
            "noise": round(self.noise, 5),
            "shadowed_fraction": round(float(self.shadowed.mean()), 4),
        }
        if self.noise_var0 is not None:
            out["noise_var0"] = float(f"{self.noise_var0:.4g}")
            out["noise_slope"] = float(f"{self.noise_slope:.4g}")
        return out


def _half_cos(n: NDArray, lights: NDArray) -> NDArray:
    h = lights + np.array([0.0, 0.0, 1.0])
    h = h / np.maximum(np.linalg.norm(h, axis=1, keepdims=True), 1e-9)
    return np.clip(n @ h.T, 0.0, 1.0)


def _lobe(c: NDArray, e: float) -> NDArray:
    """``c**e`` with what falls below :data:`LOBE_FLOOR` set to 0 (:func:`lobes`)."""
    return next(lobes(c, (e,)))


def lobes(c: NDArray, exponents: Sequence[float]) -> Iterator[NDArray]:
    """``c**e`` (``c`` clipped to [0, 1]) for each of ``exponents`` in turn, what falls to
    :data:`LOBE_FLOOR` or below set to 0 (denormals make powers 20× slower).

    An exponent a power of two times the one before (the lobe fit's grid, 4 … 512) is reached
    by squaring the previous power, ~4× cheaper than a power each (~20 ns a value): at 100
    images the eight powers over the kept observations took ~25 ms of a 0.15 s decision
    (docs/adaptive.md, "adaptive_time"). A value at the floor is zeroed before it is squared
    again, as its power would be. The results differ from ``**`` by rounding only (relative
    3e-14 at 512)."""
    base = np.clip(c, 0.0, 1.0)
    x, power = base, 1.0
    for e in exponents:
        ratio = e / power
        if ratio >= 2.0 and ratio.is_integer() and int(ratio) & (int(ratio) - 1) == 0:
            for _ in range(int(ratio).bit_length() - 1):
                x = x * x
                x[x <= LOBE_FLOOR] = 0.0
            power = float(e)
            yield x
        else:
            yield np.where(base > LOBE_FLOOR ** (1.0 / e), base, 0.0) ** e


def _az_el(d: NDArray) -> tuple[NDArray, NDArray]:
    return (
        np.degrees(np.arctan2(d[..., 1], d[..., 0])),
        np.degrees(np.arcsin(np.clip(d[..., 2], -1.0, 1.0))),
    )


def solve_unsolved(
    obs: NDArray,
    lights: NDArray[np.float64],
    normals: NDArray[np.float64],
    albedo: NDArray[np.float64],
    valid: NDArray[np.bool_],
    dark: float,
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.bool_], NDArray[np.intp]]:
    """(normals, albedo, valid, lit count) with the pixels the robust fit left unsolved
    (``valid`` False) solved by least squares on their lit observations (above ``dark``), where
    at least three are, their lights' condition number is at most
    :data:`UNSOLVED_COND_LIMIT`, and the normal found faces the camera and every light that lit
    the pixel (then counted valid); the others as given. The lit count (per pixel, 0 for those
    not solved here) tells the caller how many degrees of freedom a solved pixel's residuals
    have: with exactly three they are zero by construction.

    Why: the robust fit refuses a pixel whose lit lights are ill-conditioned (its
    ``cond_limit``), and the chooser keeps such a pixel with a level normal and its brightest
    observation as albedo — right for the bound (it is where the next light is most needed),
    wrong as the object the designs are simulated on. On the simulator's 50°-tilted plane at 6
    lights, the 4 starting lights leave one light on the far side of the plane and the other
    three at condition ~116 (> 100): every pixel unsolved, the model a level plane 50° off,
    whose simulated relighting ranked the floors wrongly (docs/adaptive.md, "Why the model
    rendered a matte tilted plane wrongly"). Three lit lights do determine the normal (with the
    noise amplified by their conditioning): a noisy tilted plane is the better model. Counted
    valid, the pixels solved so are evidence for shadows, and, where they have residual
    degrees of freedom (more than three lit lights), for the lobe and the noise
    (:func:`fit_object_model`). Solved from exactly three, they are not evidence for the lobe:
    where the robust fit solved a few pixels, the lobe of that tilted plane is still fitted to
    those alone (ks 272, e 128 on a matte surface, 4 draws of 8; fixing it moved no decision's
    error: docs/adaptive.md, "Probes of 2026-12-05")."""
    valid = np.asarray(valid, dtype=bool)
    lit_count = np.zeros(valid.shape, dtype=np.intp)
    todo = np.flatnonzero(~valid)
    if todo.size == 0:
        return normals, albedo, valid, lit_count
    o = np.asarray(obs, dtype=np.float64)[:, todo].T  # (U, K)
    w = ((o > dark) & ~_clipped(o)).astype(np.float64)
    count = w.sum(axis=1)
    lt = np.asarray(lights, dtype=np.float64)
    gram = np.einsum("uk,ki,kj->uij", w, lt, lt)  # (U, 3, 3) over each pixel's lit lights
    rhs = np.einsum("uk,uk,ki->ui", w, o, lt)
    ok = count >= 3
    if ok.any():
        eig = np.linalg.eigvalsh(gram[ok])  # ascending; cond(G) = cond(lit lights)²
        sub = eig[:, 0] > eig[:, -1] / UNSOLVED_COND_LIMIT**2
        ok[np.flatnonzero(ok)[~sub]] = False
    normals = np.array(normals, dtype=np.float64, copy=True)
    albedo = np.array(albedo, dtype=np.float64, copy=True)
    if not ok.any():
        return normals, albedo, valid, lit_count
    b = np.linalg.solve(gram[ok], rhs[ok][..., None])[..., 0]
    rho = np.linalg.norm(b, axis=1)
    n = b / np.maximum(rho, 1e-300)[:, None]
    # facing the camera, and every light that lit the pixel in front of it (a lit observation
    # behind the normal found says the Lambertian solve is not what lit it)
    lit_behind = ((n @ lt.T) <= 0.0) & (w[ok] > 0)
    good = (rho > 0) & (n[:, 2] > 0) & ~lit_behind.any(axis=1)
    which = todo[ok][good]
    normals[which] = n[good]
    albedo[which] = rho[good]
    valid = valid.copy()
    valid[which] = True
    lit_count[which] = count[ok][good].astype(np.intp)
    return normals, albedo, valid, lit_count


def _clipped(obs: NDArray) -> NDArray[np.bool_]:
    """Where an observation is at white (only with :data:`CLIPPED_CENSORED`; else nowhere)."""
    if not CLIPPED_CENSORED:
        return np.zeros(np.shape(obs), dtype=bool)
    return np.asarray(obs) >= CLIP_LEVEL


def fit_censored_lobe(
    r: NDArray, x: NDArray, r_low: NDArray, x_low: NDArray
) -> tuple[float, float]:
    """(ks ≥ 0, its cost) minimizing ``Σ (r − ks x)² + Σ max(0, r_low − ks x_low)²``: a lobe
    fitted to measured residuals ``r`` and to residuals ``r_low`` that are lower bounds (a
    clipped observation: the true value is at least white, so the lobe must reach at least
    it; above it costs nothing).

    How: the cost is convex and piecewise quadratic in ks; Newton's step on the bounds active at
    the current ks (those the lobe does not yet reach) is exact on each piece, so the iteration
    stops when the active set repeats (a few steps; capped at 50)."""
    # element-wise sums, not BLAS dot products: on a busy machine a vector dot waits for
    # BLAS's threads (measured 5–30 ms against 0.1 ms for these 30 000 terms)
    sxx = float((x * x).sum())
    sxr = float((x * r).sum())
    ks = max(0.0, sxr / sxx) if sxx > 0 else 0.0
    active = None
    for _ in range(50):
        act = r_low > ks * x_low
        if active is not None and np.array_equal(act, active):
            break
        active = act
        den = sxx + float((x_low[act] ** 2).sum())
        ks = max(0.0, (sxr + float((x_low[act] * r_low[act]).sum())) / den) if den > 0 else 0.0
    cost = float(((r - ks * x) ** 2).sum()) + float(
        (np.maximum(0.0, r_low - ks * x_low) ** 2).sum()
    )
    return ks, cost


def fit_noise_model(signal: NDArray, resid2: NDArray, floor: float) -> tuple[float, float] | None:
    """(a, b) of the noise's variance ``a + b × signal`` from kept observations' fitted
    ``signal`` and their squared *standardized* residuals ``resid2`` (each over its ``1 − h``,
    :func:`standardized_residuals2`), or None where the fit cannot separate a from b (then the
    constant serves).

    Why: a camera's noise is shot noise (the simulator's variance ≈ 1.7·10⁻⁵ × signal, ~0 in
    the dark; a real camera's likewise, plus read noise); the relighting score averages
    per-light PSNRs, and one constant σ for every observation makes a held-out light that
    leaves the object mostly dark as noisy as a bright one — it compressed the simulated
    ranking of the floors on the tilted plane (docs/adaptive.md). How: the observations are
    binned by quantiles of their signal (:data:`NOISE_BINS`); each bin's variance is its median
    squared residual over the χ²₁ median (robust to highlights and shadows the fit left in);
    the line through the bins' (median signal, variance) is Theil–Sen's (the median of
    pairwise slopes: robust, deterministic). ``a`` is at least ``floor²`` (the constant's
    floor); a slope that is not positive is no evidence of shot noise, one above
    :data:`NOISE_MAX_SLOPE` is misfit, not a camera's noise: None for both."""
    s = np.asarray(signal, dtype=np.float64).ravel()
    r2 = np.asarray(resid2, dtype=np.float64).ravel()
    if s.size < NOISE_BIN_MIN * NOISE_MIN_BINS:
        return None
    order = np.argsort(s, kind="stable")
    xs, vs = [], []
    for chunk in np.array_split(order, NOISE_BINS):
        if chunk.size < NOISE_BIN_MIN:
            continue
        xs.append(float(np.median(s[chunk])))
        vs.append(float(np.median(r2[chunk])) / _CHI2_1_MEDIAN)
    x, v = np.array(xs), np.array(vs)
    if x.size < NOISE_MIN_BINS or x[0] <= 0 or x[-1] < NOISE_MIN_SPAN * x[0]:
        return None
    i, j = np.triu_indices(x.size, 1)
    dx = x[j] - x[i]
    ok = dx > 0
    if not ok.any():
        return None
    b = float(np.median((v[j] - v[i])[ok] / dx[ok]))
    if not 0 < b <= NOISE_MAX_SLOPE:
        return None
    a = float(np.median(v - b * x))
    return max(a, floor**2), b


def standardized_residuals2(
    resid: NDArray, signal: NDArray, lights: NDArray[np.float64], use: NDArray[np.bool_]
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.bool_]]:
    """(K, P) squared residuals over ``1 − h`` (``h`` each observation's leverage in its
    pixel's least-squares fit on the observations ``use`` (K, P) marks), the signal each stands
    for, and where that is informative: a pixel with at least 4 such observations and
    ``1 − h`` ≥ 0.1.

    Why: a pixel fitted on 3 lit lights has residuals 0 whatever the noise (the tilted plane's
    first decision: every pixel so), and on few lights the residual degrees of freedom fall on
    each light by its leverage. With ``M = (I − H)²`` (element-wise) a residual's variance is
    ``Σ_j M_kj σ_j²``: for ``σ² = a + b s`` that is ``(1 − h_kk)(a + b s̄_k)`` with ``s̄_k`` the
    ``M``-weighted mean signal of the pixel's observations — so a residual over ``1 − h_kk``
    measures the noise at ``s̄_k``, not at its own signal (a dark observation's residual
    carries the bright ones' noise too). The constant's ``k/(k−3)`` is the average of this
    correction."""
    w = np.asarray(use, dtype=np.float64)
    lt = np.asarray(lights, dtype=np.float64)
    m = w.sum(axis=0)
    gram = np.einsum("kp,ki,kj->pij", w, lt, lt)
    ok_p = (m >= 4) & (np.linalg.det(gram) > 1e-12)
    inv = np.zeros_like(gram)
    inv[ok_p] = np.linalg.inv(gram[ok_p])
    # in closed form, never the (P, K, K) hat matrices (320 MB and 0.36 s at K = 200): with
    # q_k = G⁻¹ l_k, h_kk = l_k·q_k, and Σ_j M_kj s_j = s_k (1 − 2 h_kk) + q_kᵀ S q_k where
    # S = Σ_j w_j s_j l_j l_jᵀ (so Σ_j M_kj = 1 − h_kk)
    sig = np.asarray(signal, dtype=np.float64)
    q = np.matmul(lt[None, :, :], inv)  # (P, K, 3)
    h = np.einsum("pkj,kj->kp", q, lt) * w  # (K, P), on used observations
    one_h = w - h
    s_mat = np.einsum("kp,ki,kj->pij", w * sig, lt, lt)  # (P, 3, 3)
    quad = np.einsum("pki,pij,pkj->kp", q, s_mat, q)
    with np.errstate(invalid="ignore", divide="ignore"):
        s_eff = w * (sig * (1.0 - 2.0 * h) + quad) / one_h
    good = np.asarray(use, dtype=bool) & ok_p[None, :] & (one_h >= 0.1)
    r2 = np.where(good, np.asarray(resid, np.float64) ** 2 / np.maximum(one_h, 0.1), 0.0)
    return r2, np.where(good, s_eff, 0.0), good


def fit_object_model(
    obs: NDArray,
    lights: NDArray[np.float64],
    normals: NDArray[np.float64],
    albedo: NDArray[np.float64],
    valid: NDArray[np.bool_],
    dark: float,
    noise_floor: float,
    relief: tuple[NDArray, NDArray, NDArray] | None = None,
) -> ObjectModel:
    """The object's model from its K × P observations and the robust fit's normals/albedo
    (the pixels it left unsolved solved by least squares where their lit lights allow:
    :func:`solve_unsolved`, then counted valid)."""
    obs = np.asarray(obs, dtype=np.float64)  # (K, P)
    # the pixels whose residuals say something about noise and gloss: the robust fit's, and
    # those solved here from more than three lit lights (three fit exactly: zero residuals
    # would pull the noise to its floor and the lobe to zero whatever the surface)
    evidence = np.asarray(valid, dtype=bool)
    if SOLVE_UNSOLVED:
        normals, albedo, valid, lit_count = solve_unsolved(
            obs, lights, normals, albedo, valid, dark
        )
        evidence = evidence | (lit_count > 3)
    cos = (normals @ lights.T).T  # (K, P)
    lam = albedo[None, :] * np.maximum(cos, 0.0)
    resid = obs - lam
    facing = (cos > FACING_COS) & valid[None, :]
    clipped = _clipped(obs)
    lit = facing & (obs > dark) & ~clipped
    # noise: robust scale of the residuals of lit observations near the fit
    r_lit = np.abs(resid[lit & evidence[None, :]])
    noise = float(1.4826 * np.median(r_lit)) if r_lit.size else 0.0
    k = len(lights)
    if k > 3:
        noise *= float(np.sqrt(k / (k - 3)))
    noise = max(noise, noise_floor)
    # cast shadows: facing, but dark, or far below the fit
    # (a clipped observation is bright, whatever the fit says: never a shadow)
    below = (obs <= dark) | (resid < -np.maximum(4.0 * noise, 0.25 * lam))
    shadowed = facing & ~clipped & below
    shadowed = shadowed.T  # (P, K)
    # specular lobe: least squares of the positive-side residuals on ks * (n.h)^e
    hc = _half_cos(normals, lights).T  # (K, P)
    use = lit & ~shadowed.T & evidence[None, :]
    r = resid[use]
    c = hc[use]
    best = (np.inf, 0.0, LOBE_EXPONENTS[0])
    # clipped observations (only with CLIPPED_CENSORED): lower bounds on the lobe, not values
    low = facing & clipped & evidence[None, :]
    r_low, c_low = resid[low], hc[low]
    for e, x, x_low in zip(
        LOBE_EXPONENTS, lobes(c, LOBE_EXPONENTS), lobes(c_low, LOBE_EXPONENTS), strict=True
    ):
        ks, sse = fit_censored_lobe(r, x, r_low, x_low)
        if sse < best[0] - 1e-12:
            best = (sse, ks, e)
    _, ks, e = best
    noise_ab = None
    if SIGNAL_NOISE:  # the kept observations' residuals against the signal fitted to them
        # against what the model renders — the Lambertian part *and* the fitted lobe: a
        # residual against the Lambertian part alone takes the gloss the model already
        # renders for noise, counting it twice (a second reader: the coin's b 1.1e-4 at 18
        # images); the signal the noise grows with is the rendered one. Not rendered here:
        # the relief's soft cast shadows (the model's visibility, built after this fit) — an
        # observation in a penumbra that the shadow test above and the highlight test below
        # both pass counts its shading as noise (a small, noise-inflating bias)
        shown = lam + ks * _lobe(hc, e) * (cos > 0.0)
        dev = obs - shown
        kept = use & (np.abs(dev) <= np.maximum(4.0 * noise, 0.25 * shown))  # no highlight
        # on a fixed subset of the pixels (the fit needs a few hundred observations)
        sub = np.arange(0, lam.shape[1], max(1, lam.shape[1] // NOISE_PIXELS))
        r2, s_eff, good = standardized_residuals2(dev[:, sub], shown[:, sub], lights, kept[:, sub])
        noise_ab = fit_noise_model(s_eff[good], r2[good], noise_floor)
    gain = 1.0
    if relief is not None and FIT_RELIEF_GAIN:
        from rti_rig.planner.adaptive_relief import fit_relief_gain

        height, rows, cols = relief
        gain, height = fit_relief_gain(height, rows, cols, obs, lights, normals, albedo, valid)
        relief = (height, rows, cols)
    az, el = _az_el(lights)
    shadow_el = np.where(shadowed, el[None, :], -np.inf)
    shadow_az = np.broadcast_to(az[None, :], shadowed.shape).copy()
    return ObjectModel(
        normals=normals,
        albedo=albedo,
        spec_strength=ks,
        spec_exponent=e,
        noise=noise,
        shadow_el=shadow_el,
        shadow_az=shadow_az,
        lights=lights,
        shadowed=shadowed,
        relief=relief,
        relief_gain=gain,
        noise_var0=None if noise_ab is None else noise_ab[0],
        noise_slope=0.0 if noise_ab is None else noise_ab[1],
    )


def visibility(
    model: ObjectModel, lights: NDArray[np.float64], pix: NDArray[np.intp] | None = None
) -> NDArray[np.float64]:
    """(P', L): False where the model expects a cast shadow from each light on pixels ``pix``
    (all: None) — seen under a captured light (and lower ones in its azimuth), or marched over
    the relief."""
    pix = np.arange(len(model.normals)) if pix is None else pix
    az, el = _az_el(lights)
    s_az, s_el = model.shadow_az[pix], model.shadow_el[pix]
    blocked = np.zeros((len(pix), len(lights)), dtype=bool)
    pp, kk = np.nonzero(np.isfinite(s_el))  # the few (pixel, captured light) shadows seen
    if pp.size:
        daz = np.abs((s_az[pp, kk][:, None] - az[None, :] + 180.0) % 360.0 - 180.0)
        hit = (daz <= SHADOW_AZ_DEG) & (el[None, :] <= s_el[pp, kk][:, None] + 1e-9)
        starts = np.flatnonzero(np.r_[True, pp[1:] != pp[:-1]])  # pp is sorted
        blocked[pp[starts]] = np.logical_or.reduceat(hit, starts, axis=0)
    vis = ~blocked
    if model.relief is not None:
        height, rows, cols = model.relief
        return vis * soft_visibility(height, rows[pix], cols[pix], lights)
    return vis.astype(np.float64)


def soft_visibility(
    height: NDArray[np.float64],
    rows: NDArray[np.intp],
    cols: NDArray[np.intp],
    lights: NDArray[np.float64],
) -> NDArray[np.float64]:
    """(P, L) in [0, 1]: marched over the relief (height in pixels) from each pixel towards
    each light; the light fades as the terrain rises above the ray, over :data:`SOFT_PX` —
    a shadow's edge is partly lit, and it is those partly lit observations (too bright to be
    discarded as dark) that bias a robust fit, not the fully dark ones."""
    h, w = height.shape
    d = np.asarray(lights, dtype=np.float64)
    horiz = np.hypot(d[:, 0], d[:, 1])
    safe = np.maximum(horiz, 1e-9)
    sx, sy, rise = d[:, 0] / safe, d[:, 1] / safe, d[:, 2] / safe
    t = np.arange(1, MARCH_STEPS + 1, dtype=np.float32)
    height = np.asarray(height, dtype=np.float32)
    h0 = height[rows, cols]
    vis = np.ones((len(rows), len(d)))
    sx, sy, rise = sx.astype(np.float32), sy.astype(np.float32), rise.astype(np.float32)
    top = float(height.max())
    todo = np.flatnonzero((horiz >= 1e-6) & (top - float(h0.min()) > rise - SOFT_PX))
    if todo.size == 0:
        return vis
    # (P, T, L') at once: the march of every pixel towards every light that can be blocked.
    # The steps' offsets (float32 products, as the pixels' float64 positions add them) are
    # shared by every pixel, the rounding and clipping done in place, the terrain read by one
    # flat gather: 25 % less time than the plain expressions, the same values bit for bit.
    dx = (t[:, None] * sx[todo][None, :]).astype(np.float64)  # (T, L')
    dy = (t[:, None] * sy[todo][None, :]).astype(np.float64)
    cc = cols[:, None, None].astype(np.float64) + dx[None]
    rr = rows[:, None, None].astype(np.float64) - dy[None]
    inside = (cc >= 0) & (cc <= w - 1) & (rr >= 0) & (rr <= h - 1)
    ci = np.clip(np.rint(cc, out=cc), 0, w - 1, out=cc)
    ri = np.clip(np.rint(rr, out=rr), 0, h - 1, out=rr)
    ri *= w
    ri += ci
    excess = height.ravel().take(ri.astype(np.intp))  # float32 terrain under each step
    excess -= h0[:, None, None] + (t[:, None] * rise[todo][None, :])[None]  # above the ray
    excess[~inside] = -np.inf
    vis[:, todo] = np.clip(1.0 - excess.max(axis=1) / SOFT_PX, 0.0, 1.0)
    return vis


@dataclass(frozen=True)
class NearLamps:
    """Lamps at a finite distance, as the stop's estimate renders them (:func:`render`).

    Why: a fit reads each light as one direction at one intensity, the direction from the
    object's centre; a lamp ``distance_mm`` away reaches a pixel ``p`` off the centre from
    another direction (by about ``|p| / distance``) and at another irradiance (by about
    ``2 p·l / distance``), so the fitted normals carry a bias that no simulation under
    directional lights shows. On the shipped arm (lamps at 400 mm over a 12.8 mm field) the
    point estimate under directional lights was 0.30° where the session measured 1.61°.

    ``xy_mm`` (P, 2): each of the model's pixels' position on the object plane (x to the right
    of the image, y to its top, from the frame's centre, mm)."""

    distance_mm: float
    xy_mm: NDArray[np.float64]

    def key(self) -> tuple[float, int]:
        """What tells two geometries apart in the rendered columns' cache."""
        return (float(self.distance_mm), hash(np.asarray(self.xy_mm).tobytes()))


def render(
    model: ObjectModel,
    lights: NDArray[np.float64],
    pix: NDArray[np.intp],
    near: NearLamps | None = None,
) -> NDArray:
    """Noise-free modelled observations (L, P') of pixels ``pix`` under ``lights`` (each a
    direction; with ``near``, a point lamp that far along it); each light's column is kept in
    ``model.rendered`` (one decision renders a light once, whether for the estimate or for
    any design)."""
    which = hash((pix.tobytes(), None if near is None else near.key()))
    keys = [(tuple(np.round(v, 9)), which) for v in lights]
    todo = [i for i, k in enumerate(keys) if k not in model.rendered]
    if todo:
        new = _render(model, lights[todo], pix, near)
        for j, i in enumerate(todo):
            model.rendered[keys[i]] = new[j]
    return np.stack([model.rendered[k] for k in keys])


def _render(
    model: ObjectModel,
    lights: NDArray[np.float64],
    pix: NDArray[np.intp],
    near: NearLamps | None = None,
) -> NDArray:
    n = model.normals[pix]
    vis = visibility(model, lights, pix)  # cast shadows: from the lamp's direction at the centre
    if near is None:
        cos = n @ lights.T  # (P', L)
        out = model.albedo[pix, None] * np.maximum(cos, 0.0)
        if model.spec_strength > 0:
            lobe = _lobe(_half_cos(n, lights), model.spec_exponent)
            out = out + model.spec_strength * lobe * (cos > 0)
        return (out * vis).T
    at = np.zeros((len(pix), 3))
    at[:, :2] = np.asarray(near.xy_mm, dtype=np.float64)[pix]
    to = near.distance_mm * lights[None, :, :] - at[:, None, :]  # (P', L, 3) pixel -> lamp
    r = np.maximum(np.linalg.norm(to, axis=2), 1e-9)
    dirs = to / r[..., None]
    falloff = (near.distance_mm / r) ** 2  # the irradiance relative to the centre's
    cos = np.einsum("pk,plk->pl", n, dirs)
    out = model.albedo[pix, None] * np.maximum(cos, 0.0) * falloff
    if model.spec_strength > 0:
        half = dirs + np.array([0.0, 0.0, 1.0])
        half /= np.maximum(np.linalg.norm(half, axis=2, keepdims=True), 1e-9)
        hc = np.clip(np.einsum("pk,plk->pl", n, half), 0.0, 1.0)
        out = out + model.spec_strength * falloff * _lobe(hc, model.spec_exponent) * (cos > 0)
    return (out * vis).T


def light_noise(
    lights: NDArray[np.float64],
    draws: int,
    npix: int,
    sigma: float | NDArray[np.float64],
    seed: int,
) -> NDArray[np.float64]:
    """(draws, L, npix) Gaussian noise of deviation ``sigma`` (a float, or (L, npix): each
    observation's, :meth:`ObjectModel.noise_sd`), each light's drawn from a seed of its own
    direction: the same in every design, call and decision of a session, and for the normals
    and the relighting scores alike (common random numbers)."""
    if np.ndim(sigma) == 0:
        return np.stack(
            [sigma * _unit_noise(seed, _direction_key(v), draws, npix) for v in lights], 1
        )
    z = np.stack([_unit_noise(seed, _direction_key(v), draws, npix) for v in lights], 1)
    return z * np.asarray(sigma, dtype=np.float64)[None]


def _direction_key(v: NDArray[np.float64]) -> tuple[int, ...]:
    return tuple(int(k) for k in np.round(v * 1e6).astype(np.int64) % 2**31)


@functools.lru_cache(maxsize=4096)
def _unit_noise(seed: int, key: tuple[int, ...], draws: int, npix: int) -> NDArray[np.float64]:
    """A light's standard normal draws, kept: a session scores the same candidates at every
    decision, and seeding a generator per light cost ~50 µs each (10 ms for 200 LEDs).
    ``sigma * z`` is bit for bit what ``normal(0, sigma)`` draws from the same generator."""
    z = np.random.default_rng([seed, *key]).standard_normal((draws, npix))
    z.flags.writeable = False
    return z


def simulate_error_deg(
    model: ObjectModel,
    lights: NDArray[np.float64],
    fit: FitFn,
    pixels: int = SIM_PIXELS,
    draws: int = SIM_DRAWS,
    seed: int = SIM_SEED,
    near: NearLamps | None = None,
) -> float:
    """Mean angle (°) between the robust fit of simulated observations under ``lights`` and
    the model's normals (see :func:`simulate_designs`; the noise: see
    :data:`ESTIMATE_SIGNAL_NOISE`). ``near``: the lamps' geometry the observations are
    rendered with, the fit still given the directions alone (None: directional lights)."""
    return simulate_designs(
        model, [lights], fit, pixels, draws, seed, signal_noise=ESTIMATE_SIGNAL_NOISE, near=near
    )[0]


def simulate_designs(
    model: ObjectModel,
    designs: list[NDArray[np.float64]],
    fit: FitFn,
    pixels: int = SIM_PIXELS,
    draws: int = SIM_DRAWS,
    seed: int = SIM_SEED,
    signal_noise: bool = True,
    near: NearLamps | None = None,
) -> list[float]:
    """Per design (its full light set, (L, 3)): the mean angle (°) between the robust fit of
    simulated observations and the model's normals, over a fixed pixel subset and ``draws``
    noise draws (each observation's deviation the model's, :meth:`ObjectModel.noise_sd`; with
    ``signal_noise`` False the constant ``noise``); a pixel the fit cannot solve counts with
    the view axis, as the benchmarks count it; a refused fit counts 90°.

    Every light is rendered once for all designs, and its noise is the same in every design
    that has it (common random numbers: the designs are compared, not the draws)."""
    p = len(model.normals)
    pix = np.arange(0, p, max(1, p // pixels))[:pixels]
    allx = np.concatenate(designs)
    union, inverse = np.unique(np.round(allx, 9), axis=0, return_inverse=True)
    inverse = inverse.reshape(-1)
    clean = render(model, union, pix, near)  # (U, P')
    # each light's noise from a seed of its own direction: the same in every design and call
    sd = model.noise_sd(clean) if signal_noise else model.noise
    noise = light_noise(union, draws, len(pix), sd, seed)  # (draws, U, P')
    truth = model.normals[pix]
    out = []
    at = 0
    for lights in designs:
        cols = inverse[at : at + len(lights)]
        at += len(lights)
        errs = []
        for d in range(draws):
            noisy = np.clip(clean[cols] + noise[d][cols], 0.0, None).astype(np.float32)
            fitted = fit(noisy, lights)
            if fitted is None:  # a refused (ill-conditioned) fit: "90° off"
                errs.append(90.0)
                continue
            normals, valid = fitted
            est = np.where(np.asarray(valid)[:, None], normals, [0.0, 0.0, 1.0])
            cosang = np.clip((est * truth).sum(axis=1), -1.0, 1.0)
            errs.append(float(np.degrees(np.arccos(cosang)).mean()))
        out.append(float(np.mean(errs)))
    return out
