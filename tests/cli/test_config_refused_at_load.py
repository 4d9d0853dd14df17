"""Config mistakes found by an audit through the CLI, refused when the config loads (before any
port opens), naming the file, the key and what to do.

* An RTIPy exposure longer than the LED's self-timed window passed the dry run (the emulated
  window is counted on the wall clock, which a simulated camera does not use): a clean session
  of images rendered fully lit, where every capture on the dome would be refused.
* A firmware profile's ``led_count`` that differs from the [dome] layout was found only after
  the port opened, blamed on the firmware ("the firmware reports 100 LEDs but the dome's .lp has
  12": the Nab sketch reports nothing, and the layout was no .lp); a count above the sketch's
  64 LEDs was not refused at all.
* ``[camera.device]`` on a simulated or emulated rig was ignored without a word.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from conftest import UnlimitedLighting, at_key
from typer.testing import CliRunner

from rti_rig.app.config import load_rig_config
from rti_rig.cli import app
from rti_rig.core.errors import ConfigError

REPO = Path(__file__).resolve().parents[2]
CONFIGS = REPO / "rig_configs"
runner = CliRunner()


def said(result) -> str:  # type: ignore[no-untyped-def]
    return " ".join(result.output.split())


def edited(tmp_path: Path, shipped: str, old: str, new: str, name: str = "rig.toml") -> Path:
    text = (CONFIGS / shipped).read_text(encoding="utf-8")
    assert old in text, old
    path = tmp_path / name
    path.write_text(text.replace(old, new, 1), encoding="utf-8")
    return path


# ------------------------------------------------------------------ RTIPy's self-timed window


def test_an_exposure_longer_than_the_rtipy_window_is_refused_before_the_port_opens(
    tmp_path: Path,
) -> None:
    cfg = edited(tmp_path, "emulated_rtipy.toml", "exposure_s = 0.05", "exposure_s = 5.0")
    out = tmp_path / "s"
    r = runner.invoke(app, ["run", str(cfg), "--out", str(out), "--lights", "6"])
    assert r.exit_code == 2, r.output
    text = said(r)
    assert f"{at_key(cfg, 'camera.exposure_s')}" in text
    assert "the rtipy firmware lights each LED for 2 s" in text
    assert "dome.serial.protocol.light_on_s = 2" in text
    # the capture begins once the reply the sketch prints before lighting the LED is heard:
    # 46 characters at 9600 baud plus the port's latency (it had been left out: 0.95 s was
    # admitted, and every capture then refused by the all-off as "went dark by itself")
    assert (
        "the firmware's reply 0.064 s, heard after the LED lights, + timing.settle_s 0.1 " in text
    )
    assert "settle_s 0.1 + camera.exposure_s 5 + timing.readout_s 0.3" in text
    assert "= 6.16 s" in text
    assert "Raise dome.serial.protocol.light_on_s to 7" in text
    assert "shorten exposure_s to at most 0.886 s" in text
    assert not out.exists()  # refused before anything was written or opened
    assert "Rig emulated-rtipy" not in text


def test_the_window_counts_whole_seconds_and_the_profile_default(tmp_path: Path) -> None:
    # light_on_s = 1.4 is sent as T,x,y,1: a 1 s window, not 1.4 s
    cfg = edited(tmp_path, "emulated_rtipy.toml", "light_on_s = 2.0", "light_on_s = 1.4")
    r = runner.invoke(app, ["check", str(cfg)])
    assert r.exit_code == 2, r.output
    assert "for 1 s (dome.serial.protocol.light_on_s = 1.4, sent as 1 whole s)" in said(r)
    # without the key the profile's own 2 s applies, and the message says so
    cfg = edited(tmp_path, "emulated_rtipy.toml", "light_on_s = 2.0", "", "default.toml")
    cfg.write_text(
        cfg.read_text(encoding="utf-8").replace("exposure_s = 0.05", "exposure_s = 1.5"),
        encoding="utf-8",
    )
    r = runner.invoke(app, ["check", str(cfg)])
    assert r.exit_code == 2, r.output
    assert "the rtipy profile's light_on_s = 2" in said(r)


def test_a_long_exposure_fits_a_window_raised_to_hold_it(tmp_path: Path) -> None:
    cfg = edited(tmp_path, "emulated_rtipy.toml", "exposure_s = 0.05", "exposure_s = 5.0")
    cfg.write_text(
        cfg.read_text(encoding="utf-8").replace("light_on_s = 2.0", "light_on_s = 7.0"),
        encoding="utf-8",
    )
    from rti_rig.app.config import timed_exposure_limit

    loaded = load_rig_config(cfg)
    limit = timed_exposure_limit(loaded)
    assert limit is not None and limit.window_s == 7
    # "I received: T,7,0,7 the instructionByte was: T" (the longest of the 8 LEDs' replies,
    # 46 characters at 9600 baud, 10 bits each) and the port's latency, before the settle
    reply_s = len("I received: T,7,0,7 the instructionByte was: T") * 10 / 9600 + 0.016
    assert limit.reply_s == pytest.approx(reply_s)
    assert limit.max_exposure_s == pytest.approx(7 + 0.05 - reply_s - 0.1 - 0.3 - 0.7)


def test_auto_exposure_meters_no_longer_than_the_window_holds(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    """--auto-exposure on an RTIPy dome: the camera's max_exposure_s (30 s by default) is lowered
    to what the window leaves room for, and the user is told; metering never picks more."""
    import rti_rig.drivers.cameras.exposure as exposure
    import rti_rig.runtime.exposure_policy as policy
    from rti_rig.app.usecases.session import fix_exposure

    loaded = load_rig_config(CONFIGS / "emulated_rtipy.toml")
    assert loaded.config.camera.max_exposure_s == 30.0
    rules = []

    class Metered(Exception):
        pass

    def fake_fix(rig, schedule, meter, *checks, **how):  # type: ignore[no-untyped-def]
        meter(object(), 0.05)
        raise Metered

    monkeypatch.setattr(exposure, "meter_exposure", lambda cam, rule, *a, **how: rules.append(rule))
    monkeypatch.setattr(policy, "fix_session_exposure", fake_fix)

    class FakeRig:
        def __init__(self) -> None:
            self.loaded = loaded
            self.camera_config = loaded.config.camera
            self.camera = object()  # a camera with no shutter-speed list of its own
            self.lighting = UnlimitedLighting()

    def planned():  # type: ignore[no-untyped-def]
        from rti_rig.app.config import rig_geometry
        from rti_rig.planner.uniform import plan_uniform

        return plan_uniform(rig_geometry(loaded), 8)

    notes = []
    with pytest.raises(Metered):
        fix_exposure(FakeRig(), planned(), 0.001, notes.append)  # type: ignore[arg-type]
    assert rules and rules[0].max_exposure_s == pytest.approx(0.95 - 0.064, abs=1e-3)
    assert "Metering chooses no exposure longer than 0.886 s" in notes[0].text
    assert "max_exposure_s = 30 s" in notes[0].text
    assert "And each test shot is taken under a window of its own" in notes[0].text
    # a dome with no self-timed window keeps the camera's own limit (and, uncalibrated, is
    # metered at several lights: said in a note of its own)
    loaded = load_rig_config(CONFIGS / "emulated_nab_rti_v1.toml")
    notes.clear()
    with pytest.raises(Metered):
        fix_exposure(FakeRig(), planned(), 0.001, notes.append)  # type: ignore[arg-type]
    assert rules[-1].max_exposure_s == 30.0
    assert not [n for n in notes if "Metering chooses no exposure longer" in n.text]
    assert not [n for n in notes if "a window of its own" in n.text]
    # a camera whose own limit the window holds: nothing lowered, the shot per window said
    text = (CONFIGS / "emulated_rtipy.toml").read_text(encoding="utf-8")
    path = tmp_path / "rig.toml"
    path.write_text(text.replace("exposure_s = 0.05", "exposure_s = 0.05\nmax_exposure_s = 0.5"))
    loaded = load_rig_config(path)
    notes.clear()
    with pytest.raises(Metered):
        fix_exposure(FakeRig(), planned(), 0.001, notes.append)  # type: ignore[arg-type]
    assert rules[-1].max_exposure_s == 0.5
    assert notes[0].text.startswith(
        "Metering: the rtipy firmware lights each LED for 2 s (dome.serial.protocol.light_on_s "
        "= 2) and then switches it off by itself, so each test shot is taken under a window of "
        "its own (its LED lit again for it): a window holds one capture, not a series"
    ), notes[0].text


def test_a_plan_step_exposing_past_the_window_is_refused_before_the_port_opens(
    tmp_path: Path,
) -> None:
    from rti_rig.app.usecases.session import checked_rig
    from rti_rig.core.errors import ScheduleError
    from rti_rig.core.schedule import LightSchedule, LightStep

    loaded = load_rig_config(CONFIGS / "emulated_rtipy.toml")
    step = LightStep(direction=(0.0, 0.0, 1.0), led=0, exposure_s=3.0)
    with pytest.raises(ScheduleError, match=r"step 1: exposure 3 s") as info:
        checked_rig(loaded, LightSchedule((step,)))
    assert "0.886 s that fit" in str(info.value)


# ------------------------------------------------------------------ led_count of a firmware profile


def test_a_led_count_above_the_nab_sketchs_64_is_refused_naming_the_key(tmp_path: Path) -> None:
    cfg = edited(tmp_path, "emulated_nab_rti_v1.toml", "led_count = 12 ", "led_count = 100 ")
    r = runner.invoke(app, ["check", str(cfg)])
    assert r.exit_code == 2, r.output
    text = said(r)
    assert f"{at_key(cfg, 'dome.serial.protocol.led_count')}: led_count = 100" in text
    assert "the nab-rti-v1 firmware drives at most 64 LEDs" in text
    assert "firmware reports" not in text and ".lp" not in text
    assert "handshake" not in text  # found at load, not after the port opened


def test_a_led_count_other_than_the_layouts_is_refused_naming_key_and_layout(
    tmp_path: Path,
) -> None:
    cfg = edited(tmp_path, "emulated_nab_rti_v1.toml", "led_count = 12 ", "led_count = 8 ")
    r = runner.invoke(app, ["check", str(cfg)])
    assert r.exit_code == 2, r.output
    text = said(r)
    assert (
        f"{at_key(cfg, 'dome.serial.protocol.led_count')}: led_count = 8 but [dome] layout "
        "'fibonacci' (count = 12) gives 12 lights: set led_count = 12"
    ) in text
    assert "The firmware reports no count: this number is the rig config's own" in text
    assert "handshake" not in text and ".lp has" not in text


def test_a_led_count_left_to_the_profile_says_so(tmp_path: Path) -> None:
    cfg = edited(tmp_path, "emulated_nab_rti_v1.toml", "led_count = 12 ", "# led_count = 12 ")
    with pytest.raises(ConfigError) as info:
        load_rig_config(cfg)
    assert info.value.key == "dome.serial.protocol.led_count"
    assert "not set, so the nab-rti-v1 profile's 64 applies" in info.value.message
    assert "add led_count = 12 under [dome.serial.protocol]" in info.value.message


def test_a_firmware_that_reports_no_count_is_not_said_to_report_one() -> None:
    """The runtime check stays for firmwares that report a count; where the count is the
    description's, the message says so."""
    from rti_rig.core.dome_link import DomeInfo

    assert DomeInfo("x", "1", 48).led_count_said() == "the firmware reports 48 LEDs"
    said_ = DomeInfo("nab-rti-v1", "", 100, "the nab-rti-v1 protocol description").led_count_said()
    assert said_ == "the nab-rti-v1 protocol description gives 100 LEDs (the firmware reports none)"


