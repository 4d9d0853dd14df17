"""The error reconstruction raises on purpose, and the warnings it gives when it fits anyway.

A reconstruction refuses rather than returns numbers that look right and are not: too few
lights for a model, a light set that cannot determine the model (coplanar lights for
photometric stereo, a single ring for PTM), images and lights that disagree. The message says
which model, which light or image, and what to do.

When a fit goes ahead on a light set it cannot trust (regularised, or with a large relighting
noise gain somewhere on the hemisphere) it says so with a :class:`FitTrustWarning` subclass
(Python ``warnings``, so a caller can turn it into an error with a filter) and records the same
text in the fit's report: finite numbers are not evidence of a good fit.
"""

from __future__ import annotations

from rti_rig.core.errors import RtiRigError


class ReconstructionError(RtiRigError):
    """A model cannot be fitted honestly from these images and lights."""


class FitTrustWarning(UserWarning):
    """A fit was made, but some of its numbers should not be trusted (see the message)."""


class IllConditionedFitWarning(FitTrustWarning):
    """The light set determines some combination of the model badly over the hemisphere:
    relighting away from the lights amplifies noise by the reported gain."""


class RegularisedFitWarning(IllConditionedFitWarning):
    """The fit was ridge-regularised: its coefficients are biased towards zero, and relighting
    away from the lights is not a least-squares answer."""
