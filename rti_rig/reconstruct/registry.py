"""Fit any model by name: the registry a benchmark, the CLI and model choice loop over.

A model is one module with a fit function ``fit(images, lights, **kwargs) -> RelightModel`` and
one :func:`register` line below. Names: ``lambert`` (3), ``hsh1`` (4), ``ptm`` (6), ``hsh2`` (9),
``hsh3`` (16) — linear relighting bases, candidates of model choice — and ``ps`` / ``ps-robust``
(alias ``robust-ps``), Lambertian photometric stereo (least squares / robust).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from functools import partial
from typing import Any

from numpy.typing import ArrayLike

from rti_rig.core.fit_minimums import N_COEFFICIENTS, NORMAL_MIN_LIGHTS
from rti_rig.reconstruct.hsh import fit_hsh
from rti_rig.reconstruct.linear_model import RelightModel, fit_lambert
from rti_rig.reconstruct.photometric_stereo import fit_photometric_stereo
from rti_rig.reconstruct.ptm import fit_ptm


@dataclass(frozen=True)
class ModelSpec:
    """One registered model: its fit function and what it gives."""

    name: str
    n_coefficients: int
    fit: Callable[..., RelightModel]
    #: a linear relighting basis (a candidate of model choice, exportable coefficients)
    relighting: bool
    #: what its normals mean, for reports
    normals: str
    aliases: tuple[str, ...] = ()


_REGISTRY: dict[str, ModelSpec] = {}


def register(spec: ModelSpec) -> ModelSpec:
    """Add a model (and its aliases) to the registry; a name may be registered once."""
    for key in (spec.name, *spec.aliases):
        if key in _REGISTRY:
            raise ValueError(f"model name '{key}' is already registered")
        _REGISTRY[key] = spec
    return spec


def model_spec(name: str) -> ModelSpec:
    """The registered model ``name`` (or alias); ValueError naming the known ones."""
    try:
        return _REGISTRY[name]
    except KeyError:
        named = [
            n + (f" (or {', '.join(_REGISTRY[n].aliases)})" if _REGISTRY[n].aliases else "")
            for n in MODEL_NAMES
        ]
        raise ValueError(f"unknown model '{name}'; known: {', '.join(named)}") from None


# the counts are the core's (N_COEFFICIENTS, NORMAL_MIN_LIGHTS), never restated here
_N = N_COEFFICIENTS
register(
    ModelSpec("lambert", _N["lambert"], fit_lambert, True, "albedo × normal, no shadow handling")
)
register(ModelSpec("hsh1", _N["hsh1"], partial(fit_hsh, order=1), True, "none"))
register(ModelSpec("ptm", _N["ptm"], fit_ptm, True, "Lambertian reading of the PTM"))
register(ModelSpec("hsh2", _N["hsh2"], partial(fit_hsh, order=2), True, "none"))
register(ModelSpec("hsh3", _N["hsh3"], partial(fit_hsh, order=3), True, "none"))
register(
    ModelSpec(
        "ps",
        NORMAL_MIN_LIGHTS,
        partial(fit_photometric_stereo, robust=False),
        False,
        "least-squares PS",
    )
)
register(
    ModelSpec(
        "ps-robust",
        NORMAL_MIN_LIGHTS,
        partial(fit_photometric_stereo, robust=True),
        False,
        "robust PS (shadows, highlights, saturation dropped)",
        aliases=("robust-ps",),
    )
)

#: Linear relighting models in increasing coefficient count: the order "lowest order first".
RELIGHT_MODELS = tuple(
    sorted(
        (s.name for s in {id(s): s for s in _REGISTRY.values()}.values() if s.relighting),
        key=lambda n: _REGISTRY[n].n_coefficients,
    )
)
#: Every canonical name :func:`fit_model` accepts (aliases too, see :func:`model_spec`).
MODEL_NAMES = tuple(dict.fromkeys(s.name for s in _REGISTRY.values()))


def fit_model(name: str, images: Any, lights: ArrayLike, **kwargs: Any) -> RelightModel:
    """Fit the model ``name`` (see :data:`MODEL_NAMES`); ``kwargs`` go to its fit function."""
    return model_spec(name).fit(images, lights, **kwargs)
