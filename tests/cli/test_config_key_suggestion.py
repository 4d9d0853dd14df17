"""A misspelled key of a rig config is told the key of its table it is closest to.

Before: "unknown key (check its spelling and the table it is in)", and the user read the docs
to find that ``exposur_s`` stands for ``exposure_s``. Each table is checked against its own
keys: the config's, a list of tables' (``dome.rings``), a driver's (``[dome.serial]``,
``[dome.serial.protocol]``, ``[camera.device]``).
"""

from __future__ import annotations

from pathlib import Path

import pytest
from conftest import CONFIGS, said
from typer.testing import CliRunner

from rti_rig.cli import app


def _misspelled(tmp_path: Path, shipped: str, old: str, new: str) -> Path:
    text = (CONFIGS / shipped).read_text()
    assert text.count(old) == 1, old
    path = tmp_path / shipped
    path.write_text(text.replace(old, new))
    for lp in CONFIGS.glob("*.lp"):  # what a config names beside it
        (tmp_path / lp.name).write_bytes(lp.read_bytes())
    return path


@pytest.mark.parametrize(
    ("shipped", "old", "new", "key", "meant"),
    [
        ("simulated_dome.toml", "\nexposure_s", "\nexposur_s", "camera.exposur_s", "exposure_s"),
        ("simulated_dome.toml", "[timing]", "[timming]", "timming", "timing"),
        (
            "simulated_dome.toml",
            "count = 12, azimuth_offset_deg = 0.0",
            "count = 12, azimuth_ofset_deg = 0.0",
            "dome.rings[0].azimuth_ofset_deg",
            "azimuth_offset_deg",
        ),
        ("emulated_dome.toml", "\nbaudrate", "\nbauddrate", "dome.serial.bauddrate", "baudrate"),
        (
            "emulated_elexol.toml",
            "\nled_count = 12",
            "\nled_cont = 12",
            "dome.serial.protocol.led_cont",
            "led_count",
        ),
        (
            "example_dome_48.toml",
            '\nimage_format = "RAW"',
            '\nimag_format = "RAW"',
            "camera.device.imag_format",
            "image_format",
        ),
    ],
)
def test_a_misspelled_key_is_told_the_key_it_stands_for(
    tmp_path: Path, shipped: str, old: str, new: str, key: str, meant: str
) -> None:
    config = _misspelled(tmp_path, shipped, old, new)
    out = tmp_path / "s"
    r = CliRunner().invoke(app, ["run", str(config), "--out", str(out), "--no-verdict"])
    assert r.exit_code == 2, said(r)
    assert f"key '{key}': unknown key" in said(r), said(r)
    assert f"did you mean '{meant}'?" in said(r), said(r)
    assert "Traceback" not in r.output and not out.exists()


def test_a_key_like_none_is_told_no_guess(tmp_path: Path) -> None:
    config = _misspelled(tmp_path, "simulated_dome.toml", "\nexposure_s", "\nzzz = 1\nexposure_s")
    r = CliRunner().invoke(app, ["run", str(config), "--out", str(tmp_path / "s")])
    assert r.exit_code == 2, said(r)
    assert "key 'camera.zzz': unknown key (check its spelling" in said(r), said(r)
    assert "did you mean" not in said(r)


@pytest.mark.parametrize(
    ("shipped", "old", "new", "key", "table"),
    [
        # a RAW decode key under the camera: it had been asked "did you mean
        # 'shutter_tolerance'?" (the closest spelling of its own table)
        (
            "example_dome_48.toml",
            '\niso = "100"',
            '\niso = "100"\nwhite_balance = "camera"',
            "camera.device.white_balance",
            "camera.device.decode",
        ),
        (
            "simulated_dome.toml",
            "\nseed = 0",
            "\nseed = 0\nexposure_s = 0.05",
            "scene.exposure_s",
            "camera",
        ),
    ],
)
def test_a_key_of_another_table_is_told_where_it_belongs(
    tmp_path: Path, shipped: str, old: str, new: str, key: str, table: str
) -> None:
    config = _misspelled(tmp_path, shipped, old, new)
    r = CliRunner().invoke(app, ["check", str(config)])
    assert r.exit_code == 2, said(r)
    name = key.rsplit(".", 1)[1]
    assert (
        f"key '{key}': unknown key in this table; '{name}' is a key of [{table}]: did you mean "
        "to put it there?"
    ) in said(r), said(r)
    assert "did you mean '" not in said(r) and "Traceback" not in r.output
