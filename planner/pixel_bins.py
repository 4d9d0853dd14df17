"""Pixels that are nearly the same to the planner, scored once: a binned surface sample.

The ``optimal`` search's time is swaps scanned × candidates × pixel rows. From a preview the
rows are all different (256 sampled pixels and their six tilted hedge copies: 1792 rows), but
many differ by a fraction of a degree and are lit by the same lights. :func:`bin_pixels`
merges pixels whose normals fall in one cell of a grid of side :data:`PIXEL_BIN_DEG` and whose
cast-shadow rows are identical into one row: the cell's weighted mean normal, the shared shadow
row and the summed weight. Only the shadows of candidates at or above :data:`GRAZING_DEG` split
a cell (the row holds the cell's lit fraction for the lights below), and only the candidates'
(the normals objective never reads the held-out lights' shadows). Every term of the normals
objective is a smooth function of the normal for a fixed shadow row (the attached-shadow ramp
aside), so replacing a cell by its mean errs only to second order in the cell's size. Unlike
k-means medoids, which kept every plan within 0.02 % of the objective but cost most of what they
saved, the grid costs a sort.

The search runs on the binned sample; the plan's cost is then taken on every pixel, and a plan
no better than its starting layout by that cost is not taken (:mod:`rti_rig.planner.optimal`).
Measured in docs/research/planner.md ("Many lights"): the objective of the binned plans
against the plans of the full sample, and the paired normal errors of
``benchmarks.planner_speed_guard``.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from rti_rig.planner.objectives import (
    BIAS_PIXELS,
    POOL_MIN_PIXELS,
    NormalsObjective,
    RelightObjective,
    SurfaceSample,
)

#: Side of a cell of the normals' grid (degrees of arc; the grid is in Cartesian normal
#: components, so a cell spans this much along each axis near its centre). At 2° the arm's
#: 100-light plans from a preview stayed within 0.2 % of the full sample's objective.
PIXEL_BIN_DEG = 2.0

#: Candidates below this elevation (degrees) do not split a cell by their cast shadows: the
#: cell's row takes its pixels' weighted lit fraction for them instead. Lights that low are
#: shadowed at some pixels of almost every cell of a relief: on the shipped servo arm (lights
#: down to 0°) at 100 lights, cells split on every shadow (candidates' and held-out lights')
#: left 1480 of the test preview's 1792 rows, on the candidates' only 1419, and with the lights
#: under 5° left out of the key 861 (10°: 803, but it moved one verdict of
#: ``benchmarks.planner_speed_guard``; 5° moved no cell). 0: every candidate's shadow splits.
GRAZING_DEG = 5.0


def _row_ids(rows: NDArray[np.float64]) -> NDArray[np.intp]:
    """One integer per distinct 0/1 row of a shadow map (P, K)."""
    if rows.shape[1] == 0:
        return np.zeros(len(rows), dtype=np.intp)
    packed = np.packbits(rows > 0.5, axis=1)
    seen: dict[bytes, int] = {}
    return np.array([seen.setdefault(r.tobytes(), len(seen)) for r in packed], dtype=np.intp)


def bin_pixels(
    sample: SurfaceSample,
    bin_deg: float = PIXEL_BIN_DEG,
    bias_pixels: int = BIAS_PIXELS,
    grazing: NDArray[np.bool_] | None = None,
    held_out_shadows: bool = True,
) -> SurfaceSample:
    """The sample with nearly identical pixels merged (module notes); ``bin_deg`` 0 merges only
    pixels with equal normals and shadow rows.

    ``grazing`` (K,): candidates whose shadows do not split a cell (:data:`GRAZING_DEG`); the
    merged row holds its pixels' weighted lit fraction for them (a light's weight is linear in
    its lit value, so the row's information for that light is the cell's mean).
    ``held_out_shadows`` False: the held-out lights' shadows do not split cells either (the
    normals objective never reads them; the merged row keeps its pixels' mean for them too).

    Rows keep the order of their cells' first pixels, so the cells met among the first
    ``min(base_count, bias_pixels)`` pixels (the bias term's sub-sample of the estimated surface,
    :class:`rti_rig.planner.objectives.NormalsObjective`) lead; ``bias_weights`` carries how
    much of that sub-sample each holds.
    """
    normals = np.asarray(sample.normals, dtype=np.float64)
    wts = sample.weights / sample.weights.sum()
    if bin_deg > 0:
        cells = np.rint(normals / (2.0 * np.sin(np.radians(bin_deg) / 2.0))).astype(np.int64)
    else:
        cells = normals.view(np.int64)  # the exact bits: equal normals only
    keyed = sample.lit_candidates if grazing is None else sample.lit_candidates[:, ~grazing]
    ids = [_row_ids(keyed)[:, None]]
    if held_out_shadows:
        ids.append(_row_ids(sample.lit_held_out)[:, None])
    key = np.concatenate([cells, *ids], axis=1)
    _, first, inverse = np.unique(key, axis=0, return_index=True, return_inverse=True)
    order = np.argsort(first, kind="stable")  # cells in order of their first pixel
    rank = np.empty_like(order)
    rank[order] = np.arange(len(order))
    group = rank[inverse.ravel()]
    count = len(order)
    weight = np.bincount(group, weights=wts, minlength=count)
    mean = np.stack(
        [np.bincount(group, weights=wts * normals[:, i], minlength=count) for i in range(3)], 1
    )
    mean /= np.linalg.norm(mean, axis=1, keepdims=True)
    n_bias = min(sample.base_count or len(normals), bias_pixels)
    head = group[:n_bias]
    bias_weights = np.bincount(head, weights=wts[:n_bias], minlength=int(head.max()) + 1)
    rows = first[order]
    lit = sample.lit_candidates[rows]
    if grazing is not None and grazing.any():
        lit[:, grazing] = _mean_rows(sample.lit_candidates[:, grazing], group, wts, weight)
    if held_out_shadows:
        lit_held = sample.lit_held_out[rows]
    else:
        # the normals objective never reads these (the relight objective, which does, is not
        # binned): summed by cell, not by the (cells × pixels) product the read rows above keep
        lit_held = _cell_means(sample.lit_held_out, group, wts, weight)
    return SurfaceSample(
        mean,
        weight,
        lit,
        sample.held_out,
        lit_held,
        sample.specular,
        highlight_width_deg=sample.highlight_width_deg,
        base_count=None,
        bias_weights=bias_weights,
    )


def _mean_rows(
    values: NDArray[np.float64],
    group: NDArray[np.intp],
    wts: NDArray[np.float64],
    weight: NDArray[np.float64],
) -> NDArray[np.float64]:
    """Per cell, the weighted mean of its pixels' rows of ``values`` (P, C): (cells, C)."""
    member = np.zeros((len(weight), len(group)))
    member[group, np.arange(len(group))] = wts
    return (member @ values) / weight[:, None]


