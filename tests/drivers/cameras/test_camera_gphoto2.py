"""gphoto2 backend against a fake python-gphoto2 module (python-gphoto2 is not installed)."""

from __future__ import annotations

import json
import sys

import numpy as np
import pytest
from fake_gphoto2 import SHUTTERS, Body, make_module

from rti_rig.core.clock import VirtualClock
from rti_rig.core.devices import Camera
from rti_rig.core.errors import CameraBusyError, CaptureError, DeviceError
from rti_rig.drivers.cameras.dng_writer import dng_bytes, linear_to_mosaic
from rti_rig.drivers.cameras.gphoto2_camera import (
    Gphoto2Camera,
    load_gphoto2,
    nearest_shutter,
    parse_shutter,
)
from rti_rig.drivers.cameras.settings import Gphoto2CameraSettings

BLACK, WHITE = 512, 16383


def grey_card(body: Body) -> bytes:
    """A grey card of reflectance 0.25 at 1/60 s, linear in the body's exposure time."""
    secs = parse_shutter(body.config["shutterspeed"])
    level = 0.25 * secs * 60
    mosaic = linear_to_mosaic(np.full((32, 48), level), "RGGB", BLACK, WHITE)
    iso = body.config["iso"]
    return dng_bytes(
        mosaic,
        black_level=BLACK,
        white_level=WHITE,
        exposure_s=secs,
        iso=int(iso) if iso.isdigit() else None,
    )


def dslr(**kw) -> Body:
    """A Canon-like body on this fake bus: DNG RAWs, a CAPTURE_COMPLETE after each shot."""
    kw.setdefault("raw_suffix", ".DNG")
    kw.setdefault("capture_complete_event", True)
    kw.setdefault("port", "usb:001,004")
    choices = {
        "capturetarget": ["Internal RAM", "Memory card"],
        "imageformat": ["Large Fine JPEG", "RAW", "RAW + Large Fine JPEG"],
        "iso": ["Auto", "100", "200", "400"],
        "aperture": ["4", "5.6", "8"],
        "shutterspeed": SHUTTERS,
    }
    return Body(render=grey_card, choices=choices, **kw)


def camera(body, tmp_path, clock=None, **kw):
    kw.setdefault("image_format", "RAW")
    settings = Gphoto2CameraSettings(**kw)
    return Gphoto2Camera(
        settings, output_dir=tmp_path, clock=clock or VirtualClock(), gp_module=make_module(body)
    )


def test_connect_applies_settings_and_capture_downloads_and_decodes_raw(tmp_path):
    body = dslr()
    cam = camera(body, tmp_path, iso="100", aperture="8")
    assert isinstance(cam, Camera)
    cam.connect()
    assert body.config["capturetarget"] == "Internal RAM"
    assert body.config["imageformat"] == "RAW"
    assert body.config["iso"] == "100" and body.config["aperture"] == "8"
    assert 1 / 125 in cam.available_exposures_s() and 30.0 in cam.available_exposures_s()
    f = cam.capture(1 / 125)
    assert body.config["shutterspeed"] == "1/125"
    assert f.exposure_s == pytest.approx(1 / 125)
    assert f.gain == 100.0 and f.metadata["gain_unit"] == "iso"
    assert f.pixels.dtype == np.uint16 and f.pixels.shape == (32, 48, 3)  # colour by default
    # linear: 0.25 × (60/125) of full scale, black removed
    assert np.mean(f.pixels) / f.white_level == pytest.approx(0.25 * 60 / 125, abs=1e-4)
    src = tmp_path / "cap0001_IMG_0001.DNG"
    assert f.metadata["source_file"] == str(src) and src.exists()
    assert body.ram == {}  # nothing left on the camera
    assert f.metadata["shutter_label"] == "1/125"
    json.dumps(f.metadata)  # goes into the session manifest as is
    cam.close()
    cam.close()
    assert body.calls.count("exit") == 1


def test_one_session_and_shutter_set_only_when_it_changes(tmp_path):
    body = dslr()
    with camera(body, tmp_path) as cam:
        cam.capture(1 / 60)
        n_set = body.calls.count("set_config")
        cam.capture(1 / 60)
        assert body.calls.count("set_config") == n_set
        cam.capture(1 / 30)
        assert body.calls.count("set_config") == n_set + 1
    assert body.calls.count("init") == 1


