"""The one error reconstruction raises on purpose.

A reconstruction refuses rather than returns numbers that look right and are not: too few
lights for a model, a light set that cannot determine the model (coplanar lights for
photometric stereo, a single ring for PTM), images and lights that disagree. The message says
which model, which light or image, and what to do.
"""

from __future__ import annotations

from rti_rig.core.errors import RtiRigError


class ReconstructionError(RtiRigError):
    """A model cannot be fitted honestly from these images and lights."""
