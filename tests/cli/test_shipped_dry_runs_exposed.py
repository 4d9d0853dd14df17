"""Every shipped simulated or emulated rig config gives a session with no image clipped past the
QA's limit, at the config's own exposure, through the front door (`rti-rig run CONFIG`).

A first-time user's dry run should show what a good session looks like. emulated_dome.toml
shot the polished coin at 0.05 s: six of its 48 images clipped 4-7 % of their pixels and the
verdict said "reshoot"; so did the six firmware emulators' configs, which shot the coin at 48 px
and clipped 18-31 % (the glint is a large part of so small a frame). They all shoot the matte
tablet now; the coin stays in the scene library for the exposure docs and tests that want gloss.
"""

from __future__ import annotations

import json
import tomllib
from pathlib import Path

import numpy as np
import pytest
import tifffile
from conftest import CONFIGS
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.reconstruct.qa import SATURATED_LIMIT

runner = CliRunner()

#: the firmware emulators' configs, each a dry run a user starts from (docs/domes.md)
FIRMWARE_EMULATORS = {
    "emulated_elexol.toml",
    "emulated_minirti.toml",
    "emulated_nab_rti_v1.toml",
    "emulated_nichlock.toml",
    "emulated_rti_dome.toml",
    "emulated_rtipy.toml",
}


def _dry_run_configs() -> list:  # type: ignore[type-arg]
    params = []
    for path in sorted(CONFIGS.glob("*.toml")):
        backend = tomllib.loads(path.read_text(encoding="utf-8")).get("backend")
        if backend not in ("simulated", "emulated"):
            continue
        marks = [pytest.mark.pty] if backend == "emulated" else []
        params.append(pytest.param(path.name, marks=marks, id=path.stem))
    return params


def test_the_shipped_dry_run_configs_are_all_checked() -> None:
    names = {p.values[0] for p in _dry_run_configs()}
    assert {"simulated_dome.toml", "emulated_dome.toml", "simulated_arm.toml"} <= names
    assert names >= FIRMWARE_EMULATORS


@pytest.mark.parametrize("config", _dry_run_configs())
def test_a_shipped_dry_run_clips_no_image_past_the_qa_limit(config: str, tmp_path: Path) -> None:
    out = tmp_path / "s"
    r = runner.invoke(app, ["run", str(CONFIGS / config), "--out", str(out), "--no-verdict"])
    assert r.exit_code == 0, r.output
    steps = json.loads((out / "manifest.json").read_text(encoding="utf-8"))["steps"]
    clipped = {s["image"]: s["saturated_fraction"] for s in steps}
    worst = max(clipped, key=clipped.__getitem__)
    # half the QA's limit: a margin for a seed or a renderer detail, still "well exposed"
    assert clipped[worst] < SATURATED_LIMIT / 2, (worst, clipped[worst])
    # and not made safe by being dark: the brightest image's highlights reach a tenth of white
    top = max(np.percentile(tifffile.imread(out / s["linear_image"]), 99) for s in steps)
    assert top > 0.1 * 65535, top