def test_raw_plus_jpeg_collects_the_second_file_from_events(tmp_path):
    body = dslr()
    with camera(body, tmp_path, image_format="RAW + Large Fine JPEG", keep_jpeg=True) as cam:
        f = cam.capture(1 / 60)
    assert f.metadata["jpeg_file"] == str(tmp_path / "cap0001_IMG_0001.JPG")
    assert (tmp_path / "cap0001_IMG_0001.JPG").read_bytes().startswith(b"\xff\xd8")
    assert f.metadata["source_file"].endswith("IMG_0001.DNG")
    assert body.ram == {}


def test_file_announced_twice_is_downloaded_once(tmp_path):
    body = dslr(announce_first=True)
    with camera(body, tmp_path, image_format="RAW + Large Fine JPEG") as cam:
        f = cam.capture(1 / 60)
    assert f.metadata["camera_files"] == ["/IMG_0001.DNG", "/IMG_0001.JPG"]
    assert body.calls.count("file_get") == 1  # the JPEG is not kept by default
    assert f.metadata["jpeg_file"] is None


def test_jpeg_only_camera_is_an_error_naming_the_setting(tmp_path):
    """A format libgphoto2 names JPEG-only is refused at connect, before any shot; one whose
    name cannot be judged is refused at the shot that gives no RAW."""
    body = dslr()
    with pytest.raises(DeviceError, match=r"gives JPEG only.*\['RAW', 'RAW \+ Large Fine JPEG'\]"):
        camera(body, tmp_path, image_format=None).connect()
    assert body.shots == 0
    body.config["imageformat"] = "Unknown value 0007"
    body.choices["imageformat"].append("Unknown value 0007")
    body.format_gives = {"Unknown value 0007": (False, True)}
    with (
        camera(body, tmp_path, image_format=None) as cam,
        pytest.raises(CaptureError, match="no RAW file"),
    ):
        cam.capture(1 / 60)


def test_busy_is_retried_on_the_injected_clock(tmp_path):
    body = dslr(failures={"capture": [-110, -110]})
    clock = VirtualClock()
    with camera(body, tmp_path, clock=clock, retry_delay_s=0.5) as cam:
        f = cam.capture(1 / 60)
    assert body.shots == 1 and cam.retries_used == 2
    assert clock.now() == pytest.approx(1.5)  # waits of 0.5 s then 1.0 s (backoff), none real
    assert f.timestamp_s == pytest.approx(0.0)
    assert f.metadata["capture_started_s"] == 0.0
    assert f.metadata["capture_finished_s"] == pytest.approx(1.5)


def test_busy_forever_gives_up_with_a_clear_error(tmp_path):
    body = dslr(failures={"capture": [-110] * 10})
    with (
        camera(body, tmp_path, busy_retries=3) as cam,
        pytest.raises(CaptureError, match=r"-110.*after 4 attempts.*busy"),
    ):
        cam.capture(1 / 60)


def test_busy_past_fire_by_is_handed_back_without_a_picture_and_counted_on(tmp_path):
    """A body writing to a slow card answers busy for 9 s after each shot. Told to fire
    within 1 s (its light may not stay lit longer), the camera waits 0.5 s, then hands the wait
    back (its next try is due in 1 s) having taken no picture; called again after that wait
    it goes on with the same tries and back-off, and fires once the body is ready."""
    clock = VirtualClock()
    body = dslr(busy_for_s=9.0, busy_clock=clock)
    with camera(body, tmp_path, clock=clock, busy_retries=6, retry_delay_s=0.5) as cam:
        cam.capture(1 / 60)  # the first shot: the body is busy for 9 s from now
        assert body.shots == 1
        with pytest.raises(CameraBusyError) as busy:
            cam.expose_within(1 / 60, fire_by=clock.now() + 1.0)
        assert busy.value.retry_in_s == pytest.approx(1.0) and busy.value.tries == 2
        assert clock.now() == pytest.approx(0.5)  # waited 0.5 s lit, not the 1 s past fire_by
        assert body.shots == 1  # no picture while busy
        waits, wait = [], busy.value.retry_in_s
        while True:  # the caller's dark waits, each followed by a try at once
            clock.sleep(wait)
            waits.append(wait)
            try:
                cam.expose_within(1 / 60, fire_by=clock.now() + 1.0)
                break
            except CameraBusyError as again:
                wait = again.retry_in_s
        assert waits == [1.0, 2.0, 4.0, 4.0]  # the back-off went on across the calls
        assert body.shots == 2 and clock.now() == pytest.approx(11.5)
        assert cam.collect().metadata["camera_files"] == ["/IMG_0002.DNG"]


