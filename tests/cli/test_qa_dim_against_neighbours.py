"""QA names a light at half its neighbours' brightness even where the Lambertian prediction
cannot tell (a glossy object's images sit well above or below it, light by light).

On the shared 72-light real acquisition a 1-stop dim LED kept a bright-end gain of 0.6-1.9
(the absolute limit is 0.6) in 7 of 12 cases; against its 4 nearest lights it read 0.41-0.58,
where no clean image of that acquisition reads below 0.595. Here the same situation is made
from the simulator's tablet: every image scaled by a smooth function of its light (a stand-in
for gloss the Lambertian fit does not model), one image dimmed to 45 %.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np
import pytest
import tifffile
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.core.lp_format import read_lp
from rti_rig.reconstruct.synthetic import fibonacci_lights

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from fit_sessions import make_session

runner = CliRunner()
DIMMED = 5
#: a little more than a stop: at exactly one the ratio sits on the 0.5 limit (the real
#: acquisition's dimmed LEDs read 0.41-0.58 there: about half are named)
DIM = 0.45


def _glossy_session(root: Path, dim: int | None) -> Path:
    lights = fibonacci_lights(60)
    session, _, _ = make_session(root, lights=lights, size=(96, 112))
    for k, e in enumerate(read_lp(session / "lights.lp")):
        path = session / "linear" / (Path(e.name).stem + ".tif")
        px = tifffile.imread(path).astype(np.float64)
        # brighter towards the zenith by up to 1.8x, smooth in the light direction
        factor = 1.0 + 0.8 * e.direction[2] ** 4
        if k == dim:
            factor *= DIM
        tifffile.imwrite(path, np.clip(np.round(px * factor * 0.35), 0, 65535).astype(np.uint16))
    return session


def _qa(tmp_path: Path, session: Path) -> dict:
    out = tmp_path / (session.parent.name + "-fit")
    r = runner.invoke(app, ["fit", str(session), "--out", str(out), "--model", "ps"])
    assert r.exit_code == 0, r.output
    return json.loads((out / "qa.json").read_text())


@pytest.mark.slow
def test_a_dim_light_is_named_against_its_neighbours(tmp_path: Path) -> None:
    clean = _qa(tmp_path, _glossy_session(tmp_path / "clean" / "s", None))
    assert clean["verdict"].startswith("good"), clean["verdict"]
    dimmed = _qa(tmp_path, _glossy_session(tmp_path / "dim" / "s", DIMMED))
    image = dimmed["images"][DIMMED]
    # the absolute check alone cannot see it: its bright end is above the 0.6 limit
    assert image["bright_end_gain"] > 0.6
    assert image["neighbour_gain_ratio"] == pytest.approx(DIM, abs=0.05)
    verdict = dimmed["verdict"]
    assert verdict.startswith("reshoot: image_006 (misfired or dim light"), verdict
    assert "nearest lights" in verdict
    assert verdict.count("image_0") == 1, verdict  # no other image named
