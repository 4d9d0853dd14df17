"""The paper's method: k-means on the preview's normals, one light per cluster centre.

Reference: "one-shot planning of RTI light positions from surface topography"
(`../shared/reference/000_cf791ba4d7403715.txt` beside the repository), section *Methodology*
and its flowchart,
Figure 3: one image → monocular depth (LeReS) → normal map from the depth gradient → k-means with
``k`` = the number of lights → "the cluster centers ... correspond to where most of the pixels in
the normal map image are pointing towards. This vector intersects with the imaginary hemisphere
(RTI dome) around the image. That intersection point is recommended light position". So each
light lies along the (renormalised) mean normal of its cluster. The paper's own results
(section *Result and Discussion*, Figure 7) show it beats a homogeneous layout only at low light
counts, because the centres crowd the upper dome (30–90° elevation) where most normals point.

Two things the paper leaves open are filled in here and said so: the centres are snapped to the
rig's usable lights one-to-one (a dome cannot fire the same LED twice; an arm cannot enter its
keep-out cone), and when the surface has fewer distinct normals than lights (a flat surface has
one) the clusters are repeated, so the lights land on the distinct usable positions nearest the
centres rather than failing.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from rti_rig.planner.objectives import Candidates, snap_unique

#: Normals fed to k-means (a random subset; clustering needs the distribution, not every pixel).
KMEANS_PIXELS = 5000


@dataclass(frozen=True)
class KMeansResult:
    """Cluster centres (unit, the paper's light directions) and their pixel shares."""

    centres: NDArray[np.float64]
    shares: NDArray[np.float64]
    distinct_normals: int


#: Restarts of k-means from different random initial centroids; the lowest inertia wins.
KMEANS_RESTARTS = 3

#: Lloyd iterations per restart (it converges well before on normal maps).
KMEANS_ITERATIONS = 60


def sklearn_kmeans(
    points: NDArray[np.float64], k: int, seed: int
) -> tuple[NDArray[np.float64], NDArray[np.intp]]:
    """k-means with scikit-learn, as the paper uses it: Lloyd's algorithm, restarts.

    Random initial centroids (``init="random"``, the paper's description) with
    ``KMEANS_RESTARTS`` restarts; the lowest inertia wins. Callers hold BLAS/OpenMP to one thread
    (``threadpool_limits``): on a busy 2-core machine threads only cost here.
    """
    from sklearn.cluster import KMeans

    km = KMeans(
        n_clusters=k,
        init="random",
        n_init=KMEANS_RESTARTS,
        max_iter=KMEANS_ITERATIONS,
        random_state=seed,
    ).fit(points)
    return km.cluster_centers_.astype(np.float64), km.labels_.astype(np.intp)


def cluster_normals(normals: NDArray[np.float64], k: int, seed: int = 0) -> KMeansResult:
    """k-means (random initial centroids, restarts) on unit normals (..., 3), centres unit."""
    pts = np.asarray(normals, dtype=np.float64).reshape(-1, 3)
    rng = np.random.default_rng(seed)
    if len(pts) > KMEANS_PIXELS:
        pts = pts[rng.choice(len(pts), KMEANS_PIXELS, replace=False)]
    distinct = np.unique(np.round(pts, 6), axis=0)
    kk = int(min(k, len(distinct)))
    if kk == len(distinct):
        centres = distinct
        labels = np.argmin(np.linalg.norm(pts[:, None, :] - distinct[None, :, :], axis=-1), axis=1)
    else:
        centres, labels = sklearn_kmeans(pts, kk, seed)
    shares = np.bincount(labels, minlength=kk) / len(pts)
    norm = np.linalg.norm(centres, axis=1, keepdims=True)
    centres = np.where(norm > 1e-9, centres / np.maximum(norm, 1e-9), [0.0, 0.0, 1.0])
    return KMeansResult(centres, shares, len(distinct))


def kmeans_targets(result: KMeansResult, n: int) -> NDArray[np.float64]:
    """``n`` target directions: the centres, repeated by pixel share when there are fewer."""
    c = result.centres
    if len(c) >= n:
        return c[:n]
    extra = n - len(c)
    order = np.argsort(-result.shares, kind="stable")
    reps = np.resize(order, extra)
    return np.concatenate([c, c[reps]])


def plan_kmeans(
    normals: NDArray[np.float64], n: int, candidates: Candidates, seed: int = 0
) -> tuple[NDArray[np.intp], KMeansResult]:
    """Candidate indices chosen by the paper's method (cluster centres snapped one-to-one)."""
    result = cluster_normals(normals, n, seed)
    return snap_unique(kmeans_targets(result, n), candidates), result
