"""The lamps' geometry a rig gives the adaptive stop (``[lamps]`` on hardware, the scene on a
simulated or emulated rig) and the refusals that keep the two apart."""

from __future__ import annotations

from pathlib import Path

import pytest

from rti_rig.app.compose import lamp_geometry
from rti_rig.app.config import load_rig_config
from rti_rig.core.errors import ConfigError
from rti_rig.core.rig_geometry import LampGeometry

CONFIGS = Path(__file__).resolve().parents[2] / "rig_configs"
LAMPS = "\n[lamps]\ndistance_mm = 350.0\nfield_width_mm = 90.0\n"


def _with(tmp_path: Path, name: str, extra: str) -> Path:
    """A shipped config copied beside its files (a dome's .lp) with ``extra`` appended."""
    src = CONFIGS / name
    for beside in CONFIGS.glob(src.stem + ".*"):
        (tmp_path / beside.name).write_bytes(beside.read_bytes())
    path = tmp_path / name
    path.write_text(src.read_text(encoding="utf-8") + extra, encoding="utf-8")
    return path


def test_a_hardware_dome_gives_what_its_config_states(tmp_path: Path) -> None:
    loaded = load_rig_config(_with(tmp_path, "example_dome_48.toml", LAMPS))
    assert lamp_geometry(loaded) == LampGeometry(350.0, 90.0)
    assert lamp_geometry(load_rig_config(CONFIGS / "example_dome_48.toml")) is None


@pytest.mark.parametrize(
    ("name", "expected"),
    [
        ("simulated_arm.toml", LampGeometry(400.0, 12.8)),  # tablet, 256 px at 0.05 mm
        ("emulated_dome.toml", LampGeometry(400.0, 12.8)),
        ("simulated_dome.toml", None),  # the relief: directional lights
    ],
)
def test_a_simulated_rig_gives_its_scenes_lamps(name: str, expected: LampGeometry | None) -> None:
    assert lamp_geometry(load_rig_config(CONFIGS / name)) == expected


def test_lamps_on_a_simulated_rig_are_refused(tmp_path: Path) -> None:
    with pytest.raises(ConfigError) as err:
        load_rig_config(_with(tmp_path, "simulated_arm.toml", LAMPS))
    text = str(err.value)
    assert "simulated_arm.toml" in text and "[lamps]" in text, text
    assert "light_distance_mm" in text and "remove the [lamps] table" in text, text


@pytest.mark.parametrize(
    ("table", "key"),
    [
        ("distance_mm = 0.0\nfield_width_mm = 90.0\n", "distance_mm"),
        ("distance_mm = 350.0\n", "field_width_mm"),
    ],
)
def test_a_bad_lamps_table_is_refused_naming_the_key(tmp_path: Path, table: str, key: str) -> None:
    with pytest.raises(ConfigError) as err:
        load_rig_config(_with(tmp_path, "example_dome_48.toml", "\n[lamps]\n" + table))
    text = str(err.value)
    assert "lamps" in text and key in text, text


def test_a_lamp_geometry_is_positive() -> None:
    with pytest.raises(ValueError, match="must both be > 0"):
        LampGeometry(0.0, 10.0)
