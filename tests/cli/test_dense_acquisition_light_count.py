"""A dense acquisition (more lights than an `.lp` may list for relight) replayed or given as a
plan without ``--lights``: refused naming where the count came from and what to do."""

from __future__ import annotations

import math
import os
from pathlib import Path

from conftest import CONFIGS, said
from typer.testing import CliRunner

from rti_rig.cli import app

REPLAY = Path(__file__).resolve().parents[1] / "data" / "neuralrti_replay"


def _dense_lp(folder: Path, n: int, with_images: bool) -> Path:
    """``n`` lights on a spiral over the hemisphere, named ``img_0001.jpg`` ...; with their
    images (hard links to the real acquisition's 18 JPEGs, in turn) where asked."""
    folder.mkdir()
    sources = sorted(REPLAY.glob("*.jpg"))
    lines = [str(n)]
    for i in range(n):
        z = 0.05 + 0.9 * i / n
        r = math.sqrt(1 - z * z)
        name = f"img_{i + 1:04d}.jpg"
        lines.append(f"{name} {r * math.cos(i * 2.4):.6f} {r * math.sin(i * 2.4):.6f} {z:.6f}")
        if with_images:
            os.link(sources[i % len(sources)], folder / name)
    lp = folder / "dense.lp"
    lp.write_text("\n".join(lines) + "\n")
    return lp


def test_a_dense_acquisition_replayed_without_lights_says_so_and_what_to_do(
    tmp_path: Path,
) -> None:
    lp = _dense_lp(tmp_path / "acq", 1001, with_images=True)
    out = tmp_path / "s"
    r = CliRunner().invoke(app, ["run", str(lp), "--out", str(out)])
    assert r.exit_code != 0
    text = said(r)
    # the count is the acquisition's, not an option the user never gave
    assert "--lights 1001" not in text, text
    assert f"1001 lights (every image of the acquisition {lp})" in text, text
    assert "at most 1000 lights per session" in text, text
    assert "give --lights with a count of at most 1000" in text, text
    assert "(e.g. --lights 1000)" in text, text
    assert not out.exists()
    # and the way out it names works
    r = CliRunner().invoke(
        app, ["run", str(lp), "--out", str(out), "--lights", "6", "--no-verdict"]
    )
    assert r.exit_code == 0, r.output
    assert (out / "lights.lp").read_text().splitlines()[0] == "6"


def test_a_plan_longer_than_an_lp_may_be_is_named_as_the_plan(tmp_path: Path) -> None:
    plan = _dense_lp(tmp_path / "plan", 1001, with_images=False)
    out = tmp_path / "s"
    config = CONFIGS / "simulated_dome.toml"
    r = CliRunner().invoke(app, ["run", str(config), "--plan", str(plan), "--out", str(out)])
    assert r.exit_code != 0
    text = said(r)
    assert "--lights 1001" not in text, text
    assert f"--plan {plan} lists 1001 lights: at most 1000 lights per session" in text, text
    assert "split it into plans of at most 1000 lights" in text, text
    assert not out.exists()


def test_too_many_lights_asked_with_the_option_still_names_it(tmp_path: Path) -> None:
    out = tmp_path / "s"
    config = CONFIGS / "simulated_dome.toml"
    r = CliRunner().invoke(app, ["run", str(config), "--lights", "1001", "--out", str(out)])
    assert r.exit_code != 0
    assert "--lights 1001: at most 1000 lights per session" in said(r)
