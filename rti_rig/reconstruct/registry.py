"""Fit any model by name: the single entry point a benchmark or CLI loops over.

Names: ``lambert`` (3), ``hsh1`` (4), ``ptm`` (6), ``hsh2`` (9), ``hsh3`` (16) — linear relighting
bases — and ``ps`` / ``ps-robust``, Lambertian photometric stereo (least squares / robust).
"""

from __future__ import annotations

from typing import Any

from numpy.typing import ArrayLike

from rti_rig.reconstruct.hsh import fit_hsh
from rti_rig.reconstruct.linear_model import RelightModel, fit_lambert
from rti_rig.reconstruct.photometric_stereo import fit_photometric_stereo
from rti_rig.reconstruct.ptm import fit_ptm

#: Linear relighting models in increasing coefficient count: the order "lowest order first".
RELIGHT_MODELS = ("lambert", "hsh1", "ptm", "hsh2", "hsh3")
#: Every name :func:`fit_model` accepts.
MODEL_NAMES = (*RELIGHT_MODELS, "ps", "ps-robust")


def fit_model(name: str, images: Any, lights: ArrayLike, **kwargs: Any) -> RelightModel:
    """Fit the model ``name`` (see :data:`MODEL_NAMES`); ``kwargs`` go to its fit function."""
    if name == "lambert":
        return fit_lambert(images, lights, **kwargs)
    if name == "ptm":
        return fit_ptm(images, lights, **kwargs)
    if name in ("hsh1", "hsh2", "hsh3"):
        return fit_hsh(images, lights, int(name[-1]), **kwargs)
    if name == "ps":
        return fit_photometric_stereo(images, lights, robust=False, **kwargs)
    if name == "ps-robust":
        return fit_photometric_stereo(images, lights, robust=True, **kwargs)
    raise ValueError(f"unknown model '{name}'; known: {', '.join(MODEL_NAMES)}")
