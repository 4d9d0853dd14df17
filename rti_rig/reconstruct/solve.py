"""One pseudo-inverse per light set: the guarded least-squares solve shared by every model.

For a linear model the design matrix ``A`` (N lights × p coefficients) is the same for every
pixel, so the fit of all pixels is ``C = W @ I`` with ``W`` a (p × N) solve matrix computed once.
This module computes ``W`` with the guards:

* **too few lights** (N < p): refused, always — the model is undetermined.
* **ill-conditioned** light set: the condition number is measured on the design matrix with
  unit-norm columns (so it measures collinearity of the basis functions over these lights, not
  their units). Above :data:`COND_LIMIT` the solve is either refused (``"refuse"``) or
  regularised (``"regularise"``) by ridge (Tikhonov) with ``lambda = (s_max / COND_LIMIT)^2``
  on the normalised design, which caps the noise gain of the worst-determined combination at
  about ``COND_LIMIT / (2 s_max)``; the :class:`FitReport` says which happened.

Why 100: well-spread light sets (a Fibonacci hemisphere above 10° elevation) give normalised
condition numbers of 1.2 (Lambert) to 13 (HSH3) even when N equals p, and at most 5 from
N = 2p on; random minimal sets have medians 4 (Lambert) to 150 (HSH3). A single ring at one
elevation is exactly singular for PTM and HSH (``l_u^2 + l_v^2`` is constant), and coplanar lights
for Lambert. Above 100 one combination of coefficients is determined a hundred times worse than
the best, and it shows as a blown-up relighting between the lights (see algorithms notes §4.5).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import NDArray

from rti_rig.reconstruct.errors import ReconstructionError

#: Normalised condition number above which a light set is "ill-conditioned" for a model.
COND_LIMIT = 100.0

IllConditioned = Literal["refuse", "regularise"]


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

    @property
    def action(self) -> str:
        """``"least squares"`` or ``"ridge-regularised"``, for reports."""
        return "ridge-regularised" if self.regularised else "least squares"

    def describe(self) -> str:
        """One line for logs and reports."""
        text = (
            f"{self.model}: {self.n_coefficients} coefficients from {self.n_lights} lights, "
            f"condition number {self.condition_number:.3g} (limit {self.cond_limit:g}), "
            f"{self.action}"
        )
        if self.regularised:
            text += f" with lambda {self.ridge_lambda:.3g} on unit-norm columns"
        return text


def solve_matrix(
    design: NDArray[np.float64],
    model: str,
    ill_conditioned: IllConditioned = "regularise",
    cond_limit: float = COND_LIMIT,
    normalise_columns: bool = True,
) -> tuple[NDArray[np.float64], FitReport]:
    """Solve matrix ``W`` (p × N) with ``coefficients = W @ observations``, and its report.

    ``normalise_columns=False`` measures the condition of the design as given; photometric
    stereo uses it because its three columns share one unit (a ring of lights near the zenith
    determines ``n_x, n_y`` badly, which normalising the columns would hide).
    """
    n, p = design.shape
    if n < p:
        raise ReconstructionError(
            f"{model} needs at least {p} lights for its {p} coefficients, got {n}; "
            "acquire more lights or choose a lower-order model"
        )
    if ill_conditioned not in ("refuse", "regularise"):
        raise ValueError(f"ill_conditioned must be 'refuse' or 'regularise', got {ill_conditioned}")
    norms = np.linalg.norm(design, axis=0)
    norms = np.where((norms < 1e-12) | (not normalise_columns), 1.0, norms)
    scaled = design / norms
    u, s, vt = np.linalg.svd(scaled, full_matrices=False)
    cond = float(s[0] / s[-1]) if s[0] > 0 and s[-1] > s[0] * 1e-15 else float("inf")
    regularised = cond > cond_limit
    lam = 0.0
    if regularised:
        if ill_conditioned == "refuse":
            raise ReconstructionError(
                f"light set is ill-conditioned for {model}: condition number {cond:.3g} exceeds "
                f"{cond_limit:g} (lights nearly coplanar for Lambert, or on a single ring for "
                "PTM/HSH); add lights at other elevations, or pass ill_conditioned='regularise'"
            )
        lam = float((s[0] / cond_limit) ** 2)
        filt = s / (s * s + lam)
    else:
        filt = 1.0 / s
    w = (vt.T * filt) @ u.T / norms[:, None]
    report = FitReport(model, n, p, cond, cond_limit, regularised, lam)
    return w, report
