"""The edge images' spectra and medians are made once per stack (qa_drift.EdgeImages): the
same values as made afresh, and a window other than the stack's own is never served from
the cache (it would correlate under the wrong window)."""

from __future__ import annotations

import numpy as np

from rti_rig.reconstruct.qa_bands import median_of_images
from rti_rig.reconstruct.qa_drift import EdgeImages, _spectrum


def _stack() -> np.ndarray:
    rng = np.random.default_rng(3)
    yy, xx = np.mgrid[0:48, 0:64]
    base = ((xx // 8 + yy // 8) % 2).astype(np.float32)
    return np.stack([base + 0.05 * rng.random(base.shape, np.float32) for _ in range(6)])


def test_spectra_and_medians_equal_those_made_afresh() -> None:
    crops = _stack()
    edges = EdgeImages(crops, np.ones(len(crops), bool))
    for i in edges.have:
        once = edges.spectrum(i, edges.window)
        assert edges.spectrum(i, edges.window) is once  # kept, not remade
        fresh = _spectrum(edges.edges[i].astype(np.float64), edges.window)
        assert np.array_equal(once, fresh)
    some = edges.have[:3]
    first = edges.median_of(some)
    assert np.array_equal(first, edges.median_of(some))
    assert np.array_equal(first, median_of_images([edges.edges[i] for i in some]))


def test_another_window_is_not_served_from_the_cache() -> None:
    crops = _stack()
    edges = EdgeImages(crops, np.ones(len(crops), bool))
    edges.spectrum(0, edges.window)
    flat = np.ones_like(edges.window)
    got = edges.spectrum(0, flat)
    assert np.array_equal(got, _spectrum(edges.edges[0].astype(np.float64), flat))
    assert not np.array_equal(got, edges.spectrum(0, edges.window))


def test_spectra_past_the_budget_are_made_afresh_not_kept(monkeypatch) -> None:
    """A dense acquisition's QA does not keep a spectrum per light: past SPECTRA_KEPT_BYTES
    each is computed again (the same values), so its memory does not grow with the lights."""
    from rti_rig.reconstruct import qa_drift

    crops = _stack()
    edges = EdgeImages(crops, np.ones(len(crops), bool))
    one = edges.spectrum(0, edges.window).nbytes
    edges = EdgeImages(crops, np.ones(len(crops), bool))
    monkeypatch.setattr(qa_drift, "SPECTRA_KEPT_BYTES", 2 * one)
    made = [edges.spectrum(i, edges.window) for i in edges.have]
    assert len(edges._spectra) == 2  # the first two kept, the rest not
    last = edges.have[-1]
    again = edges.spectrum(last, edges.window)
    assert again is not made[-1] and np.array_equal(again, made[-1])
