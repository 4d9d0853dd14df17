"""A DSLR busy longer than its LED may stay lit: the LED goes off, the camera is awaited in the
dark, the same LED is lit again for the shot (the owners' decision, 2026-11-29).

The rig is the shipped emulated dome (the real dome policy and driver over a pty, on the rig's
virtual clock) with a 8 s ``max_on_s``, and the real gphoto2 driver on the fake python-gphoto2
module, whose body writes to a slow card: it answers busy (-110, no picture) for a time after
each shot. Each image is rendered from what the emulated firmware really has lit when the body
fires, so an image taken in the dark would show it.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from conftest import CONFIGS, write_config
from dng_spec_writer import dng, mosaic_from_rgb
from fake_gphoto2 import Body, make_module

from rti_rig.app.compose import build_rig
from rti_rig.app.config import load_rig_config
from rti_rig.cli.session import _light_off_for_camera
from rti_rig.core.errors import CaptureError
from rti_rig.core.image_files import read_linear_tiff
from rti_rig.core.schedule import LightSchedule, LightStep
from rti_rig.drivers.cameras.exposure import meter_exposure, recheck_exposure
from rti_rig.drivers.cameras.gphoto2_camera import Gphoto2Camera, parse_shutter
from rti_rig.drivers.cameras.settings import ExposureRule, Gphoto2CameraSettings
from rti_rig.runtime.controller import FinishReason, LightOffForCamera, run_session
from rti_rig.runtime.exposure_policy import Recheck, fix_session_exposure
from rti_rig.runtime.rig import Rig
from rti_rig.runtime.session import SessionFolder

pytestmark = pytest.mark.pty

H, W = 32, 48
BLACK, WHITE = (512, 512, 512, 512), 16383
#: the steps' LEDs: three distinct ones, so that each image's brightness names its LED
LEDS = (3, 20, 40)


def level(led: int | None) -> float:
    return 0.0 if led is None else 0.3 + 0.01 * led


def dome_with_thermal(tmp_path: Path, max_duty: float = 0.3) -> Path:
    """The shipped emulated dome with the DSLR example's thermal limits (max_on_s = 8 s) and
    exposure (1/8 s, a shutter speed the body offers)."""
    text = (CONFIGS / "emulated_dome.toml").read_text()
    assert "[camera]" in text and "settle_s = 0.1\n" in text and "readout_s = 0.3\n" in text
    assert "exposure_s = 0.05\n" in text
    text = text.replace("exposure_s = 0.05\n", "exposure_s = 0.125\n")
    text = text.replace('"example_dome_48.lp"', f'"{(CONFIGS / "example_dome_48.lp").as_posix()}"')
    text = text.replace(
        "[camera]", f"[dome.serial.thermal]\nmax_on_s = 8.0\nmax_duty = {max_duty}\n\n[camera]", 1
    )
    return write_config(tmp_path, text, "dome.toml")


def dslr_rig(
    tmp_path: Path, max_duty: float = 0.3, brightness: float = 1.0, **settings: object
) -> tuple[Rig, Body, list]:
    """The emulated dome with a gphoto2 DSLR on the fake module; returns the rig, the body
    and the list of what the firmware had lit at each shot the body took."""
    rig = build_rig(load_rig_config(dome_with_thermal(tmp_path, max_duty)))
    firmware = rig.emulator  # type: ignore[attr-defined]
    lit_at_shots: list = []

    def render(body: Body) -> bytes:
        lit = firmware.lit
        lit_at_shots.append(None if lit is None else lit[0])
        # as bright as the LED and the shutter make it (x brightness: 1 at 1/8 s)
        secs = parse_shutter(body.config["shutterspeed"]) or 0.125
        value = level(None if lit is None else lit[0]) * brightness * secs / 0.125
        rgb = np.full((H, W, 3), min(value, 1.5))
        return dng(mosaic_from_rgb(rgb, "RGGB", BLACK, WHITE), "RGGB", BLACK, WHITE)

    body = Body(render=render, busy_clock=rig.clock, clock=rig.clock)
    camera = Gphoto2Camera(
        Gphoto2CameraSettings(image_format="RAW", **settings),  # type: ignore[arg-type]
        output_dir=tmp_path / "staging",
        clock=rig.clock,
        gp_module=make_module(body),
    )
    rig.camera = camera
    return rig, body, lit_at_shots


def schedule_of(rig: Rig) -> LightSchedule:
    dirs = rig.geometry.directions
    steps = tuple(LightStep(tuple(float(x) for x in dirs[i]), led=i) for i in LEDS)
    return LightSchedule(steps, method="test")


def journal(out: Path) -> list[dict]:
    return [json.loads(x) for x in (out / "journal.jsonl").read_text().splitlines() if x]


def test_a_camera_busy_past_max_on_s_is_awaited_in_the_dark_and_shot_relit(tmp_path):
    """A body busy 10 s after each shot, retried after 1, 2, 4, 4… s: the LED is lit 7.1 s,
    switched off (acknowledged), dark 4 s, lit again, and the image taken under it. Until
    2026-11-29 the LED stayed lit through every retry and the session stopped at the thermal
    guard ("LED 20 stayed on 11.2 s, beyond max_on_s = 8 s")."""
    rig, body, lit_at_shots = dslr_rig(tmp_path, busy_retries=6, retry_delay_s=1.0)
    body.busy_for_s = 10.0
    out = tmp_path / "s"
    with rig:
        result = run_session(rig, schedule_of(rig), SessionFolder.create(out, len(LEDS)))
    assert result.finish_reason is FinishReason.COMPLETED, result.error
    # every shot the body took, it took under the step's own LED: none in the dark
    assert lit_at_shots == list(LEDS) and body.shots == 3
    entries = journal(out)
    assert entries[0]["relit"] == []  # the body was ready for the first image
    for e in entries[1:]:
        (relit,) = e["relit"]
        assert relit["off"] == "acknowledged"
        assert 7.0 <= relit["lit_s"] <= 8.0 - 0.125 - 0.3  # within max_on_s, less the shot
        assert relit["dark_s"] >= 4.0 and relit["camera_wait_s"] == 4.0
        assert relit["camera_busy_tries"] == 4
    for e in entries:
        tif = read_linear_tiff(out / e["linear_image"]) / 65535
        assert tif.mean() == pytest.approx(level(e["led"]), rel=1e-3)
    manifest = json.loads((out / "manifest.json").read_text())
    (note,) = [n for n in manifest["notices"] if "lit again" in n]
    assert note.endswith("[2 of 3 images]")
    # the firmware saw each busy step's LED lit, switched off and lit again: one LED at a time
    history = [(ev.what, ev.index) for ev in rig.emulator.history if ev.what in ("lit", "off")]  # type: ignore[attr-defined]
    assert history == [
        ("lit", 3),
        ("off", 3),
        ("lit", 20),
        ("off", 20),
        ("lit", 20),
        ("off", 20),
        ("lit", 40),
        ("off", 40),
        ("lit", 40),
        ("off", 40),
    ]


def test_a_camera_that_never_comes_back_stops_the_session_after_its_retries_lights_off(
    tmp_path,
):
    """The wait is bounded by the camera's retries (1 + 2 + 4 + 4 s here), lit or not: then the
    session stops, resumable, with the images before kept and every LED off."""
    rig, body, lit_at_shots = dslr_rig(tmp_path, busy_retries=4, retry_delay_s=1.0)
    body.busy_for_s = 1e9
    out = tmp_path / "s"
    with rig, pytest.raises(CaptureError, match=r"after 5 attempts over 11 s.*busy_retries"):
        run_session(rig, schedule_of(rig), SessionFolder.create(out, len(LEDS)))
    manifest = json.loads((out / "manifest.json").read_text())
    assert manifest["runner"]["finish_reason"] == "error"
    assert [e["index"] for e in journal(out)] == [0]
    assert lit_at_shots == [3] and body.shots == 1
    assert rig.emulator.lit is None  # type: ignore[attr-defined]


def test_metering_a_busy_camera_waits_in_the_dark_never_past_max_on_s(tmp_path):
    """``run --auto-exposure``'s test shots at three lights, on the body busy 9 s after each:
    each shot is awaited as a session's image is, the LED off while the camera's next try
    would keep it lit past max_on_s. The retries had all been made with the LED lit, and
    metering stopped at the thermal guard before the session began ("LED 20 stayed on
    11.1 s, beyond max_on_s = 8 s")."""
    rig, body, lit_at_shots = dslr_rig(tmp_path, busy_retries=6, retry_delay_s=1.0)
    body.busy_for_s = 9.0
    rule = ExposureRule(headroom=1.25, min_exposure_s=1 / 250, max_exposure_s=1.0)

    def meter(camera, start_s):  # type: ignore[no-untyped-def]
        return meter_exposure(camera, rule, start_s, camera.available_exposures_s())

    def recheck(camera, exposure_s):  # type: ignore[no-untyped-def]
        choice, tested = recheck_exposure(camera, rule, exposure_s, camera.available_exposures_s())
        return Recheck(tested, choice)

    with rig:
        fixed = fix_session_exposure(rig, schedule_of(rig), meter, recheck, probes=3)
    evidence = fixed.provenance["exposure"]
    order = [LEDS[i - 1] for i in evidence["lights_metered_at_steps"]]  # brightest first
    assert sorted(order) == sorted(LEDS)
    # every test shot was taken under a lit LED of the metered lights, none in the dark
    assert body.shots == evidence["metering_shots"] == len(lit_at_shots) >= 3
    assert None not in lit_at_shots and set(lit_at_shots) == set(LEDS)
    # the body was busy at the second and third lights metered: lit, off, lit again
    lit_count = {led: 0 for led in LEDS}
    for ev in rig.emulator.history:  # type: ignore[attr-defined]
        if ev.what == "lit":
            lit_count[ev.index] += 1
    assert lit_count[order[0]] == 1 and min(lit_count[led] for led in order[1:]) >= 2
    assert rig.emulator.lit is None  # type: ignore[attr-defined]


def test_the_user_is_told_when_the_led_goes_off_and_how_long_it_must_cool(tmp_path):
    """At max_duty = 0.2 an LED lit 7.1 s may light again only once that on-time has mostly
    left the 60 s duty window: the wait in the dark is the camera's 4 s and some 56 s of
    cool-down, which the message says as the LED goes off (it had said only "4 s")."""
    rig, body, _ = dslr_rig(tmp_path, max_duty=0.2, busy_retries=6, retry_delay_s=1.0)
    body.busy_for_s = 10.0
    events: list[LightOffForCamera] = []

    def on_event(event) -> None:  # type: ignore[no-untyped-def]
        if isinstance(event, LightOffForCamera):
            events.append(event)

    out = tmp_path / "s"
    with rig:
        run_session(rig, schedule_of(rig), SessionFolder.create(out, len(LEDS)), on_event=on_event)
    second = journal(out)[1]
    (relit,) = second["relit"]
    first = events[0]
    assert (first.index, first.led, first.off) == (1, LEDS[1], "acknowledged")
    assert first.wait_s == 4.0 and first.max_on_s == 8.0
    assert first.cool_s > 50.0
    assert relit["dark_s"] == pytest.approx(first.wait_s + first.cool_s, abs=0.5)
    said = _light_off_for_camera(first)
    assert "in 4 s, would keep LED 20 (lit 7.1 s) on past max_on_s = 8 s" in said
    assert "switched off, acknowledged by the dome" in said
    assert f"and {first.cool_s:.1f} s more for its duty limit (max_duty)" in said


def test_metering_a_bright_object_downloads_each_test_shot_with_the_led_off(tmp_path):
    """A bright object: the 1/8 s preview clips, so the series at the brightest light takes
    three shots, each downloaded for 3 s. Each test shot is taken as a session's image is:
    the LED off once the exposure is over, the download in the dark, the LED lit again for
    the next shot. The series had been shot under one lighting, every download lit, and
    metering stopped at the thermal guard ("LED 40 stayed on 9.3 s, beyond max_on_s = 8 s")."""
    rig, body, lit_at_shots = dslr_rig(tmp_path, brightness=30.0)
    body.download_s, body.download_clock = 3.0, rig.clock
    rule = ExposureRule(headroom=1.25, min_exposure_s=1 / 250, max_exposure_s=1.0)

    def meter(camera, start_s):  # type: ignore[no-untyped-def]
        return meter_exposure(camera, rule, start_s, camera.available_exposures_s())

    with rig:
        fixed = fix_session_exposure(rig, schedule_of(rig), meter)
    evidence = fixed.provenance["exposure"]
    led = LEDS[evidence["metered_at_step"] - 1]
    assert len(evidence["test_exposures_s"]) >= 3  # a series at one light
    assert lit_at_shots == [led] * body.shots  # every shot under its LED
    log = [(e.what, e.index) for e in rig.emulator.history if e.what in ("lit", "off")]  # type: ignore[attr-defined]
    assert log == [("lit", led), ("off", led)] * body.shots
    assert fixed.steps[0].exposure_s < 0.125 / 10


def test_metering_a_dark_object_chooses_no_exposure_longer_than_an_led_may_stay_lit(tmp_path):
    """A dark object under the emulated dome (max_on_s = 8 s, settle 0.1 s, readout 0.3 s):
    the metering may choose no exposure longer than 7.6 s, so the body's 2 s, not its 30 s,
    with a note that names max_on_s. It had chosen the camera's max_exposure_s = 30 s and shot
    it with the LED lit 30 s ("LED 40 stayed on 30.2 s, beyond max_on_s = 8 s")."""
    from rti_rig.app.usecases.session import fix_exposure

    rig, _, lit_at_shots = dslr_rig(tmp_path, brightness=0.004)
    notes: list[str] = []
    with rig:
        fixed = fix_exposure(rig, schedule_of(rig), 0.001, on_note=lambda n: notes.append(n.text))
    assert {s.exposure_s for s in fixed.steps} == {2.0}
    assert None not in lit_at_shots
    said = " ".join(notes)
    assert "The exposure, 2 s, is the longest the metering could choose" in said
    assert "leaves 7.6 s ([dome.serial.thermal] max_on_s = 8 s" in said
    assert "not the camera's max_exposure_s = 30 s" in said


def _run_cancellable(rig, out, cancel, on_event):  # type: ignore[no-untyped-def]
    """The session of ``rig``'s schedule into ``out``, with ``cancel`` and ``on_event``."""
    with rig:
        return run_session(
            rig,
            schedule_of(rig),
            SessionFolder.create(out, len(LEDS)),
            cancel=cancel,
            on_event=on_event,
        )


def test_a_cancel_while_the_camera_is_awaited_in_the_dark_stops_there_its_led_left_off(
    tmp_path,
):
    """Ctrl-C (the run's cancel) as the LED goes off for a busy camera, at max_duty = 0.2: the
    wait ahead is the camera's 4 s and some 56 s of cool-down. The run had waited it all, lit
    the LED again and taken the shot before stopping; it now stops there, the LED left off,
    the step not recorded (a resume takes it), and says so."""
    from rti_rig.runtime.controller import CancelToken

    rig, body, lit_at_shots = dslr_rig(tmp_path, max_duty=0.2, busy_retries=6, retry_delay_s=1.0)
    body.busy_for_s = 10.0
    cancel = CancelToken()
    dark: list[LightOffForCamera] = []

    def on_event(event) -> None:  # type: ignore[no-untyped-def]
        if isinstance(event, LightOffForCamera):
            dark.append(event)
            cancel.cancel()  # what the Ctrl-C handler does

    out = tmp_path / "s"
    result = _run_cancellable(rig, out, cancel, on_event)
    assert result.finish_reason is FinishReason.CANCELLED, result.error
    (event,) = dark
    assert event.index == 1 and event.cool_s > 50.0
    # one picture, the first step's; the second step's LED lit once, switched off, never again
    assert lit_at_shots == [LEDS[0]] and body.shots == 1
    history = [(ev.what, ev.index) for ev in rig.emulator.history if ev.what in ("lit", "off")]  # type: ignore[attr-defined]
    assert history == [("lit", LEDS[0]), ("off", LEDS[0]), ("lit", LEDS[1]), ("off", LEDS[1])]
    assert rig.emulator.lit is None  # type: ignore[attr-defined]
    assert [e["index"] for e in journal(out)] == [0]
    (note,) = result.notes
    assert note.startswith("image 2 was not taken: the run was cancelled while its camera")
    manifest = json.loads((out / "manifest.json").read_text())
    assert manifest["runner"]["finish_reason"] == "cancelled"


def test_a_cancel_during_the_cool_down_before_a_relight_stops_there(tmp_path):
    """The cancel comes after the camera's wait, in the cool-down the duty limit asks before
    the LED may light again (the thermal guard had waited it inside the relight, deaf to it)."""
    from rti_rig.runtime.controller import CancelToken

    rig, body, lit_at_shots = dslr_rig(tmp_path, max_duty=0.2, busy_retries=6, retry_delay_s=1.0)
    body.busy_for_s = 10.0
    cancel = CancelToken()
    dark: list[float] = []
    clock = rig.clock
    real_sleep = clock.sleep

    def sleep(seconds: float) -> None:
        real_sleep(seconds)
        # 10 s of rig time into the dark: past the camera's 4 s, inside the cool-down
        if dark and clock.now() > dark[0] + 10.0:
            cancel.cancel()

    clock.sleep = sleep  # type: ignore[method-assign]

    def on_event(event) -> None:  # type: ignore[no-untyped-def]
        if isinstance(event, LightOffForCamera):
            dark.append(clock.now())

    out = tmp_path / "s"
    result = _run_cancellable(rig, out, cancel, on_event)
    assert result.finish_reason is FinishReason.CANCELLED
    assert lit_at_shots == [LEDS[0]] and body.shots == 1
    lit = [ev.index for ev in rig.emulator.history if ev.what == "lit"]  # type: ignore[attr-defined]
    assert lit == [LEDS[0], LEDS[1]]  # never lit again for the abandoned step
    assert clock.now() < dark[0] + 10.0 + 1.0  # stopped within a poll of the cancel, not ~56 s
    assert [e["index"] for e in journal(out)] == [0]


def test_a_camera_that_never_comes_back_is_said_to_have_been_tried_for_as_long_as_it_was(
    tmp_path,
):
    """At max_duty = 0.2 the relight waits some 56 s of cool-down: the camera's five tries
    span about a minute, of which 11 s are the waits between them. The error had said "after
    5 attempts over 11 s" of a stop a minute after the first try."""
    import re

    rig, body, _ = dslr_rig(tmp_path, max_duty=0.2, busy_retries=4, retry_delay_s=1.0)
    body.busy_for_s = 1e9
    out = tmp_path / "s"
    with rig, pytest.raises(CaptureError) as e:
        run_session(rig, schedule_of(rig), SessionFolder.create(out, len(LEDS)))
    said = str(e.value)
    m = re.search(r"after 5 attempts over (\d+) s \(11 s of them the waits between tries\)", said)
    assert m is not None, said
    assert 60 <= int(m.group(1)) <= 70  # 7.1 s lit, 4 s dark, ~56 s cool-down, the settle