# ------------------------------------------------------------------ [camera.device] on a dry run


@pytest.mark.parametrize(
    ("shipped", "backend"),
    [("simulated_dome.toml", "simulated"), ("emulated_nab_rti_v1.toml", "emulated")],
)
def test_a_camera_device_on_a_dry_run_is_refused(
    tmp_path: Path, shipped: str, backend: str
) -> None:
    cfg = tmp_path / "rig.toml"
    cfg.write_text(
        (CONFIGS / shipped).read_text(encoding="utf-8") + '\n[camera.device]\nkind = "gphoto2"\n',
        encoding="utf-8",
    )
    r = runner.invoke(app, ["run", str(cfg), "--out", str(tmp_path / "s"), "--lights", "6"])
    assert r.exit_code == 2, r.output
    text = said(r)
    assert f"{at_key(cfg, 'camera.device')}: backend = '{backend}' renders its own images" in text
    assert "set backend = 'hardware'" in text and "remove [camera.device]" in text
    assert not (tmp_path / "s").exists()


# ------------------------------------------------------- a number or truth value in quotes


@pytest.mark.parametrize(
    ("shipped", "old", "new", "key", "kind"),
    [
        # a table's own number (pydantic's lax mode had read "0.05" as 0.05 without a word)
        (
            "simulated_dome.toml",
            "exposure_s = 0.05",
            'exposure_s = "0.05"',
            "camera.exposure_s",
            "a number",
        ),
        # a driver's settings table
        ("emulated_rtipy.toml", "retries = 2", 'retries = "2"', "dome.serial.retries", "a number"),
        # a firmware description, validated by the driver after the settings
        (
            "emulated_rtipy.toml",
            "led_count = 8 ",
            'led_count = "8" ',
            "dome.serial.protocol.led_count",
            "a number",
        ),
        # an element of an array of tables
        (
            "simulated_dome.toml",
            "elevation_deg = 25.0",
            'elevation_deg = "25.0"',
            "dome.rings[1].elevation_deg",
            "a number",
        ),
        # a servo arm's driver settings
        (
            "simulated_arm.toml",
            "settle_time_s = 0.05",
            'settle_time_s = "0.05"',
            "arm.dynamixel.settle_time_s",
            "a number",
        ),
        # a truth value
        (
            "simulated_arm.toml",
            "[arm]",
            '[arm]\npark_after_session = "false"',
            "arm.park_after_session",
            "true or false",
        ),
    ],
)
def test_a_quoted_number_is_refused_naming_its_key(
    tmp_path: Path, shipped: str, old: str, new: str, key: str, kind: str
) -> None:
    cfg = edited(tmp_path, shipped, old, new)
    with pytest.raises(ConfigError) as err:
        load_rig_config(cfg)
    assert err.value.key == key
    assert f"is text in quotes, not {kind}: write it without the quotes" in err.value.message
    r = runner.invoke(app, ["check", str(cfg)])
    assert r.exit_code == 2, r.output
    assert f"key '{key}'" in said(r)
    assert "Traceback" not in r.output


