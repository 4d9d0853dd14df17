"""The QA verdict judges again at most a few of the images it calls dim.

Why: each image judged again beside the other dim ones scaled back costs one robust fit of the
crop (about 5 s with 72 lights on a busy 2-core machine). Every image called dim had been
judged again: a weak ring or a failing supply dimming 20-30 lights would have added minutes to
every verdict. The few nearest to right are the ones a neighbour's dim light can have dragged
down; those are judged again, the brightest first.
"""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

import rti_rig.reconstruct.qa as qa
from rti_rig.reconstruct.errors import ReconstructionError


def test_at_most_a_few_dim_images_are_judged_again_the_nearest_to_right_first(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    n = 24
    gains = np.linspace(0.2, 0.55, n)  # every image called dim, none of them light-less
    ev = SimpleNamespace(dim=np.ones(n, dtype=bool), lit_gain=gains, moved=np.zeros(n, dtype=bool))
    judged: list[int] = []

    def fit(stack, lights, robust, saturation):  # type: ignore[no-untyped-def]
        # the image judged is the one left as captured; the others are scaled up by 1/gain
        judged.append(int(np.argmin(stack.reshape(len(stack), -1)[:, 0])))
        raise ReconstructionError("stand-in: nothing to fit")

    monkeypatch.setattr(qa, "fit_photometric_stereo", fit)
    crop = np.ones((n, 2, 2), dtype=np.float32)
    lights = np.tile([0.0, 0.0, 1.0], (n, 1))
    out = qa._dim_rejudged(ev, crop, lights, np.zeros(n, dtype=bool), None, lambda *a, **k: None)  # type: ignore[arg-type]
    assert out is ev
    assert judged == list(range(n - 1, n - 1 - qa.MAX_DIM_REJUDGED, -1))  # brightest first