def test_a_busy_answer_that_takes_time_is_counted_before_another_lit_try(tmp_path):
    """A body whose busy answer comes only after 1.5 s (a Canon whose autofocus fails): with
    3 s to fire in, a try after the 0.5 s wait would answer at 3.5 s, its light still lit past
    the time allowed; the wait is handed back at once instead (it had been tried, and the
    light kept lit until 3.5 s)."""
    clock = VirtualClock()
    body = dslr(failures={"capture": [-110] * 3}, busy_takes_s=1.5, busy_clock=clock)
    with camera(body, tmp_path, clock=clock, busy_retries=5, retry_delay_s=0.5) as cam:
        with pytest.raises(CameraBusyError) as busy:
            cam.expose_within(1 / 60, fire_by=3.0)
        assert clock.now() == pytest.approx(1.5) and busy.value.tries == 1
        assert busy.value.retry_in_s == 0.5


def test_busy_handed_back_still_ends_after_busy_retries(tmp_path):
    """The tries counted across ``expose_within`` calls end at busy_retries: a body that never
    comes back is an error that says how long it was awaited."""
    clock = VirtualClock()
    body = dslr(failures={"capture": [-110] * 20})
    with camera(body, tmp_path, clock=clock, busy_retries=3, retry_delay_s=1.0) as cam:
        for _ in range(3):
            with pytest.raises(CameraBusyError) as busy:
                cam.expose_within(1 / 60, fire_by=clock.now())
            clock.sleep(busy.value.retry_in_s)
        with pytest.raises(CaptureError, match=r"-110.*after 4 attempts over 7 s.*busy") as end:
            cam.expose_within(1 / 60, fire_by=clock.now())
        assert not isinstance(end.value, CameraBusyError)
        assert "busy_retries" in str(end.value) and body.shots == 0
        # a Canon body whose autofocus cannot lock answers busy every time (libgphoto2 #304,
        # pibooth #246): more retries would never help, manual focus does
        assert "autofocus could not lock" in str(end.value) and "MF" in str(end.value)
        # the next shot starts a new wait (the spell ended with the error)
        body.failures["capture"] = [-110]
        with pytest.raises(CameraBusyError) as busy:
            cam.expose_within(1 / 60, fire_by=clock.now())
        assert busy.value.tries == 1 and busy.value.retry_in_s == 1.0


def test_other_errors_are_not_retried(tmp_path):
    body = dslr(failures={"capture": [-7, -7]})
    with camera(body, tmp_path) as cam, pytest.raises(CaptureError, match="cable"):
        cam.capture(1 / 60)
    assert cam.retries_used == 0


def test_no_camera_found(tmp_path):
    with pytest.raises(DeviceError, match="found no camera"):
        camera(dslr(detected=[]), tmp_path).connect()


def test_usb_claimed_at_init_names_gvfs(tmp_path):
    with pytest.raises(DeviceError, match="gvfs"):
        camera(dslr(failures={"init": [-53]}), tmp_path).connect()


def test_missing_python_gphoto2_says_how_to_install(monkeypatch):
    monkeypatch.setitem(sys.modules, "gphoto2", None)  # makes `import gphoto2` fail
    with pytest.raises(DeviceError, match="pip install gphoto2"):
        load_gphoto2()
    cam = Gphoto2Camera(Gphoto2CameraSettings())
    with pytest.raises(DeviceError, match="pip install gphoto2"):
        cam.connect()


