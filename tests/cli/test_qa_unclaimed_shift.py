"""The QA verdict does not judge an image's brightness on a copy moved by a shift it does not
claim (rti_rig.reconstruct.qa.assess).

Found walking docs/guide.md section 2: `rti-rig run rig_configs/emulated_dome.toml
--auto-exposure` (the coin, metered for its glint) ended with "reshoot: ... image_043
(misfired or dim light: 0% of the brightness of the images of its 4 nearest lights ...),
image_046 (... 0% ...)" although every LED fired and those two were among the session's
brightest images. Against a fit that explains the coin poorly, the shift against the fit was
113-125 px; the verdict rightly did not claim it ("shift not judged"), but the images had
already been moved back by it, and the warp's black fill gave them a median gain of 0.
"""

from __future__ import annotations

from pathlib import Path

from conftest import coin_dome, said
from typer.testing import CliRunner

from rti_rig.cli import app

REPO = Path(__file__).resolve().parents[2]
runner = CliRunner()


def test_the_metered_coin_has_no_image_called_dim_by_an_unclaimed_shift(tmp_path: Path) -> None:
    config = coin_dome(tmp_path)
    r = runner.invoke(app, ["run", str(config), "--out", str(tmp_path / "s"), "--auto-exposure"])
    assert r.exit_code == 0, r.output
    text = said(r)
    verdict = text[text.index("QA verdict:") :]
    assert "shift not judged" in verdict, verdict  # the shift is still not claimed
    assert "misfired" not in verdict and "0% of the brightness" not in verdict, verdict
    assert verdict.startswith("QA verdict: good"), verdict
