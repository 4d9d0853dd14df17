"""A faulty LED of an uneven dome is named as a faulty LED, not as a move part-way through.

Found on the shipped emulated Nab dome with 24 lights from 3.2° up (``count`` and
``led_count`` 24, ``min_elevation_deg = 2``) over the flat plate, its LEDs uneven (the
emulator's draws for ``led_power_spread = 0.2``, seed 0) and LED 10 at 30 % of its own: the
verdict named image_011 "misfired or dim" and also "object or camera moved from image_022 on"
(the simulator never moves the object). The edges' step at image_022 was claimed on the
edges' word alone because the fit explained those images poorly (0.109 of residual, as
captured and undone alike): poorly by the lights' strengths, not by the object. With each
image levelled by its gain against the fit the plate is explained (0.0026) and the step is
refused. A real (2, 0) px move from image_013 of the same dome over the tablet, the same
faulty LED, is still named from image_013 (measured over seeds 0-9 in docs/reconstruction.md,
"A move part-way through").
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from conftest import moved_session_copy, qa_of, shipped_variant
from typer.testing import CliRunner

from rti_rig.cli import app

runner = CliRunner()


def _session(folder: Path, scene: str) -> Path:
    """A session of the shipped emulated Nab dome, 24 lights from 3.2° up, seed 0, on
    ``scene``, its LEDs drawn as ``led_power_spread = 0.2`` draws them and LED 10 at 30 %."""
    power = np.exp(0.2 * np.random.default_rng([0, 0x1ED]).standard_normal(24))
    power[10] *= 0.3
    listed = ", ".join(f"{p:.6f}" for p in power)
    edits = (
        ('\nname = "tablet"\n', f'\nname = "{scene}"\n'),
        ("count = 12\n", "count = 24\n"),
        ("led_count = 12 ", "led_count = 24 "),
        ("min_elevation_deg = 15.0", "min_elevation_deg = 2"),
    )
    config = shipped_variant(folder, "emulated_nab_rti_v1.toml", edits, f"led_power = [{listed}]\n")
    out = folder / "s"
    r = runner.invoke(
        app, ["run", str(config), "--out", str(out), "--lights", "24", "--no-verdict"]
    )
    assert r.exit_code == 0, r.output
    return out


def _named(qa: dict) -> dict[str, list[str]]:  # type: ignore[type-arg]
    return {c["name"]: c["problems"] for c in qa["images"] if c["problems"]}


def test_a_dim_led_of_an_uneven_dome_is_named_and_no_move_claimed(tmp_path: Path) -> None:
    said, qa = qa_of(_session(tmp_path, "flat"), tmp_path / "f")
    named = _named(qa)
    assert "misfired or dim" in named.get("image_011", [""])[0], qa["verdict"]
    assert "moved" not in said, said
    assert set(named) == {"image_011"}, named


def test_a_real_move_under_that_dim_led_is_still_named(tmp_path: Path) -> None:
    moved = moved_session_copy(_session(tmp_path, "tablet"), tmp_path / "moved", 13, 2, 0)
    said, qa = qa_of(moved, tmp_path / "f")
    assert "object or camera moved from image_013 on" in said, said
    named = _named(qa)
    assert "misfired or dim" in named.get("image_011", [""])[0], qa["verdict"]
    called = sorted(n for n, p in named.items() if any("moved" in x for x in p))
    assert called == [f"image_{i:03d}" for i in range(13, 25)], called
