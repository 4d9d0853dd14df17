"""Evening out a dome's LEDs: card session → calibrate-lights → intensity correction → even light.

The emulated dome's LEDs are made uneven (``[emulator] led_power``), the card is the simulator's
matte grey plate (scene ``flat``), and everything between runs the real code: the dome driver
over pyserial applies the correction as PWM levels, and the camera renders the light the
emulated firmware really gives.
"""

from __future__ import annotations

import json
import tomllib
from pathlib import Path

import numpy as np
import pytest
from card_support import TRUE_POWER, card_rig, shoot
from conftest import CONFIGS, said, write_config
from typer.testing import CliRunner

from rti_rig.app.config import load_rig_config
from rti_rig.app.light_calibration import CardSession, calibrate_dome, read_card_session
from rti_rig.cli import app
from rti_rig.core.errors import ConfigError, SessionError

runner = CliRunner()


def relative(values: np.ndarray) -> np.ndarray:
    return values / np.exp(np.median(np.log(values)))


@pytest.mark.slow
@pytest.mark.e2e
@pytest.mark.pty
def test_calibration_evens_out_the_dome(tmp_path: Path) -> None:
    cfg = card_rig(tmp_path)
    shoot(cfg, tmp_path / "card1")
    r = runner.invoke(app, ["calibrate-lights", str(tmp_path / "card1"), "--rig", str(cfg)])
    assert r.exit_code == 0, r.output
    text = said(r)
    assert "48 of 48 LEDs measured" in text
    assert 'intensity_correction_file = "card1/light_calibration.toml"' in text
    cal = tomllib.loads((tmp_path / "card1" / "light_calibration.toml").read_text())
    # each LED's own light recovered (relative to the median LED) to 1 %
    output = np.array(cal["relative_output"])
    np.testing.assert_allclose(output, relative(TRUE_POWER), rtol=0.01)
    corr = np.array(cal["intensity_correction"])
    assert corr.max() == pytest.approx(1.0) and corr.argmax() == TRUE_POWER.argmin()
    assert all(cal["measured"])

    # shot again with the correction in force: the driver dims each LED, the card is even
    cfg2 = card_rig(
        tmp_path, 'intensity_correction_file = "card1/light_calibration.toml"\n', "cal.toml"
    )
    shoot(cfg2, tmp_path / "card2")
    manifest = json.loads((tmp_path / "card2" / "manifest.json").read_text())
    recorded = manifest["rig"]["config"]["dome"]["serial"]
    assert recorded["intensity_correction_file"] == "card1/light_calibration.toml"
    assert recorded["intensity_correction"] == pytest.approx(corr.tolist())
    card2 = read_card_session(tmp_path / "card2")
    again = calibrate_dome(card2, 48)
    before = calibrate_dome(read_card_session(tmp_path / "card1"), 48)
    assert before.shot_spread > 0.12  # the uneven dome, as shot
    assert again.shot_spread < 0.01  # what is left after the correction: PWM rounding, noise
    # the second calibration composes with the correction in force: same LED outputs
    np.testing.assert_allclose(again.output, output, rtol=0.01)
    np.testing.assert_allclose(again.correction, corr, rtol=0.01)


def synthetic_card(
    leds: list[int],
    elevations_deg: list[float],
    power: list[float],
    correction: tuple[float, ...] | None = None,
) -> CardSession:
    """A level card (albedo texture × cosine shading) under the given LEDs, exactly."""
    rng = np.random.default_rng(0)
    albedo = 0.5 + 0.1 * rng.random((24, 24))
    el = np.radians(elevations_deg)
    az = np.linspace(0, 2 * np.pi, len(leds), endpoint=False)
    dirs = np.stack([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)], axis=1)
    factors = np.ones(len(leds)) if correction is None else np.array(correction)[leds]
    drive = np.round(factors * 255) / 255
    images = np.array(power)[:, None, None] * drive[:, None, None] * albedo * dirs[:, 2, None, None]
    return CardSession(
        root=Path("card"),
        rig_name="dome",
        images=images.astype(np.float32),
        directions=dirs,
        leds=np.array(leds),
        drive=drive,
        correction=correction,
    )


