"""The per-band work of `rti-rig fit`, shared by every way of running it.

A fit streams over bands of rows: each band of all images is fitted on its own (every model is
per pixel). :func:`fit_band` is that work — the exported linear models' coefficients and the
normal and albedo maps of one band — and the only place it is written down. The single-process
loop in :mod:`rti_rig.app.usecases.fit` and the Dask runner in
:mod:`rti_rig.app.usecases.fit_dask` both call it with the same :class:`BandPlan` on the same
float32 bands (same row boundaries), which is why their outputs are identical: nothing about a
pixel's result depends on where or in which thread its band was fitted.

Everything here is picklable (plain dataclasses of numpy arrays and module-level functions), so a
Dask distributed worker can run it.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field

import numpy as np

from rti_rig.reconstruct.errors import FitTrustWarning


@dataclass(frozen=True)
class BandPlan:
    """What every band of one fit needs, decided once from the whole acquisition.

    ``linear``: design matrices of the linear models fitted per band (the exported PTM/HSH and
    the Lambert fit when it gives the normals); ``normal_source``: ``"ps"``, ``"ps-robust"``,
    ``"lambert"``, ``"ptm"`` or ``""`` (no normal maps); thresholds in the stack's scaled units.
    """

    lights: np.ndarray
    linear: dict[str, np.ndarray]
    normal_source: str
    tile_rows: int
    saturation: float | None
    reference_level: float
    grey: bool
    export_encoding: str = "linear"


#: the linear models a fit writes to files (the others — Lambert — only give normals)
EXPORTED = ("ptm", "hsh1", "hsh2", "hsh3")


@dataclass
class BandFit:
    """Outputs of one band: coefficients per linear model as the files get them (``(p, r, W[,
    C])``; see ``BandPlan.export_encoding``), normals
    ``(r, W, 3)`` and albedo ``(r, W[, C])`` (None when no normal maps are fitted), and the
    texts of warnings the band's fit issued (re-issued by whoever collects the band)."""

    coefficients: dict[str, np.ndarray]
    normals: np.ndarray | None
    albedo: np.ndarray | None
    warnings: list[tuple[type[Warning], str]] = field(default_factory=list)


def fit_band(band: np.ndarray, plan: BandPlan) -> BandFit:
    """Fit one band ``(N, r, W, C)`` float32 (scaled, as :meth:`ImageStack.rows` gives it).

    Trust warnings (:class:`FitTrustWarning`) are issued once for the whole fit when the plan is
    made, never per band, so they are ignored here.
    """
    from rti_rig.reconstruct.linear_model import fit_coefficients
    from rti_rig.reconstruct.photometric_stereo import (
        DARK_FRACTION,
        HIGHLIGHT_FLOOR_FRACTION,
        fit_photometric_stereo,
    )

    if plan.grey:
        band = band[..., 0]
    rows, sat, ref = plan.tile_rows, plan.saturation, plan.reference_level
    source = plan.normal_source
    shown = shown_sat = None
    if plan.export_encoding == "srgb" and any(k in EXPORTED for k in plan.linear):
        from rti_rig.core.image_files import srgb_encode

        shown = srgb_encode(band)  # clipped at full scale: saturation stays at 1.0
        shown_sat = None if sat is None else float(srgb_encode(np.float32(min(sat, 1.0))))
    coefs: dict[str, np.ndarray] = {}  # fitted to the linear light: what normals are read from
    written: dict[str, np.ndarray] = {}  # what the files get
    for key, design in plan.linear.items():
        if shown is not None and key in EXPORTED:
            written[key] = fit_coefficients(
                shown, design, key, saturation=shown_sat, tile_rows=rows
            )[0]
            if key == source:  # `--model ptm`: its normals from the PTM of the linear light
                coefs[key] = fit_coefficients(band, design, key, saturation=sat, tile_rows=rows)[0]
        else:
            coefs[key] = fit_coefficients(band, design, key, saturation=sat, tile_rows=rows)[0]
            written[key] = coefs[key]
    del shown
    normals = albedo = None
    if not source:
        pass
    elif source.startswith("ps"):
        ps = fit_photometric_stereo(
            band,
            plan.lights,
            robust=source == "ps-robust",
            tile_rows=rows,
            saturation=sat,
            dark_threshold=DARK_FRACTION * ref,
            highlight_floor=HIGHLIGHT_FLOOR_FRACTION * ref,
            reference_level=ref,
        )
        normals, albedo = ps.normals, ps.albedo
    else:
        from rti_rig.reconstruct.linear_model import LambertModel
        from rti_rig.reconstruct.ptm import PTMModel
        from rti_rig.reconstruct.solve import FitReport

        report = FitReport(source, len(plan.lights), 0, 0.0, 0.0, False, 0.0)
        cls = PTMModel if source == "ptm" else LambertModel
        normals = cls(coefs[source], report).normals()
        if source == "lambert":
            albedo = np.linalg.norm(coefs["lambert"], axis=0)
        else:
            albedo = coefs["ptm"][5]  # the PTM's constant term: mean brightness
    return BandFit(written, normals, albedo)


def blas_threads() -> int | None:
    """Threads this process's BLAS uses (None when no BLAS is found)."""
    from threadpoolctl import threadpool_info

    counts = [int(i["num_threads"]) for i in threadpool_info() if i["user_api"] == "blas"]
    return counts[0] if counts else None


def fit_band_recording(band: np.ndarray, plan: BandPlan, threads: int | None = None) -> BandFit:
    """:func:`fit_band` in a process of its own (a Dask worker): the warnings it issues are
    returned with the band rather than lost in the worker's log, for the caller to re-issue.

    ``threads``: BLAS threads to fit with — those of the process that planned the fit
    (:func:`blas_threads`). OpenBLAS's matrix products round differently with one thread than
    with several (measured: one quantised PTM byte in 92 000 differed by 1), and a Dask nanny
    starts its workers with ``OMP_NUM_THREADS=1``; fitting with the planner's count keeps the
    outputs identical to the single-process fit on the same kind of machine.
    """
    from threadpoolctl import threadpool_limits

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        warnings.simplefilter("ignore", FitTrustWarning)
        if threads is None:
            result = fit_band(band, plan)
        else:
            with threadpool_limits(limits=threads, user_api="blas"):
                result = fit_band(band, plan)
    result.warnings = [(w.category, str(w.message)) for w in fit_warnings(caught)]
    return result


#: Warnings about the process, not the fit (a file some other code left to the garbage
#: collector, a library's deprecation): recording them would put them in ``fit.json``.
PROCESS_WARNINGS = (ResourceWarning, DeprecationWarning, PendingDeprecationWarning, ImportWarning)


def fit_warnings(caught: list[warnings.WarningMessage] | None) -> list[warnings.WarningMessage]:
    """The warnings a fit recorded that concern the fit; the others are re-issued to the
    filters outside the fit (which by default ignore a ``ResourceWarning``). Those of the JIT
    compiler (numba's, e.g. a kernel it cannot cache) concern the process too."""
    kept = []
    for w in caught or []:
        jit = w.category.__module__.partition(".")[0] in ("numba", "llvmlite")
        if jit or issubclass(w.category, PROCESS_WARNINGS):
            warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
        else:
            kept.append(w)
    return kept
