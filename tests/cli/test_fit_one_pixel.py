"""A one-pixel acquisition is fitted, and its QA is declined by name, not by a traceback.

The QA's shift check correlates images under a Hanning window that OpenCV refuses on a side of
1 px: ``rti-rig fit`` of 1×1 images wrote its outputs and then ended in ``cv2.error``.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.cli.fit import print_verdict
from rti_rig.core.image_files import write_linear_tiff
from rti_rig.core.lp_format import LpEntry, write_lp
from tests.fit_sessions import dome_lights


def _session(root: Path, shape: tuple[int, int]) -> Path:
    session, lights = root / "s", dome_lights()[:12]
    (session / "linear").mkdir(parents=True)
    normal = np.array([0.2, 0.1, 0.97]) / np.linalg.norm([0.2, 0.1, 0.97])
    for k, d in enumerate(lights):
        value = 0.7 * max(float(normal @ d), 0.0) + 0.01
        write_linear_tiff(
            session / "linear" / f"image_{k + 1:03d}.tif",
            np.full(shape, int(value * 65535), np.uint16),
        )
    write_lp(
        session / "lights.lp",
        [LpEntry(f"image_{k + 1:03d}.jpg", tuple(d)) for k, d in enumerate(lights)],
    )
    return session


def test_one_pixel_images_get_no_qa_and_no_traceback(tmp_path: Path) -> None:
    session = _session(tmp_path, (1, 1))
    r = CliRunner().invoke(app, ["fit", str(session), "--out", str(tmp_path / "f")])
    said = " ".join(r.output.split())
    assert r.exit_code == 0, (said, r.exception)
    assert "QA not possible: the images are 1×1 px" in said
    assert np.isfinite(np.load(tmp_path / "f" / "normals.npy")).all()


@pytest.mark.parametrize("shape", [(1, 1), (1, 8), (2, 1)])
def test_runs_closing_verdict_says_why_not_a_traceback(
    tmp_path: Path, shape: tuple[int, int], capsys: pytest.CaptureFixture[str]
) -> None:
    """``rti-rig run``'s last line (:func:`print_verdict`) called the QA unguarded: the guard
    was in the fit alone, and the verdict of 1×1, 1×8 or 2×1 images was a ``cv2.error``."""
    print_verdict(_session(tmp_path, shape))
    said = " ".join(capsys.readouterr().err.split())
    h, w = shape
    assert f"QA verdict unavailable: the images are {w}×{h} px" in said