def test_unmeasured_leds_take_the_median_and_the_weakest_sets_the_level() -> None:
    # LEDs 0-5 shot (LED 5 at 3° elevation: not measured), LED 6 of the dome never shot
    power = [1.0, 0.5, 1.25, 1.0, 0.8, 3.0]
    card = synthetic_card([0, 1, 2, 3, 4, 5], [30, 40, 50, 60, 35, 3], power)
    cal = calibrate_dome(card, 7, min_elevation_deg=5.0)
    assert cal.measured.tolist() == [True] * 5 + [False, False]
    np.testing.assert_allclose(cal.output, [1.0, 0.5, 1.25, 1.0, 0.8, 1.0, 1.0], rtol=1e-3)
    np.testing.assert_allclose(cal.correction, 0.5 / cal.output, rtol=1e-3)
    assert cal.evened_light == pytest.approx(0.5, rel=1e-3)
    assert cal.stops_lost == pytest.approx(1.0, rel=1e-3)


def test_unmeasured_leds_keep_the_correction_in_force() -> None:
    # LED 4 sits too low to measure; the correction in force had dimmed it to 0.5 (it is bright)
    old = (1.0, 1.0, 1.0, 1.0, 0.5)
    card = synthetic_card([0, 1, 2, 3, 4], [30, 40, 50, 60, 3], [1.0, 0.8, 1.25, 1.0, 2.0], old)
    cal = calibrate_dome(card, 5)
    assert cal.measured.tolist() == [True] * 4 + [False]
    assert cal.output[4] == pytest.approx(2.0, rel=1e-3)  # median light / its old factor
    assert cal.correction[4] == pytest.approx(0.8 / 2.0, rel=1e-3)  # still dimmed, not raised


def test_a_correction_in_force_is_composed_not_replaced() -> None:
    power = [1.0, 0.5, 1.25, 1.0, 0.8]
    old = (0.5, 1.0, 0.4, 0.5, 0.625)  # the ideal correction: the card looks even
    card = synthetic_card([0, 1, 2, 3, 4], [30, 40, 50, 60, 35], power, correction=old)
    cal = calibrate_dome(card, 5)
    assert cal.shot_spread < 0.005
    np.testing.assert_allclose(cal.output, power, rtol=5e-3)  # the LEDs' own light
    np.testing.assert_allclose(cal.correction, old, rtol=5e-3)
    np.testing.assert_allclose(cal.previous, old)


def test_calibrate_refuses_an_led_outside_the_dome_and_a_foreign_correction() -> None:
    card = synthetic_card([0, 1, 2, 9], [30, 40, 50, 60], [1, 1, 1, 1])
    with pytest.raises(SessionError, match="LED 9 is outside a dome of 5 LEDs"):
        calibrate_dome(card, 5)
    card = synthetic_card([0, 1, 2, 3], [30, 40, 50, 60], [1, 1, 1, 1], correction=(1.0,) * 6)
    with pytest.raises(SessionError, match="6 correction factors, but the dome has 5"):
        calibrate_dome(card, 5)


def edit_manifest(folder: Path, change) -> None:  # type: ignore[no-untyped-def]
    path = folder / "manifest.json"
    data = json.loads(path.read_text())
    change(data)
    path.write_text(json.dumps(data))


@pytest.mark.slow
@pytest.mark.e2e
@pytest.mark.pty
def test_card_sessions_that_cannot_calibrate_are_refused_by_name(tmp_path: Path) -> None:
    cfg = card_rig(tmp_path)
    shoot(cfg, tmp_path / "card")

    def saturate(m):  # type: ignore[no-untyped-def]
        m["steps"][6]["saturated_fraction"] = 0.2

    edit_manifest(tmp_path / "card", saturate)
    with pytest.raises(SessionError, match=r"image_007.tif \(LED 6\): 20.0 % of its pixels"):
        read_card_session(tmp_path / "card")

    def twice(m):  # type: ignore[no-untyped-def]
        m["steps"][6]["saturated_fraction"] = 0.0
        m["steps"][7]["led"] = 6

    edit_manifest(tmp_path / "card", twice)
    with pytest.raises(SessionError, match=r"LED 6 lit both linear/image_007\.tif and"):
        read_card_session(tmp_path / "card")

    def no_serial(m):  # type: ignore[no-untyped-def]
        m["steps"][7]["led"] = 7
        del m["rig"]["config"]["dome"]["serial"]

    edit_manifest(tmp_path / "card", no_serial)
    with pytest.raises(SessionError, match=r"without a \[dome.serial\] table"):
        read_card_session(tmp_path / "card")


