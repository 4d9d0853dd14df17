""" "Model only what the scene requires": the lowest-order model that predicts unseen lights.

Each candidate linear model is fitted on some lights and asked to predict the images of the
others (k-fold over lights, or one explicit held-out set). The error is the RMS difference
over held-out observations on a regular pixel sample (:meth:`ImageStack.pixel_sample`), also
given as PSNR against the stack's reference level (99th percentile of the sample). The choice
is the candidate with the fewest coefficients whose RMS error is within ``tolerance``
(relative) of the best candidate's: a higher order must *earn* its coefficients on lights it
has not seen, otherwise it is fitting noise (the HSH3-at-16-lights collapse of the notes §4.5).

Candidates that a fold cannot fit (fewer training lights than coefficients) are listed with
the reason and never chosen; folds whose light set was ill-conditioned are regularised (or the
candidate refused, with ``ill_conditioned="refuse"``) and counted in the evidence.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from rti_rig.core.fit_minimums import fewest_held_out
from rti_rig.core.rti_bases import N_COEFFICIENTS, design_matrix
from rti_rig.reconstruct.errors import ReconstructionError
from rti_rig.reconstruct.linear_model import RelightModel
from rti_rig.reconstruct.registry import RELIGHT_MODELS, fit_model
from rti_rig.reconstruct.solve import COND_LIMIT, IllConditioned, solve_matrix
from rti_rig.reconstruct.stack import ImageStack, validate_lights

#: Default relative tolerance on held-out RMS error (5 % ≈ 0.4 dB of PSNR).
DEFAULT_TOLERANCE = 0.05


@dataclass(frozen=True)
class CandidateEvidence:
    """How one candidate did on held-out lights; ``rmse`` is None when it could not be fitted."""

    model: str
    n_coefficients: int
    rmse: float | None
    psnr_db: float | None
    within_tolerance: bool
    regularised_folds: int
    folds: int
    note: str


@dataclass(frozen=True)
class ModelChoice:
    """The chosen model and the table that justifies it."""

    model: str
    n_coefficients: int
    best_model: str
    tolerance: float
    holdout: str
    n_pixels: int
    evidence: tuple[CandidateEvidence, ...]

    def to_markdown(self) -> str:
        """Evidence table for a report."""
        lines = [
            f"Chosen model: **{self.model}** ({self.n_coefficients} coefficients); best held-out "
            f"error: {self.best_model}; tolerance {self.tolerance:.1%} of the best RMS; "
            f"{self.holdout}; {self.n_pixels} sampled pixels.",
            "",
            "| model | coefficients | held-out RMS | PSNR (dB) | within tolerance | "
            "regularised folds | note |",
            "|---|---|---|---|---|---|---|",
        ]
        for e in self.evidence:
            rmse = f"{e.rmse:.4g}" if e.rmse is not None else "—"
            psnr = f"{e.psnr_db:.2f}" if e.psnr_db is not None else "—"
            lines.append(
                f"| {e.model} | {e.n_coefficients} | {rmse} | {psnr} | "
                f"{'yes' if e.within_tolerance else 'no'} | {e.regularised_folds}/{e.folds} | "
                f"{e.note} |"
            )
        return "\n".join(lines)

    def fit(self, images: Any, lights: ArrayLike, **kwargs: Any) -> RelightModel:
        """Fit the chosen model on all lights."""
        return fit_model(self.model, images, lights, **kwargs)


def fewest_images(candidates: Sequence[str] = RELIGHT_MODELS) -> int:
    """The fewest images :func:`select_model` can fit and check one of ``candidates`` from:
    the simplest one's coefficients, fitted, plus one light held out (every fold holds out at
    least one). What a session must shoot for `rti-rig fit`'s default ``--model auto``; run and
    plan read it (``core.fit_minimums.FIT_MINIMUMS``) so that their advice cannot drift from
    the choice itself."""
    return fewest_held_out(candidates)


def _folds(n: int, holdout: int | Sequence[int], seed: int) -> tuple[list[np.ndarray], str]:
    if isinstance(holdout, int | np.integer):
        k = int(holdout)
        if k < 2:
            raise ReconstructionError(f"holdout must be at least 2 folds, got {k}")
        k = min(k, n)
        perm = np.random.default_rng(seed).permutation(n)
        return [np.sort(perm[i::k]) for i in range(k)], f"{k}-fold cross-validation over lights"
    test = np.unique(np.asarray(holdout, dtype=int))
    if test.size == 0 or test.min() < 0 or test.max() >= n:
        raise ReconstructionError(f"held-out light indices must lie in 0..{n - 1}, got {holdout}")
    if test.size == n:
        raise ReconstructionError("cannot hold out every light: nothing left to fit")
    return [test], f"lights {test.tolist()} held out"


def select_model(
    images: Any,
    lights: ArrayLike,
    tolerance: float = DEFAULT_TOLERANCE,
    holdout: int | Sequence[int] = 5,
    *,
    candidates: Sequence[str] = RELIGHT_MODELS,
    max_pixels: int = 100_000,
    ill_conditioned: IllConditioned = "regularise",
    cond_limit: float = COND_LIMIT,
    seed: int = 0,
) -> ModelChoice:
    """Choose the lowest-order candidate within ``tolerance`` of the best held-out error.

    ``holdout`` is a number of folds (k-fold over lights, deterministic with ``seed``) or the
    indices of the lights to hold out. Raises when no candidate can be fitted.
    """
    if tolerance < 0:
        raise ReconstructionError(f"tolerance must be >= 0, got {tolerance}")
    stack = ImageStack(images)
    lt = validate_lights(lights, stack.n)
    unknown = [c for c in candidates if c not in N_COEFFICIENTS]
    if unknown:
        raise ReconstructionError(f"unknown candidate models {unknown}; known: {RELIGHT_MODELS}")
    ordered = sorted(candidates, key=lambda c: N_COEFFICIENTS[c])
    values, _ = stack.pixel_sample(max_pixels)  # (N, P, C)
    obs = values.reshape(stack.n, -1).astype(np.float64)
    # sampled pixel values with a saturated or NaN observation cannot be held out honestly
    keep = np.all(np.isfinite(obs), axis=0)
    if stack.saturation_level is not None:
        keep &= np.all(obs < stack.saturation_level, axis=0)
    if keep.any():
        obs = obs[:, keep]
    values = obs
    ref = float(np.percentile(values, 99.0)) or 1.0
    folds, how = _folds(stack.n, holdout, seed)

    results: dict[str, tuple[float | None, int, str]] = {}
    for name in ordered:
        p = N_COEFFICIENTS[name]
        design = design_matrix(name, lt)
        sse, count, regularised, note = 0.0, 0, 0, ""
        for test in folds:
            train = np.setdiff1d(np.arange(stack.n), test)
            if train.size < p:
                note = f"needs {p} fitting lights, a fold leaves {train.size}"
                break
            try:
                w, report = solve_matrix(
                    design[train], name, ill_conditioned, cond_limit, warn=False
                )
            except ReconstructionError as exc:
                note = f"refused: {exc}"
                break
            regularised += int(report.regularised)
            pred = np.maximum(design[test] @ (w @ obs[train]), 0.0)
            sse += float(np.sum((pred - obs[test]) ** 2))
            count += pred.size
        if note:
            results[name] = (None, regularised, note)
        else:
            results[name] = (float(np.sqrt(sse / max(count, 1))), regularised, "")
    fitted = {k: v[0] for k, v in results.items() if v[0] is not None}
    if not fitted:
        simplest = min(results, key=lambda k: N_COEFFICIENTS[k])
        fewest = fewest_images(list(results))
        plain = f"no candidate model can be fitted from {stack.n} image(s)"
        if stack.n < fewest:
            plain += (
                f": the simplest candidate ({simplest}) needs at least {fewest} lit images to "
                "be fitted and checked on one left out; shoot more lights"
            )
        raise ReconstructionError(
            f"{plain} (with {how}: " + "; ".join(f"{k}: {v[2]}" for k, v in results.items()) + ")"
        )
    best = min(fitted, key=lambda k: (fitted[k], N_COEFFICIENTS[k]))
    limit = fitted[best] * (1.0 + tolerance)
    chosen = next(k for k in ordered if k in fitted and fitted[k] <= limit)
    evidence = []
    for name in ordered:
        rmse, reg, note = results[name]
        psnr = None if rmse is None else float(20 * np.log10(ref / max(rmse, 1e-12)))
        within = rmse is not None and rmse <= limit
        if name == chosen:
            note = note or "chosen: simplest model within tolerance"
        elif name == best:
            note = note or "best held-out error"
        evidence.append(
            CandidateEvidence(name, N_COEFFICIENTS[name], rmse, psnr, within, reg, len(folds), note)
        )
    return ModelChoice(
        model=chosen,
        n_coefficients=N_COEFFICIENTS[chosen],
        best_model=best,
        tolerance=tolerance,
        holdout=how,
        n_pixels=obs.shape[1] // stack.channels,
        evidence=tuple(evidence),
    )
