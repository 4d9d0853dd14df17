"""An image clipped in one channel only is clipped to the QA.

A red object under a warm LED clips its red channel while its grey mean stays well below full
scale. The QA had measured the clipping that stops it judging a light direction on the grey
crop, so an image 50.3 % clipped in red had its light direction fitted on the clipped pixels
and was named "wrong light: lit from 12° away … (swapped?)" beside "saturated".
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from fit_sessions import _rings, make_session
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.reconstruct.qa import assess

runner = CliRunner()

#: Twelve lights in rings from 10° to 70° (as test_fit_cli's clipped-throughout test).
TWELVE = _rings(((10, 2, 0), (25, 3, 45), (40, 3, 108), (55, 3, 22), (70, 1, 60)))


def test_a_session_clipped_in_red_only_is_called_clipped_not_a_wrong_light(
    tmp_path: Path,
) -> None:
    session, _, _ = make_session(
        tmp_path / "s",
        lights=TWELVE,
        size=(96, 112),
        saturate=2,
        saturate_gain=3.0,
        saturate_channel=0,
    )
    out = tmp_path / "out"
    r = runner.invoke(app, ["fit", str(session), "--out", str(out), "--model", "ps"])
    assert r.exit_code == 0, r.output
    qa = json.loads((out / "qa.json").read_text())
    assert set(qa["reshoot"]) == {"image_003"}, qa["verdict"]
    assert "saturated: 5" in qa["verdict"], qa["verdict"]  # about half the pixels
    assert "wrong light" not in qa["verdict"], qa["verdict"]
    assert (
        "light direction not checked on image_003 (more than 50% of the pixels judged clipped)"
        in qa["verdict"]
    )


@pytest.mark.parametrize("channel", [0, 1, 2])
@pytest.mark.parametrize("dtype", [np.uint8, np.uint16])
def test_any_channel_at_the_top_of_its_range_counts_as_clipped(
    channel: int, dtype: type[np.integer]
) -> None:
    """As stored: 255 in an 8-bit image, 65535 in a 16-bit one, in whichever channel."""
    top = np.iinfo(dtype).max
    h, w = 48, 64
    yy, xx = np.mgrid[0:h, 0:w]
    # a dome of normals: every light shades it differently
    nx, ny = (xx - w / 2) / w, -(yy - h / 2) / h
    n = np.stack([nx, ny, np.ones_like(nx)], axis=-1)
    n /= np.linalg.norm(n, axis=-1, keepdims=True)
    frames = []
    for i, light in enumerate(TWELVE):
        shade = np.clip(n @ light, 0.0, None) * 0.5
        rgb = np.repeat(shade[..., None], 3, axis=2)
        if i == 2:
            rgb[..., channel] = 1.0  # that channel clipped throughout, the others not
        frames.append(np.round(rgb * top).astype(dtype))
    qa = assess(frames, TWELVE, [f"image_{k + 1:03d}" for k in range(len(TWELVE))])
    assert "image_003" in [c.name for c in qa.reshoot], qa.verdict
    assert "saturated: 100.0% of pixels clipped" in qa.verdict, qa.verdict
    assert "wrong light" not in qa.verdict, qa.verdict
    assert "light direction not checked on image_003" in qa.verdict, qa.verdict