@pytest.mark.slow
@pytest.mark.e2e
@pytest.mark.pty
def test_a_clipped_card_metered_by_auto_exposure_is_not_told_to_meter_again(
    tmp_path: Path,
) -> None:
    """--auto-exposure meters at the nominally brightest LED; on a card under an uncalibrated
    dome a brighter LED then clipped the whole frame (the shipped emulated_dome_card.toml:
    7 of 48 images), and the refusal advised "rti-rig run --auto-exposure meters one". It
    names every clipped image and a fixed exposure to try instead."""
    cfg = card_rig(tmp_path)
    shoot(cfg, tmp_path / "card")
    exposure = json.loads((tmp_path / "card" / "manifest.json").read_text())["steps"][0][
        "exposure_s"
    ]

    def metered_and_clipped(m):  # type: ignore[no-untyped-def]
        m["schedule"].setdefault("provenance", {})["exposure"] = {
            "exposure_s": exposure,
            "method": "test-series",
        }
        m["steps"][6]["saturated_fraction"] = 0.2
        m["steps"][9]["saturated_fraction"] = 0.5

    edit_manifest(tmp_path / "card", metered_and_clipped)
    with pytest.raises(SessionError) as caught:
        read_card_session(tmp_path / "card")
    text = str(caught.value)
    assert "image_010.tif (LED 9): 50.0 % of its pixels are saturated" in text, text
    assert "2 of 48 images clipped" in text and "image_007.tif (LED 6)" in text, text
    assert "meters one" not in text and "--auto-exposure metered this session" in text, text
    assert f"exposure_s = {exposure / 2:.4g} under [camera]" in text, text
    assert "at one LED" in text, text
    # metered at several LEDs (an uncalibrated dome's --auto-exposure): not said "at one LED"
    edit_manifest(
        tmp_path / "card",
        lambda m: m["schedule"]["provenance"]["exposure"].update(
            lights_metered_at_steps=[45, 46, 44, 47, 43, 48]
        ),
    )
    with pytest.raises(SessionError) as caught:
        read_card_session(tmp_path / "card")
    text = str(caught.value)
    assert "--auto-exposure metered this session at 6 LEDs" in text, text
    assert "so a brighter one it did not meter at clipped the card" in text, text


@pytest.mark.slow
@pytest.mark.e2e
@pytest.mark.pty
def test_simulated_arm_and_missing_images_are_refused(tmp_path: Path) -> None:
    arm = tmp_path / "arm"
    r = runner.invoke(
        app, ["run", str(CONFIGS / "virtual_arm.toml"), "--out", str(arm), "--lights", "4"]
    )
    assert r.exit_code == 0, r.output
    with pytest.raises(SessionError, match="light calibration is for domes"):
        read_card_session(arm)
    cfg = card_rig(tmp_path)
    shoot(cfg, tmp_path / "card")
    (tmp_path / "card" / "linear" / "image_003.tif").unlink()
    with pytest.raises(SessionError, match=r"image_003.tif \(LED 2\) missing"):
        read_card_session(tmp_path / "card")