def _cell_means(
    values: NDArray[np.float64],
    group: NDArray[np.intp],
    wts: NDArray[np.float64],
    weight: NDArray[np.float64],
) -> NDArray[np.float64]:
    """:func:`_mean_rows` summed cell by cell in pixel order (every cell has a pixel): the same
    means to rounding (their last bits may differ), without a dense (cells, P) matrix and its
    product — 160 held-out lights × 1792 pixels × ~860 cells took ~20 ms."""
    order = np.argsort(group, kind="stable")
    starts = np.searchsorted(group[order], np.arange(len(weight)))
    sums = np.add.reduceat(values[order] * wts[order, None], starts, axis=0)
    return sums / weight[:, None]


def binned_objective(
    objective: NormalsObjective | RelightObjective,
    bin_deg: float | None = None,
    grazing_deg: float | None = None,
) -> NormalsObjective | RelightObjective:
    """The stand-in the exchange search sweeps with: the normals objective on the binned sample
    when that has fewer rows than the objective scores (from a preview: 1792 → 600–800);
    otherwise the objective itself (no preview: its 7 distinct rows already; the relight
    objective's cost does not grow with the pixels). ``bin_deg`` None: :data:`PIXEL_BIN_DEG`
    as it is when called (0 turns the binning off); ``grazing_deg`` None: :data:`GRAZING_DEG`
    as it is when called. The held-out lights' shadows never split a cell here (the normals
    objective does not read them)."""
    bin_deg = PIXEL_BIN_DEG if bin_deg is None else bin_deg
    if not isinstance(objective, NormalsObjective) or bin_deg <= 0:
        return objective
    if len(objective.n) < POOL_MIN_PIXELS:  # a few rows already: nothing worth the binning
        return objective
    grazing_deg = GRAZING_DEG if grazing_deg is None else grazing_deg
    d = objective.candidates.directions
    grazing = d[:, 2] < np.sin(np.radians(grazing_deg))
    binned = bin_pixels(objective.sample, bin_deg, grazing=grazing, held_out_shadows=False)
    if len(binned.normals) >= len(objective.n):
        return objective
    return NormalsObjective(
        binned, objective.candidates, bias_rel=objective.bias_rel, gain_rel=objective.gain_rel
    )
