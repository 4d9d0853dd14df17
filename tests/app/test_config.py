"""Rig configs: shipped ones load; bad ones name the file, the key and what is wrong."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from conftest import REPO, SMALL_DOME, write_config

from rti_rig.app.config import default_config_path, load_rig_config, rig_geometry
from rti_rig.core.errors import ConfigError
from rti_rig.core.rig_geometry import ArmGeometry, DomeGeometry


def test_shipped_configs_load(dome_config_path: Path, arm_config_path: Path) -> None:
    dome = load_rig_config(dome_config_path)
    g = rig_geometry(dome)
    assert isinstance(g, DomeGeometry) and g.count == 48
    assert np.all(g.directions[:, 2] > 0)
    arm = rig_geometry(load_rig_config(arm_config_path))
    assert isinstance(arm, ArmGeometry)
    assert default_config_path().name == "simulated_dome.toml"
    assert default_config_path().exists()


@pytest.mark.parametrize(
    ("edit", "key", "fragment"),
    [
        (
            ("count = 8", "count = -8"),
            "dome.rings[0].count",
            "must be more than 0 and at most 1000 (got -8)",
        ),
        (("count = 8", "cuont = 8"), "dome.rings[0].count", "'dome.rings[0].cuont': unknown key"),
        (('kind = "dome"', 'kind = "cupola"'), "kind", "'dome' or 'arm'"),
        (('backend = "simulated"', 'backend = "usb"'), "backend", "simulated"),
        (("exposure_s = 0.05", "exposure_s = 100.0"), "camera.exposure_s", "outside"),
        (("width = 64", 'width = "wide"'), "camera.width", "integer"),
        (('layout = "rings"', 'layout = "lp"'), "dome", "needs key 'lp_file'"),
        # a key another layout reads is refused, not ignored (an lp_file naming no file passed)
        (
            ('layout = "rings"', 'layout = "rings"\nlp_file = "nosuch.lp"'),
            "dome",
            "lp_file (read only with layout = 'lp') would be ignored",
        ),
        (
            ('layout = "rings"', 'layout = "rings"\ncount = 12'),
            "dome",
            "count (read only with layout = 'fibonacci') would be ignored",
        ),
        (("seed = 3", "seed = -1"), "scene.seed", "must be at least 0 (got -1)"),
        (
            ("seed = 3", "seed = 3\n[timing]\nsettle_s = 1e6"),
            "timing.settle_s",
            "must be at least 0 and at most 600 (got 1000000.0)",
        ),
        # a check of the whole [camera] table blames the key, not the table's line
        (
            ("exposure_s = 0.05", "exposure_s = 0.05\nmin_exposure_s = 40.0"),
            "camera.min_exposure_s",
            "40 is above max_exposure_s 30: the limits are the wrong way round",
        ),
        (
            ("exposure_s = 0.05", "exposure_s = 1e9"),
            "camera.exposure_s",
            "1e+09 s is outside min_exposure_s 0.0001 to max_exposure_s 30",
        ),
    ],
)
def test_bad_values_name_file_and_key(
    tmp_path: Path, edit: tuple[str, str], key: str, fragment: str
) -> None:
    old, new = edit
    assert old in SMALL_DOME
    path = write_config(tmp_path, SMALL_DOME.replace(old, new, 1))
    with pytest.raises(ConfigError) as info:
        load_rig_config(path)
    assert info.value.key == key
    assert fragment in info.value.message
    assert str(path) in str(info.value)


def test_a_table_the_kind_does_not_read_is_refused(tmp_path: Path) -> None:
    with pytest.raises(ConfigError, match=r"kind 'dome' reads no \[arm\] table"):
        load_rig_config(write_config(tmp_path, SMALL_DOME + "[arm]\n"))
    arm = (REPO / "rig_configs" / "virtual_arm.toml").read_text()
    with pytest.raises(ConfigError, match=r"kind 'arm' reads no \[dome\] table"):
        load_rig_config(write_config(tmp_path, arm + '\n[dome]\nlayout = "fibonacci"\ncount = 8\n'))


def test_missing_table_and_bad_toml(tmp_path: Path) -> None:
    no_dome = SMALL_DOME.split("[dome]")[0]
    with pytest.raises(ConfigError, match=r"needs a \[dome\] table"):
        load_rig_config(write_config(tmp_path, no_dome))
    with pytest.raises(ConfigError, match="not valid TOML"):
        load_rig_config(write_config(tmp_path, "name = \n", "broken.toml"))
    with pytest.raises(ConfigError, match="cannot read"):
        load_rig_config(tmp_path / "nope.toml")


def test_lp_layout_resolves_relative_to_config(tmp_path: Path) -> None:
    (tmp_path / "domes").mkdir()
    (tmp_path / "domes" / "my.lp").write_text("2\nled_1.jpg 0 0.6 0.8\nled_2.jpg 0.6 0 0.8\n")
    text = SMALL_DOME.replace('layout = "rings"', 'layout = "lp"\nlp_file = "domes/my.lp"')
    text = text.split("rings = [")[0] + "\n[camera]" + text.split("[camera]")[1]
    g = rig_geometry(load_rig_config(write_config(tmp_path, text)))
    assert isinstance(g, DomeGeometry)
    assert g.names == ("led_1.jpg", "led_2.jpg")


def test_lp_layout_errors_name_the_lp_line(tmp_path: Path) -> None:
    (tmp_path / "bad.lp").write_text("2\nled_1.jpg 0 0.6 0.8\nled_2.jpg 0 0 zero\n")
    text = SMALL_DOME.replace('layout = "rings"', 'layout = "lp"\nlp_file = "bad.lp"')
    text = text.split("rings = [")[0] + "\n[camera]" + text.split("[camera]")[1]
    with pytest.raises(ConfigError) as info:
        load_rig_config(write_config(tmp_path, text))
    assert info.value.key == "dome.lp_file"
    assert "bad.lp, line 3" in str(info.value)
    missing = text.replace("bad.lp", "gone.lp")
    with pytest.raises(ConfigError, match="does not exist"):
        load_rig_config(write_config(tmp_path, missing, "m.toml"))


def test_arm_limits_checked(tmp_path: Path) -> None:
    text = """