def test_a_card_image_changed_since_capture_is_refused_not_measured(tmp_path: Path) -> None:
    """A halved TIFF had been measured: the dome read "0.37 of the median" and the correction
    written from it would have dimmed every other LED. The journal's checksums say what was
    captured; an image without a readable record cannot be vouched for either."""
    import tifffile

    cfg = card_rig(tmp_path)
    card = tmp_path / "card"
    shoot(cfg, card)
    read_card_session(card)  # intact: measured
    tif = card / "linear" / "image_005.tif"
    tifffile.imwrite(tif, tifffile.imread(tif) // 2)
    with pytest.raises(SessionError, match=r"image_005.tif \(LED 4\) changed since capture"):
        read_card_session(card)
    r = runner.invoke(app, ["calibrate-lights", str(card), "--rig", str(cfg)])
    assert r.exit_code != 0 and "changed since capture" in said(r) and "Traceback" not in r.output
    assert not (card / "light_calibration.toml").exists()
    journal = card / "journal.jsonl"
    lines = journal.read_text().splitlines(keepends=True)
    journal.write_text("".join(lines[:3]) + "{not json\n" + "".join(lines[4:]))
    (card / "records" / "image_004.json").unlink()  # its step record file lost too
    with pytest.raises(SessionError, match=r"image_004.tif \(LED 3\) has no readable record"):
        read_card_session(card)


@pytest.mark.slow
@pytest.mark.e2e
@pytest.mark.pty
def test_cli_refusals_name_what_is_wrong(tmp_path: Path) -> None:
    cfg = card_rig(tmp_path)
    card = tmp_path / "card"
    shoot(cfg, card)

    def calibrate(*extra: str, rig: Path = cfg) -> str:
        r = runner.invoke(app, ["calibrate-lights", str(card), "--rig", str(rig), *extra])
        assert r.exit_code == 2, r.output
        return said(r)

    other = write_config(tmp_path, cfg.read_text().replace("emulated-dome-48", "other"), "o.toml")
    assert "was shot on rig 'emulated-dome-48', not 'other'" in calibrate(rig=other)
    assert "a simulated dome's LEDs are exact" in calibrate(rig=CONFIGS / "simulated_dome.toml")
    no_level = cfg.read_text().replace('profile = "default"', 'profile = "framed"')
    no_level += "\n[dome.serial.framed]\nsend_level = false\n"
    assert "cannot dim an LED" in calibrate(rig=write_config(tmp_path, no_level, "nl.toml"))
    assert "--card-normal" in calibrate("--card-normal", "0,1")
    assert "must face the camera" in calibrate("--card-normal", "1,0,0")
    r = runner.invoke(app, ["calibrate-lights", str(card), "--rig", str(cfg)])
    assert r.exit_code == 0, r.output
    # the calibration file inside the session is written once, never replaced, even forced
    forced = calibrate("--force")
    assert "calibrated already (its file is never replaced" in forced
    # --force is refused here: the refusal says so, not only "give --out" (its help had said
    # "Overwrite an existing file.", and the user had given it)
    assert "even with --force" in forced, forced
    elsewhere = tmp_path / "cal.toml"
    assert (
        runner.invoke(
            app, ["calibrate-lights", str(card), "--rig", str(cfg), "--out", str(elsewhere)]
        ).exit_code
        == 0
    )
    assert "exists; use --force" in calibrate("--out", str(elsewhere))


def test_correction_file_errors_name_the_key(tmp_path: Path) -> None:
    key = "dome.serial.intensity_correction_file"
    cases = {
        "missing.toml": "cannot read",
        "bad.toml": "not valid TOML",
        "foreign.toml": "calibrates the dome 'other', not 'emulated-dome-48'",
        "short.toml": "intensity_correction has 3 factors for 48 LEDs",
    }
    (tmp_path / "bad.toml").write_text("format = ")
    head = 'format = "rti-rig-light-calibration/1"\n'
    (tmp_path / "foreign.toml").write_text(head + 'rig = "other"\nintensity_correction = [1.0]')
    (tmp_path / "short.toml").write_text(
        head + 'rig = "emulated-dome-48"\nintensity_correction = [1.0, 0.5, 0.7]'
    )
    for name, fragment in cases.items():
        cfg = card_rig(tmp_path, f'intensity_correction_file = "{name}"\n', f"rig_{name}")
        with pytest.raises(ConfigError) as info:
            load_rig_config(cfg)
        assert info.value.key == key, name
        assert fragment in info.value.message, (name, info.value.message)
    both = card_rig(
        tmp_path,
        'intensity_correction_file = "short.toml"\nintensity_correction = [1.0]\n',
        "both.toml",
    )
    with pytest.raises(ConfigError, match="not both"):
        load_rig_config(both)


@pytest.mark.parametrize(
    ("emulator", "fragment"),
    [
        ("led_power = [1.0, 2.0]", "2 values for 48 LEDs"),
        ("led_power_spread = 0.2\nled_power = [1.0]", "not both"),
        ("led_power = [0.0]", "led_power[0] is 0.0"),
    ],
)
def test_uneven_led_settings_are_checked(tmp_path: Path, emulator: str, fragment: str) -> None:
    text = card_rig(tmp_path).read_text().split("[emulator]")[0]
    with pytest.raises(ConfigError, match=fragment.replace("[", r"\[").replace("]", r"\]")):
        load_rig_config(write_config(tmp_path, text + f"[emulator]\n{emulator}\n", "e.toml"))
    sim = (CONFIGS / "simulated_dome.toml").read_text() + "\n[emulator]\nled_power_spread = 0.1\n"
    with pytest.raises(ConfigError, match="backend = 'emulated'"):
        load_rig_config(write_config(tmp_path, sim, "s.toml"))


@pytest.mark.slow
@pytest.mark.e2e
@pytest.mark.pty
def test_the_shipped_rehearsal_config_runs_as_its_comments_say(tmp_path: Path) -> None:
    """rig_configs/emulated_dome_card.toml: shoot, calibrate, add the line, shoot again."""
    text = (CONFIGS / "emulated_dome_card.toml").read_text()
    text = text.replace("width = 256", "width = 48").replace("height = 256", "height = 48")
    text = text.replace('"example_dome_48.lp"', f'"{CONFIGS}/example_dome_48.lp"')
    (tmp_path / "rigs").mkdir()
    cfg = write_config(tmp_path / "rigs", text, "card.toml")
    card = tmp_path / "sessions" / "card"
    shoot(cfg, card)
    r = runner.invoke(app, ["calibrate-lights", str(card), "--rig", str(cfg)])
    assert r.exit_code == 0, r.output
    line = 'intensity_correction_file = "../sessions/card/light_calibration.toml"'
    assert line in said(r)
    cfg.write_text(text.replace('profile = "default"\n', f'profile = "default"\n{line}\n'))
    shoot(cfg, tmp_path / "sessions" / "card2")
    assert calibrate_dome(read_card_session(card), 48).shot_spread > 0.1
    assert calibrate_dome(read_card_session(tmp_path / "sessions" / "card2"), 48).shot_spread < 0.01


@pytest.mark.slow
@pytest.mark.e2e
@pytest.mark.pty
def test_resumed_unfinished_or_malformed_card_sessions_are_refused(tmp_path: Path) -> None:
    cfg = card_rig(tmp_path)
    card = tmp_path / "card"
    shoot(cfg, card)
    good = (card / "manifest.json").read_text()

    def refused(change, match: str) -> None:  # type: ignore[no-untyped-def]
        (card / "manifest.json").write_text(good)
        edit_manifest(card, change)
        with pytest.raises(SessionError, match=match):
            read_card_session(card)

    journal = (card / "journal.jsonl").read_text().splitlines(keepends=True)
    (card / "journal.jsonl").write_text("".join(journal[:20]))  # as a stop after 20 leaves it
    records = card / "records"
    later = {p: p.read_bytes() for p in sorted(records.glob("image_*.json"))[20:]}
    for p in later:  # ... with no step record file of a later image either
        p.unlink()

    def cancelled(m):  # type: ignore[no-untyped-def]
        m["runner"]["finish_reason"] = "cancelled"
        m["steps"] = m["steps"][:20]

    refused(cancelled, r"did not finish \(cancelled, 20 of 48 images\)")

    def killed(m):  # type: ignore[no-untyped-def]
        # a kill: the manifest as the run began (its steps are written when a run finishes);
        # the journal holds the 20 images taken ("0 of 48 images" had been said)
        m["runner"] = {"state": "running", "finish_reason": None}
        m["steps"] = []

    refused(killed, r"did not finish \(no finish recorded, 20 of 48 images\)")
    (card / "journal.jsonl").write_text("".join(journal))
    for p, data in later.items():
        p.write_bytes(data)

    def resumed_with_another_calibration(m):  # type: ignore[no-untyped-def]
        m["runs"].append({**m["runs"][0], "config_sha256": "0" * 64})

    refused(resumed_with_another_calibration, "resumed with a changed rig config or light")
    refused(lambda m: m["steps"][3].update(led=-1), r"records LED -1")
    refused(lambda m: m["steps"][3].pop("actual_direction"), r"step 4 \(image_004.jpg, LED 3\)")
    refused(lambda m: m.update(rig=[]), "does not describe a card session")


@pytest.mark.slow
@pytest.mark.e2e
@pytest.mark.pty
def test_a_step_shot_at_another_exposure_is_scaled_by_it(tmp_path: Path) -> None:
    cfg = card_rig(tmp_path)
    card = tmp_path / "card"
    shoot(cfg, card)
    before = calibrate_dome(read_card_session(card), 48).output
    # the same image said to be shot at half the exposure: its LED must be twice as bright
    edit_manifest(card, lambda m: m["steps"][12].update(exposure_s=0.025))
    after = calibrate_dome(read_card_session(card), 48).output
    assert after[12] / before[12] == pytest.approx(2.0, rel=0.01)
    others = np.delete(np.arange(48), 12)
    np.testing.assert_allclose(after[others], before[others], rtol=0.01)


def test_the_calibration_file_counts_in_the_rig_fingerprint_and_follows_symlinks(
    tmp_path: Path,
) -> None:
    head = 'format = "rti-rig-light-calibration/1"\nrig = "emulated-dome-48"\n'
    cal = tmp_path / "rigs" / "cal.toml"
    cal.parent.mkdir()
    cal.write_text(head + f"intensity_correction = [{', '.join(['1.0'] * 48)}]\n")
    cfg = card_rig(tmp_path / "rigs", 'intensity_correction_file = "cal.toml"\n')
    first = load_rig_config(cfg).sha256
    cal.write_text(head + f"intensity_correction = [{', '.join(['0.9'] * 48)}]\n")
    assert load_rig_config(cfg).sha256 != first  # a resume then says the rig has changed
    (tmp_path / "elsewhere").mkdir()
    link = tmp_path / "elsewhere" / "rig.toml"
    link.symlink_to(cfg)
    assert load_rig_config(link).config.dome.serial.intensity_correction == [0.9] * 48  # type: ignore[union-attr]
    for bad, fragment in [("0.0", "intensity_correction[0] is 0.0"), ("true", "is True")]:
        cal.write_text(head + f"intensity_correction = [{bad}]\n")
        with pytest.raises(ConfigError) as info:
            load_rig_config(cfg)
        assert info.value.key == "dome.serial.intensity_correction_file"
        assert fragment in info.value.message


@pytest.mark.slow
@pytest.mark.e2e
@pytest.mark.pty
def test_a_session_of_an_object_is_not_calibrated_as_a_card(tmp_path: Path) -> None:
    """The coin, not the card, shot on the same dome: its relief had been read as the LEDs'
    differences and the user told to install the correction. Refused, nothing written; a card
    large for its dome can still be calibrated with --not-flat-ok."""
    cfg = card_rig(tmp_path)
    text = cfg.read_text().replace('name = "flat"', 'name = "coin"')
    text = text.replace("exposure_s = 0.05", "exposure_s = 0.005")  # the coin's face unclipped
    coin_cfg = write_config(tmp_path, text, "coin.toml")
    coin = tmp_path / "coin"
    r = runner.invoke(app, ["run", str(coin_cfg), "--out", str(coin), "--lights", "12"])
    assert r.exit_code == 0, r.output
    r = runner.invoke(app, ["calibrate-lights", str(coin), "--rig", str(coin_cfg)])
    assert r.exit_code == 2, r.output
    assert "these images are not of a flat card" in said(r) and "--not-flat-ok" in said(r)
    assert not (coin / "light_calibration.toml").exists()
    r = runner.invoke(app, ["calibrate-lights", str(coin), "--rig", str(coin_cfg), "--not-flat-ok"])
    assert r.exit_code == 0, r.output
