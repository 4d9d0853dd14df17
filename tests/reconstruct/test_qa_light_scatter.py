"""QA tells an image brightened by its own light's output (within the session's light-to-light
scatter, as an uncalibrated dome's LEDs make it) from one brightened on its own (a stray flash:
far outside the scatter, or in a session whose lights agree)."""

from __future__ import annotations

import numpy as np
import pytest

from rti_rig.reconstruct.qa import (
    BRIGHTER,
    LIGHT_SCATTER_MIN,
    LIGHT_SCATTER_Z,
    QAReport,
    assess,
)
from rti_rig.reconstruct.synthetic import fibonacci_lights, render, sphere_normals

N = 36
BRIGHT = 20  # the image made brighter


def _report(gains: np.ndarray) -> QAReport:
    """A matte sphere under ``N`` lights, each image scaled by its light's output."""
    lights = fibonacci_lights(N)
    normals, _ = sphere_normals(96, 96)
    images = render(normals, 0.5, lights) * gains[:, None, None]
    frames = [np.clip(im * 0.5 * 65535, 0, 65535).astype(np.uint16) for im in images]
    return assess(frames, lights, [f"image_{i + 1:03d}" for i in range(N)])


def _uneven(bright: float) -> np.ndarray:
    """LED outputs drawn at 20 % RMS (ln), as a real uncalibrated dome's; one set to ``bright``."""
    gains = np.exp(0.2 * np.random.default_rng(1).standard_normal(N))
    gains[BRIGHT] = bright
    return gains


def _bright_problem(report: QAReport) -> list[str]:
    return [p for p in report.images[BRIGHT].problems if p.endswith(BRIGHTER)]


def test_a_bright_image_within_uneven_lights_is_told_apart() -> None:
    report = _report(_uneven(1.9))
    assert report.light_scatter >= LIGHT_SCATTER_MIN
    check = report.images[BRIGHT]
    assert _bright_problem(report), check  # still called brighter by the QA itself ...
    assert check.within_light_scatter and check.misfit < 0.05  # ... but its light explains it
    assert [c.index for c in report.bright_within_light_scatter()] == [BRIGHT]
    explained = report.explain_bright_by_lights("the lights differ: calibrate them")
    assert explained.good and not explained.reshoot
    assert explained.verdict.startswith("no image to reshoot, but the lights differ")
    assert explained.to_json()["light_note"] == "the lights differ: calibrate them"


@pytest.mark.parametrize(
    ("gains", "why"),
    [
        # every other light gives the same: one bright image is that image's fault
        (np.where(np.arange(N) == BRIGHT, 1.9, 1.0), "lights agree"),
        # uneven lights, but this image far brighter than any of them gives
        (_uneven(4.0), "beyond the scatter"),
    ],
)
def test_a_bright_image_the_lights_cannot_explain_stays_to_reshoot(
    gains: np.ndarray, why: str
) -> None:
    report = _report(gains)
    assert _bright_problem(report), why
    assert not report.images[BRIGHT].within_light_scatter, why
    if why == "lights agree":
        assert report.light_scatter < LIGHT_SCATTER_MIN
    else:
        z = abs(np.log(report.images[BRIGHT].gain)) / report.light_scatter
        assert z > LIGHT_SCATTER_Z
    kept = report.explain_bright_by_lights("the lights differ")
    assert kept is report and [c.index for c in kept.reshoot] == [BRIGHT]
    assert kept.verdict.startswith("reshoot: image_021 (")


def test_another_problem_of_an_explained_image_still_calls_for_a_reshoot() -> None:
    from dataclasses import replace

    report = _report(_uneven(1.9))
    images = list(report.images)
    moved = "object or camera moved: shifted (+2.0, +0.0) px against the others"
    images[BRIGHT] = replace(images[BRIGHT], problems=(*images[BRIGHT].problems, moved))
    explained = replace(report, images=tuple(images)).explain_bright_by_lights("lights differ")
    assert explained.images[BRIGHT].problems == (moved,)
    assert explained.verdict.startswith(f"reshoot: image_021 ({moved}); lights differ")


def test_the_bright_claim_is_taken_off_by_what_it_is_not_by_its_words() -> None:
    """The application takes the bright claim off an image its light explains. It finds that
    claim by the check's own record of it (``bright_problem``), so another problem of the image
    stays and a claim reworded tomorrow still goes (it was found by matching English text)."""
    from dataclasses import replace

    report = _report(_uneven(1.9))
    check = report.images[BRIGHT]
    assert check.bright_problem is not None and check.bright_problem in check.problems
    assert all(c.bright_problem is None for c in report.images if c.index != BRIGHT)
    reworded = "1.9x the brightness its neighbours give"
    other = "object or camera moved: shifted (+3.0, +0.0) px against the others"
    images = tuple(
        replace(c, problems=(reworded, other), bright_problem=reworded) if c.index == BRIGHT else c
        for c in report.images
    )
    explained = replace(report, images=images).explain_bright_by_lights("the lights differ")
    after = explained.images[BRIGHT]
    assert after.problems == (other,) and after.bright_problem is None
    assert [c.index for c in explained.reshoot] == [BRIGHT]  # still to reshoot: it moved


def test_a_note_on_a_fit_no_image_could_measure_says_so_not_inf_percent() -> None:
    from rti_rig.reconstruct.qa import MISFIT_LIMIT, _poor_fit_said

    unmeasured = _poor_fit_said(float("inf"))
    assert "inf" not in unmeasured and "poorly" not in unmeasured, unmeasured
    said = _poor_fit_said(0.42)
    assert said.endswith(f"poorly (median misfit 42%, limit {MISFIT_LIMIT:.0%})"), said
