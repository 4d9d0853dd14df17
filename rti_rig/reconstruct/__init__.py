"""Reconstruction: photometric stereo, PTM, HSH, model choice — streamed in row tiles.

Images are linear float arrays (N, H, W) or (N, H, W, C), or sequences of such images (e.g.
uint16 frame pixels, see :func:`stack_from_frames`); lights are unit directions (N, 3) in the
frame of docs/conventions.md. See docs/reconstruction.md.
"""

from rti_rig.core.rti_bases import N_COEFFICIENTS, design_matrix, hsh_basis, ptm_basis
from rti_rig.reconstruct.errors import ReconstructionError
from rti_rig.reconstruct.hsh import HSHModel, fit_hsh
from rti_rig.reconstruct.light_gains import LightGains, apply_light_gains, estimate_light_gains
from rti_rig.reconstruct.linear_model import LambertModel, RelightModel, fit_lambert
from rti_rig.reconstruct.model_select import CandidateEvidence, ModelChoice, select_model
from rti_rig.reconstruct.photometric_stereo import PSResult, fit_photometric_stereo
from rti_rig.reconstruct.ptm import PTMModel, fit_ptm
from rti_rig.reconstruct.registry import MODEL_NAMES, RELIGHT_MODELS, fit_model
from rti_rig.reconstruct.solve import COND_LIMIT, FitReport
from rti_rig.reconstruct.stack import ImageStack, stack_from_frames, validate_lights

__all__ = [
    "COND_LIMIT",
    "MODEL_NAMES",
    "N_COEFFICIENTS",
    "RELIGHT_MODELS",
    "CandidateEvidence",
    "FitReport",
    "HSHModel",
    "ImageStack",
    "LambertModel",
    "LightGains",
    "ModelChoice",
    "PSResult",
    "PTMModel",
    "ReconstructionError",
    "RelightModel",
    "apply_light_gains",
    "design_matrix",
    "estimate_light_gains",
    "fit_hsh",
    "fit_lambert",
    "fit_model",
    "fit_photometric_stereo",
    "fit_ptm",
    "hsh_basis",
    "ptm_basis",
    "select_model",
    "stack_from_frames",
    "validate_lights",
]
