"""A relighting design score for adaptive acquisition (``run --adaptive --objective relight``).

Why: the designs an adaptive session chooses among (homogeneous layouts of N above one of
:data:`rti_rig.planner.adaptive.DESIGN_FLOORS`) are ranked by the *simulated normal error* of
this object by default. Relighting prefers other floors: a relighting basis fitted on the
chosen lights is judged on every light it did *not* see, down to the horizon, so low lights
matter for it where they only add bias to normals (the polished coin's PSNR-tuned floor is 0°
where its normals-tuned floor is 20°: docs/adaptive.md). So with ``--objective relight`` each
design is scored the way the benchmarks score relighting, on this object's model:

* the object model is the normals score's (:mod:`rti_rig.planner.adaptive_bias`: the fitted
  normals and albedo of the sampled pixels, a specular lobe, cast shadows seen and marched over
  the relief, noise);
* a design's observations (all N lights) are simulated at the same pixels and with the same
  noise (each light's noise seeded from its own direction) as the normals score;
* **the relighting basis the benchmarks fit** at N lights (:func:`relight_basis`: the richest
  basis N lights determine, ``objectives.models_for(N)[-1]``: HSH1 at 6, PTM at 9 and 12, HSH2
  at 18) is fitted on them by the project's own fit (injected as ``relight``: the planner does
  not import :mod:`rti_rig.reconstruct`), and relit to every candidate light still available
  that *none* of the designs takes (:func:`shared_held_out`: the same lights for every design,
  as the benchmarks compare layouts; each design's own left-out lights only where the designs
  take every light left) — the renderings clipped at white (:data:`SATURATION`);
* each held-out light's PSNR (data range 1, the images' white) against the model's rendering
  under it, with the model's noise in the reference (a held-out image is a photograph: its
  noise adds ``σ²`` to the squared error, in expectation), averaged over the held-out lights
  as ``benchmarks.metrics.relight_psnr`` averages them, then over the noise draws.

The design kept is the current one unless another is simulated better by
:data:`RELIGHT_MARGIN_DB` (the same hysteresis as the normals score's ``SIM_MARGIN``). Beside
the floors' designs, the fitted relight design (:data:`RELIGHT_FITTED_DESIGN`,
:mod:`rti_rig.planner.adaptive_relight_design`) is scored and taken the same way.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray

from rti_rig.planner.adaptive_bias import (
    SIM_DRAWS,
    SIM_PIXELS,
    SIM_SEED,
    ObjectModel,
    light_noise,
    render,
)
from rti_rig.planner.objectives import models_for

#: The design objectives of an adaptive session with ``--lights N``.
OBJECTIVES = ("normals", "relight")
#: Another floor's design is taken only if its simulated relighting PSNR is higher than the
#: current design's by this many dB: chosen leave one scene out on the simulator
#: (``python -m benchmarks.adaptive_relight_margin``; docs/adaptive.md), never on real data.
RELIGHT_MARGIN_DB = 0.5
#: Also offer, with the relight objective, the fitted relight design
#: (:mod:`rti_rig.planner.adaptive_relight_design`: ``optimal --objective relight`` on the object
#: model fitted so far, the lights shot kept), scored and taken like the floors' designs (the
#: same simulated PSNR, margin and hysteresis). On: chosen leave one scene out on the simulator
#: against the floors alone (``python -m benchmarks.adaptive_relight_variants``,
#: docs/adaptive.md); ``benchmarks.adaptive --no-relight-fitted-design`` turns it off.
RELIGHT_FITTED_DESIGN = True
#: ... for designs of at most this many lights: the range it was measured on (N = 6…18), where
#: its exchange search (two dB-weighted rounds, up to 4 sweeps of at most 14 lights not shot)
#: keeps a decision near 0.2 s from a 24-MP frame; beyond, its sweeps over more lights (and
#: the 16 coefficients of HSH3) took 0.3–0.44 s (``benchmarks.adaptive_time``, docs), so
#: larger designs are chosen among the floors alone, as before.
RELIGHT_FITTED_MAX_LIGHTS = 18
#: The images' top code in their units (``small_grey`` divides by the white level, and the
#: camera clips there): the object model's renderings, as the relighting score uses them (the
#: designs' simulated photographs and the held-out references), are clipped to it, as a
#: photograph is. Why: with few images the lobe fit can choose a sharp exponent whose strength
#: only the lobe's tail constrains (a matte tilted plane after its 4 starting images: ks 9e4
#: at exponent 512); unclipped it rendered held-out lights at 8e4 × white and every floor's
#: design read −10 to −27 dB at 18 lights, a ranking of noise (docs/adaptive.md, "A rendering
#: no camera can give"). None: unclipped (up to format 9's first builds). The normals score is
#: not clipped: its robust fit discards such highlights, and clipping it was measured worse.
SATURATION: float | None = 1.0
#: Judge every design's relighting on the same lights: those still available that none of the
#: designs takes (:func:`shared_held_out`), as the benchmarks compare layouts since
#: 2026-11-24. False: each design on the lights it leaves out (up to format 9's first builds).
SHARED_HELD_OUT = True
#: PSNR reported for a perfect relighting (as ``benchmarks.metrics.PSNR_CAP_DB``).
PSNR_CAP_DB = 100.0

#: ``relight(obs (L, P), lights (L, 3), held (T, 3), basis) -> (T, P)``: the relighting basis
#: ``basis`` fitted on the observations and relit to the held-out lights (clamped at 0, as the
#: fitted models relight), or None when the fit refuses the light set.
RelightFn = Callable[
    [NDArray[np.float32], NDArray[np.float64], NDArray[np.float64], str], NDArray | None
]


def relight_basis(n_total: int) -> str:
    """The relighting basis a session of ``n_total`` lights is scored with (the benchmarks'
    relighting table's). Scoring instead the order-1 HSH that `rti-rig fit` writes from 6–12
    lights was measured (``benchmarks.adaptive --relight-basis hsh1``; docs/adaptive.md): no loss
    of either table removed, four wins of this one lost."""
    return models_for(n_total)[-1]


def saturated(clean: NDArray) -> NDArray:
    """The model's rendering as a camera records it: nothing above :data:`SATURATION`."""
    return clean if SATURATION is None else np.minimum(clean, SATURATION)


def mean_psnr_db(relit: NDArray, reference: NDArray, noise: float | NDArray) -> float:
    """Mean over held-out lights (rows) of the PSNR (dB, data range 1) of ``relit`` against a
    photograph of ``reference``: the squared error plus the photograph's noise ``noise²``
    (``noise``: a float, or each observation's deviation, as ``reference``)."""
    mse = ((np.asarray(relit, np.float64) - reference) ** 2).mean(axis=1)
    if np.ndim(noise) == 0:
        mse = mse + noise**2
    else:
        mse = mse + (np.asarray(noise, np.float64) ** 2).mean(axis=1)
    with np.errstate(divide="ignore"):
        db = np.where(mse > 0, -10.0 * np.log10(np.maximum(mse, 1e-300)), PSNR_CAP_DB)
    return float(np.minimum(db, PSNR_CAP_DB).mean())


def simulate_relight_designs(
    model: ObjectModel,
    designs: list[NDArray[np.float64]],
    held: list[NDArray[np.float64]],
    relight: RelightFn,
    basis: str,
    pixels: int = SIM_PIXELS,
    draws: int = SIM_DRAWS,
    seed: int = SIM_SEED,
) -> list[float]:
    """Per design (its full light set (L, 3), and its held-out lights (T, 3)): the simulated
    mean relighting PSNR (dB) of ``basis`` fitted on the design's modelled observations (see
    the module notes). A refused fit scores 0 dB."""
    p = len(model.normals)
    pix = np.arange(0, p, max(1, p // pixels))[:pixels]
    allx = np.concatenate([*designs, *[h for h in held if len(h)]])
    union, inverse = np.unique(np.round(allx, 9), axis=0, return_inverse=True)
    inverse = inverse.reshape(-1)
    clean = saturated(render(model, union, pix))  # (U, P'): every light once, for all designs
    sd = model.noise_sd(clean)  # each observation's noise (a float: the constant)
    noise = light_noise(union, draws, len(pix), sd, seed)  # (draws, U, P')
    n_design = sum(len(d) for d in designs)
    d_cols, h_cols = inverse[:n_design], inverse[n_design:]
    out = []
    at = hat = 0
    for lights, ho in zip(designs, held, strict=True):
        cols = d_cols[at : at + len(lights)]
        at += len(lights)
        hcols = h_cols[hat : hat + len(ho)]
        hat += len(ho)
        if len(ho) == 0:  # nothing held out: every light of the rig is in the design
            out.append(PSNR_CAP_DB)
            continue
        scores = []
        for d in range(draws):
            noisy = np.clip(clean[cols] + noise[d][cols], 0.0, SATURATION).astype(np.float32)
            relit = relight(noisy, lights, ho, basis)
            if relit is None:
                scores.append(0.0)
                continue
            ref_sd = sd if np.ndim(sd) == 0 else sd[hcols]
            scores.append(mean_psnr_db(relit, clean[hcols], ref_sd))
        out.append(float(np.mean(scores)))
    return out


def held_out(
    candidates: NDArray[np.float64], available: NDArray[np.bool_], design: NDArray[np.intp]
) -> NDArray[np.float64]:
    """The candidate directions a design leaves out (still available — not captured — and not
    in the design): what its relighting is judged on where the designs compared leave no light
    out in common (:func:`shared_held_out`)."""
    mask = np.asarray(available, dtype=bool).copy()
    mask[np.asarray(design, dtype=np.intp)] = False
    return candidates[mask]


def shared_held_out(
    candidates: NDArray[np.float64],
    available: NDArray[np.bool_],
    designs: list[NDArray[np.intp]],
) -> tuple[list[NDArray[np.float64]], bool]:
    """Per design, the lights its relighting is judged on, and whether they are shared: the
    candidates still available that *none* of the designs takes, the same for every design (as
    the benchmarks compare layouts since 2026-11-24), so that a design is not ranked higher for
    taking the one light the model renders worst. Where the designs together take every
    available light (or with :data:`SHARED_HELD_OUT` off), each design's own held-out lights
    (:func:`held_out`)."""
    mask = np.asarray(available, dtype=bool).copy()
    for d in designs:
        mask[np.asarray(d, dtype=np.intp)] = False
    if not SHARED_HELD_OUT or not mask.any():
        return [held_out(candidates, available, d) for d in designs], False
    return [candidates[mask]] * len(designs), True


def pick_floor(
    psnr_db: dict[float, float], keep_floor: float, margin_db: float | None = None
) -> float:
    """The floor whose design has the highest simulated PSNR, unless ``keep_floor``'s is within
    ``margin_db`` (default :data:`RELIGHT_MARGIN_DB`) of it (then that one: a session leaves its
    design only for clear evidence). Ties go to the floor nearest ``keep_floor``."""
    margin_db = RELIGHT_MARGIN_DB if margin_db is None else margin_db
    best = min(psnr_db, key=lambda f: (-psnr_db[f], abs(f - keep_floor)))
    if keep_floor in psnr_db and psnr_db[keep_floor] >= psnr_db[best] - margin_db:
        return keep_floor
    return best