def test_a_quoted_truth_value_in_the_camera_device_table_is_refused(tmp_path: Path) -> None:
    """``[camera.device]`` is validated by the camera driver's settings after the rig's own
    tables; its text values (``iso = "100"``) stay text, a quoted boolean is refused."""
    (tmp_path / "example_dome_48.lp").write_bytes((CONFIGS / "example_dome_48.lp").read_bytes())
    cfg = edited(tmp_path, "example_dome_48.toml", 'iso = "100"', 'iso = "100"\nkeep_jpeg = "true"')
    with pytest.raises(ConfigError) as err:
        load_rig_config(cfg)
    assert err.value.key == "camera.device.keep_jpeg"
    assert "'true' is text in quotes, not true or false" in err.value.message
    # without the quotes it loads, and the camera's own text values are kept as text
    fixed = edited(
        tmp_path, "example_dome_48.toml", 'iso = "100"', 'iso = "100"\nkeep_jpeg = true', "ok.toml"
    )
    assert load_rig_config(fixed).config.camera.device["iso"] == "100"


def test_every_shipped_config_has_no_quoted_number() -> None:
    for cfg in sorted(CONFIGS.glob("*.toml")):
        load_rig_config(cfg)  # raises on a quoted number


def test_text_that_is_no_number_is_not_called_a_quoted_number(tmp_path: Path) -> None:
    """The protocol's baud rate is [dome.serial]'s where that gives one: a
    ``protocol.baudrate = "fast"`` beside it met a number in the validated description and was
    refused as "'fast' is text in quotes, not a number: write it without the quotes", which is
    untrue ('fast' unquoted is no TOML). Only text that reads as the value is a quoted value."""
    cfg = edited(
        tmp_path,
        "emulated_rtipy.toml",
        "[dome.serial]\n",
        "[dome.serial]\nbaudrate = 57600\n",
    )
    text = cfg.read_text(encoding="utf-8").replace(
        "led_count = 8 ", 'baudrate = "fast"\nled_count = 8 ', 1
    )
    cfg.write_text(text, encoding="utf-8")
    try:
        load_rig_config(cfg)
    except ConfigError as exc:
        assert "text in quotes" not in exc.message, exc.message


