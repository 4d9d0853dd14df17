"""One pseudo-inverse per light set: the guarded least-squares solve shared by every model.

For a linear model the design matrix ``A`` (N lights × p coefficients) is the same for every
pixel, so the fit of all pixels is ``C = W @ I`` with ``W`` a (p × N) solve matrix computed once.
This module computes ``W`` with the guards:

* **too few lights** (N < p): refused, always — the model is undetermined.
* **conditioning judged over the hemisphere**, not over the lights given. Two measures:

  - the *condition number* of the design with each column divided by that basis function's
    RMS over the whole upper hemisphere (uniform in solid angle). Scaling by the RMS over the
    given lights (the earlier rule) hides a bunched light set: lights at 80–88° elevation make
    every PTM column nearly constant *over those lights*, and normalising them there reports a
    harmless 9.4 where the hemisphere-scaled figure is in the hundreds;
  - the *relighting noise gain*: the largest, over a dense set of hemisphere directions ``d``,
    of ``|a(d)^T W|``, the standard deviation of a relit value per unit of image noise. A
    well-spread set gives about ``sqrt(p / N)`` (below 1); a cap of lights near the zenith
    relit at 35° gives tens.

  Above :data:`COND_LIMIT` the solve is refused (``"refuse"``) or ridge-regularised
  (``"regularise"``, with ``lambda = (s_max / COND_LIMIT)^2`` on the hemisphere-scaled design).
  A regularised fit, or a noise gain above :data:`NOISE_GAIN_LIMIT`, issues a named warning
  (:class:`RegularisedFitWarning` / :class:`IllConditionedFitWarning`) and records it in the
  :class:`FitReport`.

Why 100: well-spread light sets (a Fibonacci hemisphere above 10° elevation) give
hemisphere-scaled condition numbers of order 1–20 even when N equals p; a single ring at one
elevation is exactly singular for PTM and HSH (``l_u^2 + l_v^2`` is constant), coplanar lights
for Lambert.
"""

from __future__ import annotations

import threading
import warnings
from dataclasses import dataclass, field
from functools import lru_cache
from typing import Literal

import numpy as np
from numpy.typing import NDArray

from rti_rig.core.rti_bases import N_COEFFICIENTS, design_matrix
from rti_rig.reconstruct.errors import (
    IllConditionedFitWarning,
    ReconstructionError,
    RegularisedFitWarning,
)

#: Hemisphere-scaled condition number above which a light set is ill-conditioned for a model.
COND_LIMIT = 100.0
#: Largest relighting noise gain over the hemisphere above which a fit is flagged (warned).
NOISE_GAIN_LIMIT = 10.0
#: Directions used to judge a light set over the hemisphere (uniform in solid angle).
HEMISPHERE_SAMPLES = 2000

IllConditioned = Literal["refuse", "regularise"]


@lru_cache(maxsize=1)
def hemisphere_directions(n: int = HEMISPHERE_SAMPLES) -> NDArray[np.float64]:
    """``n`` unit directions spread uniformly (in solid angle) over the whole upper hemisphere,
    horizon included: the directions a user may relight from."""
    i = np.arange(n) + 0.5
    z = 1.0 - i / n
    r = np.sqrt(1.0 - z * z)
    phi = i * np.pi * (3.0 - np.sqrt(5.0))
    out = np.stack([r * np.cos(phi), r * np.sin(phi), z], axis=1)
    out.setflags(write=False)
    return out


@lru_cache(maxsize=16)
def hemisphere_design(basis: str) -> NDArray[np.float64]:
    """Design matrix of ``basis`` over :func:`hemisphere_directions` (cached, read-only)."""
    out = design_matrix(basis, hemisphere_directions())
    out.setflags(write=False)
    return out


