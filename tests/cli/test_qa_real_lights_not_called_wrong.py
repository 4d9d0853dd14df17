"""QA calls a light wrong only against a majority that agrees with its recorded lights.

A real acquisition replayed (the gilded icon of tests/data/neuralrti_replay) at 12 lights: every
image is the recorded image of the light the .lp names, yet QA had told the user to reshoot two
of them as "wrong light … (swapped?)" at 111-120°, because one image happened to point within
8° of its light and set "the images that agree" for all. Real swaps are still named, in a small
session too (the six and nine swapped pairs of 36 are tests/app/test_fit_cli.py's cases).
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.reconstruct.qa import assess
from rti_rig.reconstruct.synthetic import fibonacci_lights, render, sphere_normals

REPO = Path(__file__).resolve().parents[2]
ACQ = REPO / "tests" / "data" / "neuralrti_replay"
runner = CliRunner()


@pytest.mark.slow
@pytest.mark.e2e
def test_a_replayed_real_session_has_no_light_called_wrong(tmp_path: Path) -> None:
    out = tmp_path / "s"
    r = runner.invoke(app, ["run", str(ACQ / "dirs.lp"), "--out", str(out), "--lights", "12"])
    assert r.exit_code == 0, r.output
    said = " ".join(r.output.split())
    assert "QA verdict" in said
    assert "wrong light:" not in said, said  # the problem as QA names it on an image
    # the check not made is said, with why, not passed over in silence
    assert "light directions not checked" in said and "most disagree" in said, said
    # what is really wrong with these images is still said: the source has clipped highlights
    assert "saturated" in said


def _matte_session(n: int, swaps: tuple[tuple[int, int], ...]):  # type: ignore[no-untyped-def]
    lights = fibonacci_lights(n)
    normals, _ = sphere_normals(96, 96)
    images = render(normals, 0.6, lights)
    frames = [np.clip(im * 0.8 * 65535, 0, 65535).astype(np.uint16) for im in images]
    recorded = lights.copy()
    for i, j in swaps:
        recorded[[i, j]] = recorded[[j, i]]
    return assess(frames, recorded, [f"image{k:02d}.tif" for k in range(n)])


@pytest.mark.parametrize(
    ("n", "swaps"),
    [(9, ((2, 6),)), (12, ((1, 5), (6, 11)))],
    ids=["one pair of 9", "two pairs of 12"],
)
def test_swapped_lights_in_a_small_session_are_still_named(
    n: int, swaps: tuple[tuple[int, int], ...]
) -> None:
    report = _matte_session(n, swaps)
    expected = {f"image{k:02d}.tif" for k in np.ravel(swaps)}
    assert {c.name for c in report.reshoot} == expected, report.verdict
    assert all("wrong light:" in "; ".join(c.problems) for c in report.reshoot)
    assert report.directions_checked


def test_a_clean_nine_light_session_is_good() -> None:
    report = _matte_session(9, ())
    assert report.good and report.directions_checked, report.verdict
    assert json.dumps(report.to_json())  # serialisable as written to qa.json