def test_several_cameras_need_a_port(tmp_path):
    body = dslr(detected=[("A", "usb:001,004"), ("B", "usb:001,005")])
    with pytest.raises(DeviceError) as refused:
        camera(body, tmp_path).connect()
    # each camera in words and the line that takes it, not a Python list of tuples
    said = str(refused.value)
    assert "2 cameras found: A on usb:001,004; B on usb:001,005" in said, said
    assert 'port = "usb:001,004" or port = "usb:001,005"' in said and "[(" not in said, said
    assert "same model" not in said
    twins = dslr(detected=[("A", "usb:001,004"), ("A", "usb:001,005")])
    with pytest.raises(DeviceError, match="same model: unplug one"):
        camera(twins, tmp_path).connect()
    with pytest.raises(DeviceError, match="no camera on port usb:002,001"):
        camera(body, tmp_path, port="usb:002,001").connect()


def test_port_chooses_one_of_several_cameras(tmp_path):
    body = dslr(detected=[("Nikon D750", "usb:001,004"), ("Canon EOS 600D", "usb:001,005")])
    with camera(body, tmp_path, port="usb:001,005") as cam:
        assert cam.camera_model == "Canon EOS 600D"
        cam.capture(1 / 60)
    assert "set_port_info usb:001,005" in body.calls
    assert "set_abilities Canon EOS 600D" in body.calls


def test_value_not_offered_and_value_not_latched(tmp_path):
    with pytest.raises(DeviceError, match=r"'12800' is not offered for iso.*'100'"):
        camera(dslr(), tmp_path, iso="12800").connect()
    body = dslr(read_only={"iso"})  # e.g. the mode dial is not on M
    cam = camera(body, tmp_path)
    with pytest.raises(DeviceError, match="manual"):
        cam.connect()
    assert body.calls.count("exit") == 1  # failed connect leaves the camera released


def test_exposure_not_offered_is_refused(tmp_path):
    """Refused naming the speeds either side and the config keys to change: it had said
    "choose one of available_exposures_s()", a Python method, to a CLI user."""
    with camera(dslr(), tmp_path) as cam, pytest.raises(CaptureError) as info:
        cam.capture(0.1)  # between 1/8 and 1/15
    said = str(info.value)
    assert "not a shutter speed this camera offers" in said
    assert "0.0666667 s ('1/15') or 0.125 s ('1/8')" in said
    assert "[camera] exposure_s" in said and "shutter_tolerance" in said
    assert "available_exposures_s" not in said


def test_no_timed_shutter_speed_names_the_key_its_section_and_what_to_do(tmp_path):
    """A body on Av/P or a wrong shutter_config offers no timed speed: the error names the
    config key and section and both remedies (it had asked "is the camera in manual (M)
    mode?" and named neither)."""
    body = dslr()
    body.choices["shutterspeed"] = ["bulb", "Auto"]
    body.config["shutterspeed"] = "Auto"
    with pytest.raises(DeviceError) as info:
        camera(body, tmp_path).connect()
    said = str(info.value)
    assert "'shutterspeed' (shutter_config in [camera.device]) offers no timed" in said, said
    assert "put the camera in manual (M) mode" in said, said
    assert "set shutter_config in [camera.device] to the name `gphoto2 --list-config`" in said


def test_a_shutter_speed_no_longer_offered_names_exposure_s_not_shutter_config(tmp_path):
    """The speeds are read at connect; a mode dial moved since takes one away. The error had
    said to set shutter_config (the key of the setting's *name*) to a speed."""
    body = dslr()
    with camera(body, tmp_path) as cam:
        body.choices["shutterspeed"] = [s for s in SHUTTERS if s != "1/8"]
        with pytest.raises(DeviceError) as info:
            cam.capture(0.125)
    said = str(info.value)
    assert "shutter speed '1/8' (chosen for [camera] exposure_s" in said, said
    assert "put the camera back in manual (M) mode" in said, said
    assert "set shutter_config" not in said, said


def test_unknown_config_name_points_to_list_config(tmp_path):
    with pytest.raises(DeviceError, match="list-config"):
        camera(dslr(), tmp_path, aperture="8", aperture_config="f-number").connect()