@dataclass(frozen=True)
class FitReport:
    """How a model was fitted: the evidence that its coefficients mean something."""

    model: str
    n_lights: int
    n_coefficients: int
    condition_number: float
    cond_limit: float
    regularised: bool
    ridge_lambda: float
    #: largest relighting noise gain over the hemisphere (std of a relit value per unit noise)
    noise_gain: float = float("nan")
    #: the texts of the warnings this fit issued (empty when it can be trusted)
    warnings: tuple[str, ...] = field(default=())
    #: pixels (× channels) with at least one observation excluded (saturated, NaN, masked)
    pixels_with_missing: int = 0
    #: pixels (× channels) that could not be fitted at all (too few usable observations)
    pixels_unfitted: int = 0

    @property
    def action(self) -> str:
        """``"least squares"`` or ``"ridge-regularised"``, for reports."""
        return "ridge-regularised" if self.regularised else "least squares"

    @property
    def trusted(self) -> bool:
        """True when the fit issued no warning."""
        return not self.warnings

    def describe(self) -> str:
        """One line for logs and reports."""
        text = (
            f"{self.model}: {self.n_coefficients} coefficients from {self.n_lights} lights, "
            f"{condition_words(self.condition_number, self.cond_limit)}, "
            f"noise gain {self.noise_gain:.3g}, {self.action}"
        )
        if self.regularised:
            text += f" with lambda {self.ridge_lambda:.3g} on hemisphere-scaled columns"
        if self.pixels_with_missing:
            text += (
                f"; {self.pixels_with_missing} pixel values fitted without excluded "
                f"observations, {self.pixels_unfitted} unfitted"
            )
        return text


def _basis_for(model: str) -> str | None:
    if model in N_COEFFICIENTS:
        return model
    if model in ("photometric stereo", "ps", "ps-robust"):
        return "lambert"
    return None


def solve_matrix(
    design: NDArray[np.float64],
    model: str,
    ill_conditioned: IllConditioned = "regularise",
    cond_limit: float = COND_LIMIT,
    normalise_columns: bool = True,
    *,
    basis: str | None = None,
    warn: bool = True,
    noise_gain_limit: float = NOISE_GAIN_LIMIT,
) -> tuple[NDArray[np.float64], FitReport]:
    """Solve matrix ``W`` (p × N) with ``coefficients = W @ observations``, and its report.

    ``basis`` names the design's basis (default: ``model`` when it is one of
    :data:`N_COEFFICIENTS`, Lambert for photometric stereo); its columns are scaled by their
    RMS over the hemisphere and the noise gain is measured over the hemisphere. Without a known
    basis the columns are scaled by their RMS over the given lights and the gain is not known.
    ``normalise_columns=False`` measures the design as given. ``warn=False`` records the
    warnings in the report without issuing them (model selection's folds).
    """
    key = (
        design.shape,
        np.ascontiguousarray(design, dtype=np.float64).tobytes(),
        model,
        ill_conditioned,
        float(cond_limit),
        bool(normalise_columns),
        basis,
        float(noise_gain_limit),
    )
    with _SOLVED_LOCK:
        cached = _SOLVED.get(key)
    if cached is None:
        cached = _solve(
            design, model, ill_conditioned, cond_limit, normalise_columns, basis, noise_gain_limit
        )
        with _SOLVED_LOCK:
            if len(_SOLVED) >= _SOLVED_MAX:
                _SOLVED.pop(next(iter(_SOLVED)))
            _SOLVED[key] = cached
    w, report, categories = cached
    if warn:
        for category, text in zip(categories, report.warnings, strict=True):
            warnings.warn(text, category, stacklevel=3)
    return w.copy(), report


#: Solve matrices of the light sets seen lately: a streamed fit asks for the same one per band,
#: and judging it over the hemisphere (an SVD and 2000 relighting gains) costs more than
#: fitting a small band.
_SOLVED: dict[tuple, tuple[NDArray[np.float64], FitReport, tuple[type[Warning], ...]]] = {}
_SOLVED_MAX = 32
_SOLVED_LOCK = threading.Lock()


