"""Dome serial settings: validation with messages that say what to fix; the example `.lp`."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest
from conftest import at_key
from pydantic import ValidationError

from rti_rig.app.dome_factory import policy_settings
from rti_rig.drivers.led_dome import DomeSerialSettings, make_codec
from rti_rig.drivers.led_dome.codec_binary import BinaryCodec
from rti_rig.drivers.led_dome.codec_default import DefaultCodec
from rti_rig.drivers.led_dome.codec_framed import FramedCodec
from rti_rig.drivers.led_dome.messages import AllOff

REPO = Path(__file__).resolve().parents[3]


def errors_of(**fields):
    with pytest.raises(ValidationError) as info:
        DomeSerialSettings.model_validate(fields)
    return [(".".join(str(p) for p in e["loc"]), e["msg"]) for e in info.value.errors()]


def test_minimal_settings_and_defaults():
    s = DomeSerialSettings(port="/dev/ttyACM0")
    assert (s.profile, s.baudrate, s.retries) == ("default", 115200, 2)
    assert isinstance(make_codec(s), DefaultCodec)
    p = policy_settings(s)
    assert p.thermal.max_on_s == 10.0 and p.intensity_correction is None


def test_each_profile_builds_its_codec():
    assert isinstance(make_codec(DomeSerialSettings(port="x", profile="framed")), FramedCodec)
    codec = make_codec(DomeSerialSettings(port="x", profile="binary", binary={"start_byte": 0x55}))
    assert isinstance(codec, BinaryCodec) and codec.start_byte == 0x55
    codec = make_codec(DomeSerialSettings(port="x", default={"checksum": False}))
    assert codec.encode_command(1, AllOff()) == b"1 X\n"


@pytest.mark.parametrize(
    ("fields", "loc", "fragment"),
    [
        ({}, "port", "Field required"),
        ({"port": "x", "profile": "modbus"}, "profile", "'default', 'framed' or 'binary'"),
        ({"port": "x", "baudrate": 0}, "baudrate", "greater than 0"),
        ({"port": "x", "reply_timeout_s": 0}, "reply_timeout_s", "greater than 0"),
        ({"port": "x", "retries": 11}, "retries", "less than or equal to 10"),
        ({"port": "x", "colour": "red"}, "colour", "Extra inputs are not permitted"),
        ({"port": "x", "framed": {}}, "", "options for the 'framed' profile are given"),
        (
            {"port": "x", "intensity_correction": [1.0, 1.2]},
            "intensity_correction",
            "factor for LED 1 is 1.2",
        ),
        (
            {"port": "x", "thermal": {"max_on_s": 40, "max_duty": 0.5, "duty_window_s": 60}},
            "thermal",
            "a single lighting would break the duty",
        ),
        (
            {"port": "x", "profile": "framed", "framed": {"start": "<", "end": "<"}},
            "framed",
            "must differ",
        ),
        (
            {"port": "x", "profile": "framed", "framed": {"codes": {"light": "0"}}},
            "framed.codes",
            "command codes must differ",
        ),
        ({"port": "x", "profile": "binary", "max_level": 1023}, "", "max_level ≤ 255"),
        (
            {"port": "x", "profile": "framed", "framed": {"codes": {"light": "L,1"}}},
            "framed",
            "command code light = 'L,1' contains the separator character",
        ),
        (
            {"port": "x", "expected_led_count": 3, "intensity_correction": [1, 1]},
            "",
            "2 factors for expected_led_count = 3",
        ),
    ],
)
def test_invalid_settings_name_the_key_and_the_fix(fields, loc, fragment):
    errs = errors_of(**fields)
    assert any(e_loc == loc and fragment in msg for e_loc, msg in errs), errs


def test_check_led_count_against_the_lp():
    s = DomeSerialSettings(port="x", intensity_correction=[1.0] * 48)
    assert s.check_led_count(48) is None
    assert "48 factors for 47 LEDs" in s.check_led_count(47)


LP_LINE = re.compile(r"^(led_\d{2}\.jpg) (-?0\.\d{6}) (-?0\.\d{6}) (-?0\.\d{6})$")


def test_example_dome_lp_is_a_safe_profile_48_led_hemisphere():
    text = (REPO / "rig_configs" / "example_dome_48.lp").read_text(encoding="ascii")
    assert "\r" not in text and text.endswith("\n")
    lines = text.splitlines()
    assert lines[0] == "48" and len(lines) == 49
    names, dirs = [], []
    for line in lines[1:]:
        m = LP_LINE.match(line)
        assert m, line
        names.append(m.group(1))
        dirs.append([float(m.group(i)) for i in (2, 3, 4)])
    assert names == sorted(names) == [f"led_{i:02d}.jpg" for i in range(48)]
    d = np.array(dirs)
    assert np.allclose(np.linalg.norm(d, axis=1), 1.0, atol=2e-6)
    elevation = np.degrees(np.arcsin(d[:, 2]))
    assert elevation.min() > 8 and elevation.max() < 72  # a hemisphere above the object plane
    # five rings, 12-12-10-8-6 LEDs, in line order
    ring_of = np.digitize(elevation, [17.5, 32.5, 47.5, 62.5])
    assert np.bincount(ring_of).tolist() == [12, 12, 10, 8, 6]
    assert (np.diff(ring_of) >= 0).all()


def test_another_profiles_options_name_the_table_they_are_in(tmp_path: Path) -> None:
    """The example config copied and set to a firmware's profile (as `rti-rig probe` prints it)
    keeps its [dome.serial.framed] table: the refusal told the user to remove "[dome.framed]",
    a table that is not in the file (and one the loader refuses as an unknown key)."""
    import shutil

    from typer.testing import CliRunner

    from rti_rig.cli import app

    configs = REPO / "rig_configs"
    shutil.copy(configs / "example_dome_48.lp", tmp_path)
    text = (configs / "example_dome_48.toml").read_text()
    cfg = tmp_path / "my_dome.toml"
    cfg.write_text(text.replace('profile = "framed"', 'profile = "minirti"'))
    r = CliRunner().invoke(app, ["check", str(cfg)])
    said = " ".join(r.output.split())
    assert r.exit_code == 2, said
    assert at_key(cfg, "dome.serial") in said and ", line " in at_key(cfg, "dome.serial"), said
    assert "remove [dome.serial.framed] or set profile = 'framed'" in said, said
