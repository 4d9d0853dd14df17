"""`rti-rig run --auto-exposure` on the shipped emulated dome with uneven LEDs clips no image.

Metered at the one light nearest the zenith, 7 of its 48 images clipped 56–100 % (LEDs 36, 38,
39, 40, 42, 43 and 47 give more light than the metered LED 44): the exposure chosen there,
0.134 s, was too long for them. Checked at the 6 highest planned lights, LED 42 shortens it.
"""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest
import tifffile
from conftest import CONFIGS, REPO
from typer.testing import CliRunner

from rti_rig.cli import app

runner = CliRunner()
GUIDE = REPO / "docs" / "guide.md"


def _guide_metering_figures() -> tuple[str, str]:
    """The guide's section 4 sample "Exposure fixed at …" line up to its "(…)", and its quoted
    "Session time on the real rig: …" line up to "simulated in", which a reader compares with
    their own run of this dome (no test had read the sample: its figures had gone stale)."""
    text = GUIDE.read_text(encoding="utf-8")
    found = re.search(r"^## 4\. A DSLR\n(.*?)^## 5\.", text, re.S | re.M)
    assert found, "the guide's section 4 is gone"
    section = found.group(1)
    fixed = re.search(r"^(Exposure fixed at .*?) \(…\)$", section, re.M)
    time_line = re.search(r"`(Session time on the real rig: [^`]*?simulated in)", section, re.S)
    assert fixed and time_line, "the guide's metering sample is gone"
    return fixed.group(1), " ".join(time_line.group(1).split())


@pytest.mark.slow
@pytest.mark.pty
@pytest.mark.e2e
def test_auto_exposure_on_the_uneven_card_dome_clips_no_image(tmp_path: Path) -> None:
    out = tmp_path / "s"
    r = runner.invoke(
        app,
        [
            "run",
            str(CONFIGS / "emulated_dome_card.toml"),
            "--auto-exposure",
            "--out",
            str(out),
            "--no-verdict",
        ],
    )
    assert r.exit_code == 0, r.output
    m = json.loads((out / "manifest.json").read_text(encoding="utf-8"))
    chosen = m["schedule"]["provenance"]["exposure"]
    limit = chosen["rule"]["max_saturated_fraction"]
    # the images as written: none over the rule's limit (the controller's figure, and the TIFFs')
    assert len(m["steps"]) == 48
    over = [
        (s["image"], s["saturated_fraction"]) for s in m["steps"] if s["saturated_fraction"] > limit
    ]
    assert not over, over
    for s in m["steps"]:
        px = tifffile.imread(out / s["linear_image"])
        brightest = px.max(axis=-1) if px.ndim == 3 else px
        assert float(np.mean(brightest >= np.iinfo(px.dtype).max)) <= limit, s["linear_image"]
    # what it cost and where the exposure was set: said, and recorded
    assert len(chosen["lights_metered_at_steps"]) == 6
    assert chosen["metering_shots"] >= 6
    assert len(chosen["test_exposures_by_light_s"]) == 6
    assert {s["exposure_s"] for s in m["steps"]} == {chosen["exposure_s"]}
    said = " ".join(r.output.split())
    assert "Metering checks the 6 planned lights a level object receives most from" in said
    step = chosen["metered_at_step"]
    assert f"Exposure fixed at {chosen['exposure_s']:.4g} s at image_{step:03d}'s light" in said
    # the session's time on the real rig counts the metering's test shots (7, on the simulated
    # rig's clock: 8.4 s); it had said 57.2 s, the 48 images alone
    metering_s = chosen["rig_time_s"]
    assert metering_s > chosen["metering_shots"] * (0.3 + 0.7)  # readout + transfer a shot
    total = m["timing"]["rig_time_s"] + metering_s
    assert (
        f"Session time on the real rig: {total:.1f} s including {chosen['metering_shots']} "
        f"metering shots (metering {metering_s:.1f} s, simulated in "
    ) in said
    # the guide's sample of this very run (section 4) shows what it printed
    fixed, time_line = _guide_metering_figures()
    assert fixed in said, (fixed, said)
    # its time line: the same shots (the seconds are not compared: the emulated link's real
    # reply times are added to the rig's clock, so they grow with the machine's load)
    shots = re.search(r"including (\d+) metering shots", time_line)
    assert shots and f"including {shots.group(1)} metering shots (metering " in said, time_line