name = "a"
kind = "arm"
[arm]
max_elevation_deg = 88.0
keep_out_half_angle_deg = 10.0
"""
    with pytest.raises(ConfigError, match="keep-out cone"):
        load_rig_config(write_config(tmp_path, text))


def test_led_below_plane_rejected(tmp_path: Path) -> None:
    (tmp_path / "low.lp").write_text("1\nled_1.jpg 0 0.6 -0.8\n")
    text = SMALL_DOME.replace('layout = "rings"', 'layout = "lp"\nlp_file = "low.lp"')
    text = text.split("rings = [")[0] + "\n[camera]" + text.split("[camera]")[1]
    with pytest.raises(ConfigError, match="below the object plane"):
        load_rig_config(write_config(tmp_path, text))


def test_missing_backend_with_device_tables_is_refused(tmp_path: Path) -> None:
    """A hardware config that lost its backend line must not run as a dry run unnoticed."""
    shipped = Path(__file__).resolve().parents[2] / "rig_configs" / "example_dome_48.toml"
    text = shipped.read_text(encoding="utf-8")
    assert 'backend = "hardware"\n' in text
    (tmp_path / "example_dome_48.lp").write_text(
        (shipped.parent / "example_dome_48.lp").read_text(encoding="utf-8")
    )
    path = write_config(tmp_path, text.replace('backend = "hardware"\n', ""), "no_backend.toml")
    with pytest.raises(ConfigError) as info:
        load_rig_config(path)
    assert "backend is not set" in info.value.message
    assert "[dome.serial] and [camera.device]" in info.value.message
    assert str(path) in str(info.value)
    # a config without device tables may still default to the simulated backend
    assert 'backend = "simulated"' in SMALL_DOME
    plain = SMALL_DOME.replace('backend = "simulated"\n', "")
    assert load_rig_config(write_config(tmp_path, plain, "plain.toml")).config.backend == (
        "simulated"
    )


def test_dome_shutter_trigger_needs_a_dome(tmp_path):
    from rti_rig.app.config import load_rig_config
    from rti_rig.core.errors import ConfigError

    text = (REPO / "rig_configs" / "simulated_arm.toml").read_text()
    text = text.replace('backend = "emulated"', 'backend = "hardware"')
    text += '\n[camera.device]\nkind = "folder_watch"\nfolder = "."\ntrigger = "dome_shutter"\n'
    with pytest.raises(ConfigError, match=r"camera\.device\.trigger.*needs a dome"):
        load_rig_config(write_config(tmp_path, text))


def test_a_camera_setting_given_as_a_number_says_how_to_write_it(tmp_path: Path) -> None:
    """`iso = 100` was refused as "Input should be a valid string", with no value and no way."""
    import shutil

    from rti_rig.app.config import camera_device_settings

    shutil.copy(REPO / "rig_configs" / "example_dome_48.lp", tmp_path)
    text = (REPO / "rig_configs" / "example_dome_48.toml").read_text()
    assert 'iso = "100"' in text
    path = write_config(tmp_path, text.replace('iso = "100"', "iso = 100"), "dslr.toml")
    with pytest.raises(ConfigError) as info:
        camera_device_settings(load_rig_config(path))
    assert info.value.key == "camera.device.iso"
    assert 'got 100: write it in quotes, "100"' in info.value.message


@pytest.mark.parametrize(
    ("trigger", "timeout", "said"),
    [("none", 15.0, True), ("none", 7.0, False), ("dome_shutter", 15.0, False)],
)
def test_a_camera_awaited_longer_than_an_led_may_stay_lit_is_noted(
    tmp_path: Path, trigger: str, timeout: float, said: bool
) -> None:
    """With trigger = 'none' the LED stays lit until the file comes: a timeout_s beyond
    max_on_s let a late file stop the session at the thermal limit, with advice about settle
    and exposure only. Now the config says so when it is loaded (shown by run)."""
    import shutil

    shutil.copy(REPO / "rig_configs" / "example_dome_48.lp", tmp_path / "example_dome_48.lp")
    text = (REPO / "rig_configs" / "example_dome_48_folder_watch.toml").read_text()
    assert 'trigger = "dome_shutter"' in text and "timeout_s = 15.0" in text
    text = text.replace('trigger = "dome_shutter"', f'trigger = "{trigger}"')
    cfg = tmp_path / "fw.toml"
    cfg.write_text(text.replace("timeout_s = 15.0", f"timeout_s = {timeout}"))
    notes = " ".join(load_rig_config(cfg).notes)
    assert ("stops the session at the thermal limit" in notes) is said
    if said:
        assert "camera.device.timeout_s = 15 s" in notes and "max_on_s = 8 s" in notes


@pytest.mark.parametrize(("timeout", "said"), [(3.0, True), (3.5, False), (15.0, False)])
def test_a_wait_within_the_capture_time_checks_allowance_is_noted(
    tmp_path: Path, timeout: float, said: bool
) -> None:
    """A resume's first file is refused only when shot more than 1 s + shutter_lag_s + the
    trigger times before the resume, its shot known only to within as much: with a timeout_s
    not over twice that, the file a stopped run waited for may pass as the resumed light's.
    The docs said it was always caught; the config now says so when it is loaded (shown by
    run and check), naming both keys."""
    import shutil

    shutil.copy(REPO / "rig_configs" / "example_dome_48.lp", tmp_path / "example_dome_48.lp")
    text = (REPO / "rig_configs" / "example_dome_48_folder_watch.toml").read_text()
    assert "timeout_s = 15.0" in text and "shutter_lag_s = 0.5" in text
    cfg = tmp_path / "fw.toml"
    cfg.write_text(text.replace("timeout_s = 15.0", f"timeout_s = {timeout}"))
    notes = " ".join(load_rig_config(cfg).notes)
    assert ("twice the allowance of the capture-time check" in notes) is said, notes
    if said:
        assert "camera.device.timeout_s = 3 s" in notes, notes
        assert "camera.device.shutter_lag_s = 0.5 s" in notes and "(1.6 s" in notes, notes
        assert "Raise timeout_s over 3.2 s" in notes, notes


def test_a_dslr_retried_longer_than_an_led_may_stay_lit_is_no_longer_a_note(
    tmp_path: Path,
) -> None:
    """A 'busy' body is retried with growing waits; those that outlast the LED's max_on_s are
    now waited with the LED off (the controller lights it again for the shot), so a config
    whose retries do (the shipped example's 15.5 s against max_on_s = 8 s) loads without the
    note that had said such a camera "stops the session at the thermal limit"."""
    import re
    import shutil

    shutil.copy(REPO / "rig_configs" / "example_dome_48.lp", tmp_path / "example_dome_48.lp")
    text = (REPO / "rig_configs" / "example_dome_48.toml").read_text()
    assert "max_on_s = 8.0\n" in text
    cfg = tmp_path / "dslr.toml"
    cfg.write_text(re.sub(r"(?m)^busy_retries = \d+$", "busy_retries = 20", text, count=1))
    assert "busy_retries = 20\n" in cfg.read_text()
    notes = " ".join(load_rig_config(cfg).notes)
    assert "busy" not in notes and "thermal limit" not in notes, notes


@pytest.mark.parametrize(("exposure", "refused"), [("2.0", True), ("1.3", False)])
def test_an_exposure_whose_shot_cannot_end_while_its_led_is_lit_is_refused_at_load(
    tmp_path: Path, exposure: str, refused: bool
) -> None:
    """max_on_s = 2 s, settle 0.2 s, readout 0.5 s: a 2 s exposure cannot end while its LED is
    lit. It was accepted, and `rti-rig run` stopped at its first image with the LED lit all
    along ("LED 0 stayed on 2.208 s, beyond max_on_s = 2 s")."""
    import shutil

    shutil.copy(REPO / "rig_configs" / "example_dome_48.lp", tmp_path / "example_dome_48.lp")
    text = (REPO / "rig_configs" / "example_dome_48.toml").read_text()
    assert "max_on_s = 8.0\n" in text and "exposure_s = 0.125\n" in text
    text = text.replace("max_on_s = 8.0\n", "max_on_s = 2.0\n")
    cfg = tmp_path / "dslr.toml"
    cfg.write_text(text.replace("exposure_s = 0.125\n", f"exposure_s = {exposure}\n"))
    if not refused:
        load_rig_config(cfg)
        return
    with pytest.raises(ConfigError) as e:
        load_rig_config(cfg)
    assert e.value.key == "camera.exposure_s"
    said = str(e.value)
    assert "[dome.serial.thermal] max_on_s = 2 s" in said
    assert "timing.settle_s 0.2 + camera.exposure_s 2 + timing.readout_s 0.5 = 2.7 s" in said
    assert "shorten exposure_s to at most 1.3 s" in said
