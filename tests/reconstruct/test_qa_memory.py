"""The QA's memory per added light stays a few copies of a crop, not a dozen.

At 1000 lights of 128 px the QA had peaked at 968 MB where the fit alone took 244 MB: its
per-pixel statistics (the median residual of `_reliable_gains`, the median edge image, the crop's
placing gradients), the pooled residual median and the stacks built from lists each held several
full copies of every image's crop at once. Now they work a band of rows at a time
(qa_bands). What grows with the lights is measured here with tracemalloc (allocations, not
time): the QA's peak on many lights less its peak on few, per added image pixel. The crop stack
itself (4 bytes), its clipped mask (1), the residuals and masks the evidence keeps (about 9) and
the consensus draws' sample stay; a step that went back to stacking every image in float64, or
sorting a copy of the stack, adds 8-24 bytes more.
"""

from __future__ import annotations

import tracemalloc

import numpy as np

from rti_rig.reconstruct.qa import assess
from rti_rig.reconstruct.synthetic import sphere_frames

SIDE = 96
#: Bytes per added image pixel the QA's peak may grow by (measured: 20.3 now; 28 with a float64
#: copy of the reduced stack for flat_images' percentiles and a copy of the crop stack held
#: beside it; 45 before the bands). tracemalloc counts bytes, so CPU load cannot move it.
BYTES_PER_ADDED_PIXEL = 25


def _frames(n: int) -> tuple[list[np.ndarray], np.ndarray]:
    return sphere_frames(n, SIDE, specular=0.3, shininess=40.0)


def _qa_peak(n: int) -> int:
    frames, lights = _frames(n)
    names = [f"image_{i + 1:03d}" for i in range(n)]
    assess(frames[:8], lights[:8], names[:8])  # imports and caches before measuring
    tracemalloc.start()
    try:
        base, _ = tracemalloc.get_traced_memory()
        assess(frames, lights, names)
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    return peak - base


def test_the_qa_grows_by_a_few_copies_of_each_added_image() -> None:
    few, many = 24, 240
    grown = _qa_peak(many) - _qa_peak(few)
    per_pixel = grown / ((many - few) * SIDE * SIDE)
    assert per_pixel < BYTES_PER_ADDED_PIXEL, f"{per_pixel:.1f} bytes per added image pixel"