@pytest.mark.parametrize(
    ("setting", "key", "name_key"),
    [
        ("imageformat", "image_format", "image_format_config"),
        ("aperture", "aperture", "aperture_config"),
        ("iso", "iso", "iso_config"),
    ],
)
def test_a_missing_setting_names_the_key_that_holds_its_name(tmp_path, setting, key, name_key):
    """A body whose setting has another name (a Nikon's): the error had said "set
    'image_format' to this camera's name for it", the key of the value, not of the name."""
    body = dslr()
    del body.config[setting]
    with pytest.raises(DeviceError) as info:
        camera(body, tmp_path, iso="100", aperture="8").connect()
    said = str(info.value)
    assert f"camera has no setting '{setting}' (asked for by {key})" in said
    assert f"set {name_key} = " in said and f"set '{key}' to" not in said


@pytest.mark.parametrize(
    ("label", "secs"),
    [
        ("1/125", 1 / 125),
        ("0.3", 0.3),
        ("2.5s", 2.5),
        ('30"', 30.0),
        ("1/4000s", 1 / 4000),
        ("bulb", None),
        ("Auto", None),
        ("0", None),
    ],
)
def test_parse_shutter(label, secs):
    got = parse_shutter(label)
    assert got == (pytest.approx(secs) if secs is not None else None)


def test_nearest_shutter_in_stops():
    table = [(1 / 125, "1/125"), (1 / 60, "1/60"), (1 / 30, "1/30")]
    assert nearest_shutter(0.016, table)[1] == "1/60"
    assert nearest_shutter(0.03, table)[1] == "1/30"


def test_expose_returns_once_the_shot_is_taken_and_collect_downloads_it(tmp_path):
    """The download and the RAW decode (seconds for 24 megapixels) had happened inside one
    capture call, with the dome's LED lit: now ``expose`` ends at the shot, so the controller
    switches the light off before ``collect`` downloads it."""
    from rti_rig.core.devices import ExposingCamera

    body = dslr()
    with camera(body, tmp_path) as cam:
        assert isinstance(cam, ExposingCamera)
        ended = cam.expose(1 / 125)
        assert ended is not None
        assert "capture" in body.calls and "file_get" not in body.calls
        assert not list(tmp_path.glob("cap*"))
        f = cam.collect()
        assert body.calls.count("file_get") == 1 and f.exposure_s == pytest.approx(1 / 125)
        with pytest.raises(CaptureError, match=r"collect\(\) without expose"):
            cam.collect()  # one frame per exposure


def test_expose_ends_when_the_body_has_taken_the_picture(tmp_path):
    """libgphoto2's capture returns once the picture is taken, so a 1/2 s shot ends 1/2 s
    after it was fired, on the body's clock as on the rig's: the light may go off then and
    not before. (The fake body had answered at once, whatever the shutter: a test of the
    light against the exposure saw a 2 s shot end in no time.)"""
    clock = VirtualClock()
    body = dslr(clock=clock)
    with camera(body, tmp_path, clock=clock) as cam:
        ended = cam.expose(0.5)
        assert ended == pytest.approx(0.5) and clock.now() == pytest.approx(0.5)
        assert cam.collect().metadata["capture_started_s"] == 0.0


def test_a_body_without_capturetarget_can_be_left_alone_with_an_empty_value(tmp_path):
    """libgphoto2 offers 'capturetarget' on some makes only. The default "Internal RAM" was
    asked of such a body at every connect, and TOML has no null to say "leave it": the body
    could not be used at all. capture_target = "" now leaves the camera's own setting."""
    body = dslr()
    del body.config["capturetarget"]
    with pytest.raises(DeviceError) as info:
        camera(body, tmp_path).connect()
    assert 'in [camera.device] set capture_target = "" to leave it' in str(info.value)
    assert Gphoto2CameraSettings(capture_target="", iso="").capture_target is None
    with camera(body, tmp_path, capture_target="") as cam:
        frame = cam.capture(1 / 60)
    assert frame.metadata["camera_files"] == ["/store_00020001/DCIM/100CANON/IMG_0001.DNG"]