def condition_words(cond: float, limit: float, what: str = "its terms") -> str:
    """A condition number as a user reads it: the figure and its limit, or, where it is
    infinite, what that means for the lights. Why: "condition number inf" reached users, who
    were left to guess that no fit can tell ``what`` apart from these lights at all."""
    if np.isfinite(cond):
        return f"condition number {cond:.3g} over the hemisphere, limit {limit:g}"
    return f"these lights cannot separate {what} (the fit's system is singular)"


def _solve(
    design: NDArray[np.float64],
    model: str,
    ill_conditioned: IllConditioned,
    cond_limit: float,
    normalise_columns: bool,
    basis: str | None,
    noise_gain_limit: float,
) -> tuple[NDArray[np.float64], FitReport, tuple[type[Warning], ...]]:
    """:func:`solve_matrix` without the cache and without issuing warnings."""
    n, p = design.shape
    if n < p:
        raise ReconstructionError(
            f"{model} needs at least {p} lights for its {p} coefficients, got {n}; "
            "acquire more lights or choose a lower-order model"
        )
    if ill_conditioned not in ("refuse", "regularise"):
        raise ValueError(f"ill_conditioned must be 'refuse' or 'regularise', got {ill_conditioned}")
    basis = basis if basis is not None else _basis_for(model)
    hemi = hemisphere_design(basis) if basis is not None else None
    if hemi is not None and hemi.shape[1] != p:
        raise ValueError(f"basis {basis} has {hemi.shape[1]} columns, the design {p}")
    if not normalise_columns:
        norms = np.ones(p)
    elif hemi is not None:
        norms = np.sqrt(np.mean(hemi * hemi, axis=0))
    else:
        norms = np.linalg.norm(design, axis=0) / np.sqrt(n)
    norms = np.where(norms < 1e-12, 1.0, norms)
    scaled = design / norms
    u, s, vt = np.linalg.svd(scaled, full_matrices=False)
    cond = float(s[0] / s[-1]) if s[0] > 0 and s[-1] > s[0] * 1e-15 else float("inf")
    regularised = cond > cond_limit
    lam = 0.0
    if regularised:
        if ill_conditioned == "refuse":
            raise ReconstructionError(
                f"light set is ill-conditioned for {model}: "
                f"{condition_words(cond, cond_limit, f'its {p} terms')} (lights nearly "
                "coplanar or bunched near the "
                "zenith for Lambert, on a single ring or a small cap for PTM/HSH); add lights "
                "at other elevations (from Python, ill_conditioned='regularise' fits it "
                "regularised)"
            )
        lam = float((s[0] / cond_limit) ** 2)
        filt = s / (s * s + lam)
    else:
        filt = 1.0 / s
    w = (vt.T * filt) @ u.T / norms[:, None]
    gain = float(np.max(np.linalg.norm(hemi @ w, axis=1))) if hemi is not None else float("nan")
    texts: list[tuple[type[Warning], str]] = []
    if regularised:
        texts.append(
            (
                RegularisedFitWarning,
                f"{model} fit ridge-regularised: "
                f"{condition_words(cond, cond_limit, f'its {p} terms')}, for these {n} lights; "
                "its coefficients are biased and "
                f"relighting away from the lights is not trustworthy (noise gain {gain:.3g})",
            )
        )
    elif np.isfinite(gain) and gain > noise_gain_limit:
        texts.append(
            (
                IllConditionedFitWarning,
                f"{model} fit ill-conditioned over the hemisphere: relighting amplifies image "
                f"noise up to {gain:.3g}× (limit {noise_gain_limit:g}) for these {n} lights "
                f"(condition number {cond:.3g}); add lights where the set leaves gaps",
            )
        )
    report = FitReport(
        model, n, p, cond, cond_limit, regularised, lam, gain, tuple(t for _, t in texts)
    )
    w.setflags(write=False)
    return w, report, tuple(c for c, _ in texts)
