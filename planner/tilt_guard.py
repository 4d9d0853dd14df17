"""A guard for the ``optimal`` exchange: a swap may not leave a tilted object unsolvable.

The planner cannot see a global tilt (a tilted plane shades like a level one of another albedo),
so :func:`rti_rig.planner.surface_estimate.hedge_global_tilt` adds copies of the surface tilted
by 25°. That hedge is a cost, and a cost trades: on the simulated 50°-tilted plane it let the
exchange pick 4 lights at 24–34° elevation, two of them behind the plane, leaving every pixel
with two lit lights and nothing solved (49.8° mean error in 2 of 6 draws, against 0.25° for an
even layout). Heavier or wider hedges fixed that scene only by making glossy ones worse
(docs/research/planner.md, "The tilt guard"). The cliff is not a matter of degree, so it is
guarded as a constraint, not weighed as a cost: the exchange may not accept a swap that leaves
the layout less robust to a tilt than the even layouts it is compared with (up to a cap).

Robustness here is :func:`tilt_tolerance`: the largest tilt of the object's plane (every
azimuth) under which the lights that still face it past grazing determine a normal — at least
:data:`NEED_LIT` of them (the three a Lambertian fit needs), their directions conditioned as
the fit asks of a pixel's lights (:data:`SOLVABLE_COND`). Counting facing lights was not enough:
on the simulated 50°-tilted plane an optimal plan of 6 lights had, at that tilt, three facing
lights on one great circle (condition number ~2e4) and a fourth at 3° above grazing; the robust
fit solved 59 % of the pixels (20.8° mean error, against 0.2–0.5° in the other 7 draws), while
the plan said its lights faced the plane up to 60° of tilt. The guard asks the plan for the
largest tolerance among the even layouts the exchange may start from, capped at
:data:`MAX_GUARD_DEG`, and starts it from the cheapest layout that has it; it never asks more
than a start had, so the exchange keeps a layout to return.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from rti_rig.planner.objectives import GRAZING_COS

#: Whether ``optimal``'s exchange is guarded; only ``benchmarks.planner_tilt_guard`` turns it
#: off, to measure what the guard costs and saves.
ENABLED = True

#: Lights a Lambertian fit needs to face a pixel (its three unknowns).
NEED_LIT = 3
#: The largest condition number of the facing lights' directions under which their plane counts
#: as solved: the robust fit's own limit for a pixel's lights
#: (``rti_rig.reconstruct.solve.COND_LIMIT``, restated: the planner stands on the core alone;
#: a test keeps the two equal). Three lights on one great circle face a plane and solve nothing.
SOLVABLE_COND = 100.0

#: The tilts checked (degrees from the plane's estimated normal), and their azimuths. The cap
#: was chosen on the simulator's five trade-off scenes (``benchmarks.planner_tilt_guard``, which
#: also measures 60°): at 40° no cell was left unsolved (worst: the 50°-tilted plane at 4
#: lights, 2.2° against 17.4° unguarded) and the glossy coin kept most of its gain at 4–5
#: lights; at 60° the ratios to the even layout were better but the coin at 4 lights fell from
#: 8.1° to 21.5°, no better than an even layout.
TILT_STEP_DEG = 5.0
MAX_GUARD_DEG = 40.0
GUARD_AZIMUTHS = 24
#: How far every plan's written layout is checked (:func:`tilt_tolerance`) for the plan to say
#: the tilt its lights survive: past the guard's cap, so a plan that keeps more says so.
REPORT_MAX_DEG = 60.0


def object_plane(normals: NDArray[np.float64] | None) -> NDArray[np.float64]:
    """The object's plane as the preview's surface estimate sees it: the mean of its normals;
    level (z up) with no estimate or a mean too short to have a direction."""
    if normals is not None:
        mean = np.asarray(normals, dtype=np.float64).reshape(-1, 3).mean(axis=0)
        if np.linalg.norm(mean) > 1e-6:
            return mean / np.linalg.norm(mean)
    return np.array([0.0, 0.0, 1.0])


def tilted_planes(up: NDArray[np.float64], max_deg: float) -> NDArray[np.float64]:
    """Unit normals of the plane ``up`` tilted by every step up to ``max_deg`` towards every
    azimuth (:data:`TILT_STEP_DEG`, :data:`GUARD_AZIMUTHS`), ``up`` itself first."""
    up = np.asarray(up, dtype=np.float64)
    up = up / np.linalg.norm(up)
    # an orthonormal frame around up
    seed = np.array([1.0, 0.0, 0.0]) if abs(up[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    e1 = np.cross(up, seed)
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(up, e1)
    steps = np.arange(TILT_STEP_DEG, max_deg + 1e-9, TILT_STEP_DEG)
    phi = 2.0 * np.pi * np.arange(GUARD_AZIMUTHS) / GUARD_AZIMUTHS
    t = np.radians(steps)[:, None, None]
    around = np.cos(phi)[:, None] * e1 + np.sin(phi)[:, None] * e2  # (azimuths, 3)
    planes = np.cos(t) * up + np.sin(t) * around[None]
    return np.concatenate([up[None], planes.reshape(-1, 3)])


def outer_products(lights: NDArray[np.float64]) -> NDArray[np.float64]:
    """Each light's ``l lᵀ`` flattened (K × 9): a set's Gram matrix is a sum of rows."""
    lights = np.asarray(lights, dtype=np.float64)
    return np.einsum("ki,kj->kij", lights, lights).reshape(-1, 9)


def solvable(grams: NDArray[np.float64], counts: NDArray[np.intp]) -> NDArray[np.bool_]:
    """Per plane: whether its facing lights (``counts`` of them, Gram matrix ``grams``, rows of
    9) determine a normal — at least :data:`NEED_LIT`, conditioned within
    :data:`SOLVABLE_COND` (cond(L)² = λmax/λmin of LᵀL)."""
    grams = np.asarray(grams, dtype=np.float64).reshape(-1, 3, 3)
    counts = np.asarray(counts).reshape(-1)
    ok = counts >= NEED_LIT
    if ok.any():
        ok[ok] = _conditioned(np.linalg.eigvalsh(grams[ok]))
    return ok


def _conditioned(eig: NDArray[np.float64], slack: float = 0.0) -> NDArray[np.bool_]:
    """Per row of ascending eigenvalues of LᵀL: λmin > 0 and λmax + ``slack`` ≤
    SOLVABLE_COND² λmin — the one test :func:`solvable` and :meth:`TiltGuard.allowed` share
    (``slack`` 1: still true after any unit light is added)."""
    return (eig[:, 0] > 0.0) & (eig[:, -1] + slack <= SOLVABLE_COND**2 * eig[:, 0])


def facing_count(lights: NDArray[np.float64], up: NDArray[np.float64]) -> int:
    """How many of ``lights`` face the plane of normal ``up`` past grazing: with
    :func:`tilt_tolerance` -1, it tells too few facing lights from facing lights that lie on
    one great circle."""
    return int(((np.asarray(lights, dtype=np.float64) @ np.asarray(up)) > GRAZING_COS).sum())


def _planes_solved(lights: NDArray[np.float64], planes: NDArray[np.float64]) -> NDArray[np.bool_]:
    facing = (planes @ np.asarray(lights, dtype=np.float64).T) > GRAZING_COS
    return solvable(facing @ outer_products(lights), facing.sum(axis=1))


def tilt_tolerance(
    lights: NDArray[np.float64], up: NDArray[np.float64], max_deg: float | None = None
) -> float:
    """The largest checked tilt (degrees, a multiple of :data:`TILT_STEP_DEG` up to
    ``max_deg``) under which, at every azimuth and every smaller tilt, the ``lights`` facing
    the plane past grazing determine a normal (:func:`solvable`); -1 if the level plane's do
    not. ``max_deg`` None: :data:`MAX_GUARD_DEG`."""
    planes = tilted_planes(up, MAX_GUARD_DEG if max_deg is None else max_deg)
    enough = _planes_solved(lights, planes)
    if not enough[0]:
        return -1.0
    per_step = enough[1:].reshape(-1, GUARD_AZIMUTHS).all(axis=1)
    failed = np.flatnonzero(~per_step)
    steps = len(per_step) if len(failed) == 0 else int(failed[0])
    return steps * TILT_STEP_DEG


@dataclass(frozen=True)
class TiltGuard:
    """Which swaps keep every plane of ``lit`` (rows: planes, columns: candidates) solved by
    the chosen lights that face it (:func:`solvable`); ``outer``: each candidate's ``l lᵀ``
    (:func:`outer_products`)."""

    lit: NDArray[np.bool_]
    outer: NDArray[np.float64]
    tolerance_deg: float

    def holds(self, chosen: NDArray[np.intp]) -> bool:
        """Whether ``chosen`` meets the guard."""
        chosen = np.asarray(chosen, dtype=np.intp)
        facing = self.lit[:, chosen]
        return bool(solvable(facing @ self.outer[chosen], facing.sum(axis=1)).all())

    def allowed(self, chosen: NDArray[np.intp], pos: int) -> NDArray[np.bool_]:
        """Per candidate: whether putting it at position ``pos`` of ``chosen`` meets the guard.

        Exact, and cheap where the other lights already solve a plane with room to spare:
        adding a unit light raises LᵀL's smallest eigenvalue (or keeps it) and its largest by
        at most 1, so a plane whose others have λmax + 1 ≤ SOLVABLE_COND² λmin stays solved
        whatever is added; only the other planes are checked candidate by candidate."""
        others = np.delete(np.asarray(chosen, dtype=np.intp), pos)
        n_cand = self.lit.shape[1]
        facing = self.lit[:, others]
        count = facing.sum(axis=1)
        if (count < NEED_LIT - 1).any():
            return np.zeros(n_cand, dtype=bool)
        gram = facing @ self.outer[others]  # (planes, 9)
        eig = np.linalg.eigvalsh(gram.reshape(-1, 3, 3))
        enough = count >= NEED_LIT
        # a plane the others leave unsolved stays so unless the newcomer faces it
        allowed = self.lit[~(enough & _conditioned(eig))].all(axis=0)
        roomy = enough & _conditioned(eig, slack=1.0)
        check = np.flatnonzero(~roomy)
        todo = np.flatnonzero(allowed)
        if check.size == 0 or todo.size == 0:
            return allowed
        lit = self.lit[np.ix_(check, todo)]  # (planes checked, candidates)
        g = gram[check][:, None, :] + lit[..., None] * self.outer[todo][None, :, :]
        ok = solvable(g.reshape(-1, 9), (count[check][:, None] + lit).reshape(-1))
        allowed[todo] = ok.reshape(lit.shape).all(axis=0)
        return allowed


def tilt_guard(
    candidates: NDArray[np.float64],
    up: NDArray[np.float64],
    starts: Sequence[NDArray[np.intp]],
) -> TiltGuard | None:
    """The guard that keeps the largest tilt tolerance among ``starts`` (capped at
    :data:`MAX_GUARD_DEG`); None when no start has any to keep."""
    candidates = np.asarray(candidates, dtype=np.float64)
    tolerance = max(tilt_tolerance(candidates[np.asarray(s, dtype=np.intp)], up) for s in starts)
    if tolerance <= 0.0:
        return None
    lit = (tilted_planes(up, tolerance) @ candidates.T) > GRAZING_COS
    return TiltGuard(lit, outer_products(candidates), tolerance)
