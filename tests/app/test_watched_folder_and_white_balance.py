"""A watched-folder camera's relative ``folder`` is read relative to its config, and raw white
balance multipliers must each be above 0.

Before: ``folder = "t_rel"`` was read relative to where the command was typed (``check``
passed from the config's folder and failed from another; a resume typed elsewhere would have
watched another folder); ``white_balance = [-1, 1, 1, 1]`` was taken, the red channel then
recorded as a constant in silence, and ``[0, 0, 0, 0]`` made every image black.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from rti_rig.app.config import camera_device_settings, load_rig_config
from rti_rig.core.errors import ConfigError

CONFIGS = Path(__file__).resolve().parents[2] / "rig_configs"
SHIPPED = CONFIGS / "example_dome_48_folder_watch.toml"
DECODE = '[camera.device.decode]\nmode = "demosaic"'


def _config(tmp_path: Path, old: str, new: str) -> Path:
    text = SHIPPED.read_text(encoding="utf-8")
    assert old in text
    (tmp_path / "example_dome_48.lp").write_bytes((CONFIGS / "example_dome_48.lp").read_bytes())
    path = tmp_path / "rig.toml"
    path.write_text(text.replace(old, new), encoding="utf-8")
    return path


def _folder(config: Path) -> Path:
    return camera_device_settings(load_rig_config(config)).folder


def test_a_relative_watched_folder_is_the_configs_wherever_the_command_is_typed(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    config = _config(tmp_path, 'folder = "~/Pictures/rti-tether"', 'folder = "t_rel"')
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    for cwd in (tmp_path, elsewhere):
        monkeypatch.chdir(cwd)
        assert _folder(config) == (tmp_path / "t_rel").resolve()
    # typed elsewhere, the folder it reads is said (the rule was the working folder's)
    notes = " ".join(load_rig_config(config).notes)
    assert "is read relative to the rig config's folder" in notes, notes
    monkeypatch.chdir(tmp_path)
    assert not load_rig_config(config).notes  # the same folder either way: nothing to say
    # a home folder stays the user's, as the shipped config writes it
    assert _folder(SHIPPED) == Path("~/Pictures/rti-tether").expanduser()


@pytest.mark.parametrize(
    "multipliers", ["[-1, 1, 1, 1]", "[0, 0, 0, 0]", "[2, 1, nan, 1]", '"daylight"', "[2, 1, 1]"]
)
def test_white_balance_multipliers_at_or_below_zero_are_refused_by_key(
    tmp_path: Path, multipliers: str
) -> None:
    config = _config(tmp_path, DECODE, f"{DECODE}\nwhite_balance = {multipliers}")
    with pytest.raises(ConfigError) as info:
        camera_device_settings(load_rig_config(config))
    said = str(info.value)
    assert "key 'camera.device.decode.white_balance':" in said and "each above 0" in said, said


def test_a_dome_fired_camera_on_a_firmware_without_shutter_is_refused_by_key(
    tmp_path: Path,
) -> None:
    """``trigger = "dome_shutter"`` on minirti (no shutter command): ``check`` had passed, and
    ``run`` stopped at its first image, the dome lit. The same table on rti-rig's own
    protocol (which has one) loads."""
    text = (CONFIGS / "emulated_minirti.toml").read_text(encoding="utf-8")
    assert 'backend = "emulated"' in text and "\n[scene]" in text
    text = text.replace('backend = "emulated"', 'backend = "hardware"')
    text = text.replace('port = "emulated"', 'port = "/dev/ttyUSB0"').split("\n[scene]")[0]
    text += f'\n[camera.device]\nkind = "folder_watch"\nfolder = "{tmp_path}"\n'
    text += 'trigger = "dome_shutter"\n'
    path = tmp_path / "minirti.toml"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(ConfigError) as info:
        load_rig_config(path)
    assert info.value.key == "camera.device.trigger", str(info.value)
    assert "profile 'minirti' has none" in str(info.value)
    framed = _config(tmp_path, 'folder = "~/Pictures/rti-tether"', f'folder = "{tmp_path}"')
    assert 'trigger = "dome_shutter"' in framed.read_text()
    load_rig_config(framed)  # the shipped DSLR-by-shutter example: its firmware has one


@pytest.mark.parametrize("patterns", ["[]", '[""]'])
def test_a_watched_folder_without_patterns_is_refused_by_key(tmp_path: Path, patterns: str) -> None:
    """``patterns = []`` was taken, and the run waited out its timeout, the dome lit."""
    text = SHIPPED.read_text(encoding="utf-8")
    old = next(line for line in text.splitlines() if line.startswith("patterns = "))
    config = _config(tmp_path, old, f"patterns = {patterns}")
    with pytest.raises(ConfigError) as info:
        camera_device_settings(load_rig_config(config))
    assert "key 'camera.device.patterns':" in str(info.value), str(info.value)


def test_a_key_of_another_camera_kind_is_said_so_not_called_a_typo(tmp_path: Path) -> None:
    """``decode`` under an ``opencv`` camera was told "unknown key …; did you mean 'device'?"."""
    config = _config(tmp_path, 'kind = "folder_watch"', 'kind = "opencv"\ndevice = 0')
    with pytest.raises(ConfigError) as info:
        camera_device_settings(load_rig_config(config))
    said = str(info.value)
    assert "is a key of a" in said and "camera, and this one is kind 'opencv'" in said, said
    assert "did you mean" not in said, said


def test_a_camera_without_kind_is_told_to_add_it(tmp_path: Path) -> None:
    config = _config(tmp_path, 'kind = "folder_watch"\n', "")
    with pytest.raises(ConfigError) as info:
        camera_device_settings(load_rig_config(config))
    said = str(info.value)
    assert "key 'camera.device.kind': required, and not given: add a line kind = …" in said, said
