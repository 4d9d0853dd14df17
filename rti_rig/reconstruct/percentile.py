"""A high percentile of many values without holding them all: what a fit's reference level is.

:meth:`rti_rig.reconstruct.stack.ImageStack.reference_level` is the 99th percentile of a pixel
sample — 5.4 million float32 values (22 MB) at 72 images × 2.5 MP × RGB. Partitioning a copy of
them (what ``numpy.percentile`` does) doubled that, and a normals-only fit of such an
acquisition has 108 MB in all (relight's figure, issue #29). Only the values above the
percentile matter: the ``m`` largest values of the whole are among the ``m`` largest of any
part that holds them, so :class:`TopValues` keeps, part by part, the ``m`` largest seen so far
(about 1 % of the values at ``q`` = 99), and the percentile is read from those. It is exactly
what the fit computed before (``numpy.percentile``'s linear interpolation between the same two
order statistics, in float64); against ``numpy.percentile`` on float32 input it can differ at
the rounding level.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import NDArray

#: Values per part when a whole array is given (float32: 4 MB).
CHUNK = 1 << 20


def _rank(size: int, q: float) -> tuple[int, float]:
    """Order statistic below the ``q``-th percentile of ``size`` values, and the fraction of
    the way to the next one (numpy's linear method)."""
    pos = q / 100.0 * (size - 1)
    lo = math.floor(pos)
    return lo, pos - lo


def values_needed(size: int, q: float) -> int:
    """How many of the largest values the ``q``-th percentile of ``size`` values reads
    (it never decreases as ``size`` grows, so a bound on the size gives a safe count)."""
    return size - _rank(size, q)[0] if size else 0


class TopValues:
    """The ``keep`` largest finite values of everything :meth:`add` was given, and how many
    finite values that was; memory about twice ``keep`` plus one part."""

    def __init__(self, keep: int) -> None:
        self.keep = max(1, int(keep))
        self.finite = 0
        self._top: NDArray[Any] = np.empty(0, np.float32)
        self._pending: list[NDArray[Any]] = []
        self._pending_size = 0

    def add(self, values: NDArray[Any]) -> None:
        flat = np.asarray(values).reshape(-1)
        ok = np.isfinite(flat)
        if not ok.all():
            flat = flat[ok]
        self.finite += int(flat.size)
        if flat.size > self.keep:  # a copy of its top only: the partitioned part is let go
            flat = np.partition(flat, flat.size - self.keep)[flat.size - self.keep :]
        self._pending.append(flat.copy())
        self._pending_size += flat.size
        if self._pending_size > self.keep:
            self._merge()

    def _merge(self) -> None:
        top = np.concatenate([self._top, *self._pending])
        self._pending, self._pending_size = [], 0
        if top.size > self.keep:
            top = np.partition(top, top.size - self.keep)[top.size - self.keep :].copy()
        self._top = top

    def percentile(self, q: float) -> float:
        """The ``q``-th percentile (linear interpolation) of the finite values added; 0.0 when
        there were none. Raises ValueError when more values were added than ``keep`` allows
        for this ``q`` (the bound was too small)."""
        if self.finite == 0:
            return 0.0
        self._merge()
        need = values_needed(self.finite, q)
        if need > self.keep:
            raise ValueError(f"{need} top values needed, {self.keep} kept")
        _, frac = _rank(self.finite, q)
        top = self._top
        k = top.size - need  # the lowest rank read, among the kept values
        part = np.partition(top, k)
        a = float(part[k])
        if k + 1 >= top.size:
            return a
        b = float(part[k + 1 :].min())
        return a + (b - a) * frac


def percentile(values: NDArray[Any], q: float, chunk: int = CHUNK) -> float:
    """``numpy.percentile`` (linear) of the finite ``values`` for a high ``q``, a chunk at a
    time (see the module's note); 0.0 when none is finite."""
    flat = np.asarray(values).reshape(-1)
    top = TopValues(values_needed(flat.size, q))
    for start in range(0, flat.size, chunk):
        top.add(flat[start : start + chunk])
    return top.percentile(q)