# ------------------------------------------------------- the baud rate given twice


def _two_bauds(tmp_path: Path, serial: str, protocol: str, name: str = "rig.toml") -> Path:
    """emulated_nab_rti_v1.toml (its firmware at 9600) with a baud rate in both tables."""
    cfg = edited(
        tmp_path, "emulated_nab_rti_v1.toml", "[dome.serial]\n", f"[dome.serial]\n{serial}\n", name
    )
    text = cfg.read_text(encoding="utf-8").replace(
        "[dome.serial.protocol]\n", f"[dome.serial.protocol]\n{protocol}\n", 1
    )
    cfg.write_text(text, encoding="utf-8")
    return cfg


def test_two_different_baud_rates_are_refused_naming_both_keys(tmp_path: Path) -> None:
    """``[dome.serial] baudrate`` silently won over ``[dome.serial.protocol] baudrate``: the
    port opened at 115200 to a firmware at 9600, and ``check`` blamed a silent board after a
    reply timeout. Both given and different is refused as the config loads, before any port."""
    cfg = _two_bauds(tmp_path, "baudrate = 115200", "baudrate = 9600")
    with pytest.raises(ConfigError) as err:
        load_rig_config(cfg)
    assert str(err.value.path) == str(cfg)
    r = runner.invoke(app, ["check", str(cfg)])
    assert r.exit_code == 2, r.output
    text = said(r)
    assert f"{at_key(cfg, 'dome.serial')}" in text
    assert "dome.serial.baudrate = 115200 and dome.serial.protocol.baudrate = 9600 disagree" in text
    assert "remove one of the two keys" in text
    assert "LEDs stepped" not in text and "Traceback" not in text


@pytest.mark.parametrize(
    ("serial", "protocol", "baud"),
    [
        ("baudrate = 9600", "baudrate = 9600", 9600),  # equal: accepted
        ("baudrate = 9600", "baudrate = 9600.0", 9600),  # the same number written otherwise
        ("", "baudrate = 19200", 19200),  # only the protocol's: it is the port's
        ("baudrate = 38400", "", 38400),  # only [dome.serial]'s
        ("", "", 9600),  # neither: the nab-rti-v1 firmware's own
    ],
)
def test_one_baud_rate_or_two_equal_ones_load(
    tmp_path: Path, serial: str, protocol: str, baud: int
) -> None:
    loaded = load_rig_config(_two_bauds(tmp_path, serial, protocol))
    settings = loaded.config.dome.serial  # type: ignore[union-attr]
    assert settings.baudrate == baud
    assert settings.protocol_spec().baudrate == baud
