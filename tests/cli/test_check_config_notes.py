"""`rti-rig check` says what loading the rig config tolerated, as `run` and `plan` do.

Found by a front-door audit: a dome whose calibration `.lp` has a light a hair below the
horizon (clamped to z = 0) and a count line that disagrees with its lines was checked with
"RESULT: PASS" and not a word of either, while `run` and `plan` of the same config printed both
notes. The check is the step before a dome's first session: it is where a user should hear it.
"""

from __future__ import annotations

import shutil
from pathlib import Path

from conftest import CONFIGS
from typer.testing import CliRunner

from rti_rig.app.config import dome_led_directions, load_rig_config
from rti_rig.cli import app

runner = CliRunner()


def _bare(text: str) -> str:
    """``text`` without whitespace: the console wraps a long path mid-word."""
    return "".join(text.split())


def _check_text(config: Path) -> str:
    r = runner.invoke(app, ["check", str(config)])
    assert r.exit_code == 0, r.output
    assert "Traceback" not in r.output
    return _bare(r.output)


def test_check_of_a_dome_names_the_mended_lines_of_its_calibration_lp(tmp_path: Path) -> None:
    config = tmp_path / "emulated_dome.toml"
    shutil.copy(CONFIGS / "emulated_dome.toml", config)
    lines = (CONFIGS / "example_dome_48.lp").read_text().splitlines()
    name, x, y, _ = lines[5].split()
    lines[5] = f"{name} {x} {y} -0.001"  # LED 4, at the horizon: calibration noise
    lines[0] = str(int(lines[0]) - 1)  # the count line disagrees with the 48 lines
    (tmp_path / "example_dome_48.lp").write_text("\n".join(lines) + "\n")

    text = _check_text(config)
    assert _bare("RESULT: PASS") in text
    lp = tmp_path / "example_dome_48.lp"
    assert _bare(f"note: {lp}, line 6: light z = -0.0010") in text and "clampedtoz=0" in text
    assert _bare(f"note: {lp}, line 1: count line says 47 lights but the file lists 48") in text


def test_check_of_a_camera_triggered_dome_names_them_too(tmp_path: Path) -> None:
    shipped = CONFIGS / "emulated_cceh_rti.toml"
    dirs, _ = dome_led_directions(load_rig_config(shipped))
    body = [f"led_{i:02d}.jpg {d[0]:.6f} {d[1]:.6f} {d[2]:.6f}" for i, d in enumerate(dirs)]
    (tmp_path / "flash_order.lp").write_text("\n".join([str(len(body) + 1), *body]) + "\n")
    text = shipped.read_text()
    start, end = text.index("[dome]"), text.index("[dome.flash_sync]")
    config = tmp_path / "cceh.toml"
    config.write_text(
        text[:start] + '[dome]\nlayout = "lp"\nlp_file = "flash_order.lp"\n\n' + text[end:]
    )

    out = _check_text(config)
    assert _bare("RESULT: PASS") in out
    assert _bare(f"note: {tmp_path / 'flash_order.lp'}, line 1: count line says 61 lights") in out
