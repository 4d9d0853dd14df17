"""What tethered-capture users hit, at python-gphoto2's API boundary (tests/fake_gphoto2.py).

Busy on the next shot, a camera switched off mid-session, a full card, a file counter that
wraps or repeats names, RAM vs card capture targets, RAW+JPEG delivered as two files.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from dng_spec_writer import dng, mosaic_from_rgb
from fake_gphoto2 import Body, make_module

from rti_rig.core.clock import VirtualClock
from rti_rig.core.devices import Frame
from rti_rig.core.errors import CaptureError
from rti_rig.drivers.cameras.gphoto2_camera import CameraGoneError, CardFullError, Gphoto2Camera
from rti_rig.drivers.cameras.settings import Gphoto2CameraSettings
from rti_rig.runtime.session import RAW_INCOMING, SessionFolder, prepare_resume


def render(body: Body | None = None) -> bytes:
    rgb = np.broadcast_to(np.array([0.2, 0.5, 0.8]), (32, 48, 3))
    return dng(mosaic_from_rgb(np.array(rgb), "RGGB", (0, 0, 0, 0), 4095), white=4095)


def camera(body: Body, out=None, clock=None, **kw) -> Gphoto2Camera:
    kw.setdefault("image_format", "RAW")
    return Gphoto2Camera(
        Gphoto2CameraSettings(**kw),
        output_dir=out,
        clock=clock or VirtualClock(),
        gp_module=make_module(body),
    )


def test_busy_on_the_second_capture_is_retried_with_backoff(tmp_path):
    body = Body(render=render, busy_after_shot=3)
    clock = VirtualClock()
    with camera(body, tmp_path, clock, retry_delay_s=0.25, retry_backoff=2.0) as cam:
        cam.capture(1 / 60)
        t0 = clock.now()
        cam.capture(1 / 60)
    assert body.shots == 2 and cam.retries_used == 3
    assert clock.now() - t0 == pytest.approx(0.25 + 0.5 + 1.0)  # doubling waits, none real


def test_backoff_is_capped(tmp_path):
    body = Body(render=render, failures={"capture": [-110] * 5})
    clock = VirtualClock()
    with camera(body, tmp_path, clock, retry_delay_s=1.0, retry_max_delay_s=2.0) as cam:
        cam.capture(1 / 60)
    assert clock.now() == pytest.approx(1 + 2 + 2 + 2 + 2)


def test_camera_switched_off_mid_session_is_a_named_error(tmp_path):
    body = Body(render=render)
    with camera(body, tmp_path) as cam:
        cam.capture(1 / 60)
        body.switch_off()
        with pytest.raises(
            CameraGoneError, match=r"stopped answering.*Reconnect it, then go on"
        ) as info:
            cam.capture(1 / 60)
    assert isinstance(info.value, CaptureError)  # exit code 2 through the CLI, no traceback


def test_full_card_is_named_with_what_to_do(tmp_path):
    body = Body(render=render, card_free_shots=1)
    with camera(body, tmp_path, capture_target="Memory card", delete_from_camera=False) as cam:
        cam.capture(1 / 60)
        with pytest.raises(CardFullError, match=r"card is full.*Internal RAM"):
            cam.capture(1 / 60)
    assert len(body.card) == 1  # the first shot is left on the card as asked


def test_card_target_deletes_after_download_ram_target_leaves_nothing(tmp_path):
    card = Body(render=render)
    with camera(card, tmp_path / "a", capture_target="Memory card") as cam:
        f = cam.capture(1 / 60)
    assert card.deleted == ["IMG_0001.CR2"] and not card.card
    assert f.metadata["camera_files"] == ["/store_00020001/DCIM/100CANON/IMG_0001.CR2"]
    ram = Body(render=render)
    with camera(ram, tmp_path / "b") as cam:
        f = cam.capture(1 / 60)
    assert ram.config["capturetarget"] == "Internal RAM" and not ram.ram
    assert f.metadata["camera_files"] == ["/IMG_0001.CR2"]


def test_wrapping_counter_never_overwrites_a_download(tmp_path):
    body = Body(render=render, counter_start=9999, counter_wrap=9999)
    (tmp_path / "cap0001_IMG_9999.CR2").write_bytes(b"left by an earlier run")
    with camera(body, tmp_path) as cam:
        a = cam.capture(1 / 60)
        b = cam.capture(1 / 60)
    assert [o["name"] for o in a.metadata["originals"] + b.metadata["originals"]] == [
        "/IMG_9999.CR2",
        "/IMG_0001.CR2",
    ]
    assert (tmp_path / "cap0001_IMG_9999.CR2").read_bytes() == b"left by an earlier run"
    assert a.metadata["originals"][0]["path"].endswith("cap0001_IMG_9999-2.CR2")


@pytest.mark.parametrize("jpeg_first", [False, True])
def test_raw_plus_jpeg_arriving_as_two_files_keeps_both(tmp_path, jpeg_first):
    body = Body(render=render, jpeg_first=jpeg_first)
    with camera(
        body, tmp_path / RAW_INCOMING, image_format="RAW + Large Fine JPEG", keep_jpeg=True
    ) as cam:
        folder = SessionFolder.create(tmp_path / "s", 1)
        folder.begin({"rig": {}, "schedule": {"steps": [{}]}})  # as the controller does
        cam.output_dir = folder.root / RAW_INCOMING
        f = cam.capture(1 / 60)
    assert f.pixels.ndim == 3  # decoded from the RAW, whichever came first
    names = sorted(o["name"] for o in f.metadata["originals"])
    assert names == ["/IMG_0001.CR2", "/IMG_0001.JPG"]
    rec = folder.write_step(0, f, _fields())
    assert rec.originals == {
        "raw/image_001.cr2": "/IMG_0001.CR2",
        "raw/image_001.jpg": "/IMG_0001.JPG",
    }
    assert (folder.root / "raw/image_001.jpg").read_bytes().startswith(b"\xff\xd8")
    assert set(rec.sha256) >= {"raw/image_001.cr2", "raw/image_001.jpg"}


def _fields() -> dict:
    return {
        "planned_direction": (0.0, 0.0, 1.0),
        "actual_direction": (0.0, 0.0, 1.0),
        "led": 0,
        "rig_start_s": 0.0,
        "light_s": 0.0,
        "settle_s": 0.0,
        "capture_s": 0.0,
    }


def _frame(path, name: str) -> Frame:
    return Frame(
        pixels=np.full((4, 4, 3), 1000, np.uint16),
        exposure_s=0.1,
        gain=100.0,
        white_level=65535,
        timestamp_s=0.0,
        metadata={"originals": [{"path": str(path), "name": name}], "decode": {"mode": "half"}},
    )


def test_resume_verifies_raw_originals_and_sets_aside_uncommitted_downloads(tmp_path):
    folder = SessionFolder.create(tmp_path / "s", 3)
    folder.begin({"rig": {}, "schedule": {"steps": [{}, {}, {}]}})
    incoming = folder.root / RAW_INCOMING
    incoming.mkdir(parents=True)
    for i in range(2):
        (incoming / f"cap{i}.CR2").write_bytes(f"raw {i}".encode())
        folder.write_step(i, _frame(incoming / f"cap{i}.CR2", f"/IMG_{i}.CR2"), _fields())
    (incoming / "cap2.CR2").write_bytes(b"downloaded, never committed")  # crash here
    (folder.root / "raw/image_002.cr2").write_bytes(b"tampered")  # and a damaged original
    state = prepare_resume(folder.root)
    assert sorted(state.done) == [0]  # step 2's RAW fails its checksum: it is taken again
    moved = sorted(p.split("/", 2)[2] for p in state.recovered)
    assert moved == [
        "image_002.jpg",
        "linear/image_002.tif",
        "raw/.incoming/cap2.CR2",
        "raw/image_002.cr2",
    ]
    assert not (folder.root / RAW_INCOMING / "cap2.CR2").exists()
    lines = [json.loads(x) for x in (folder.root / "journal.jsonl").read_text().splitlines()]
    assert lines[0]["originals"] == {"raw/image_001.cr2": "/IMG_0.CR2"}


def test_metering_shots_before_the_session_exists_go_to_a_private_folder(tmp_path):
    body = Body(render=render)
    with camera(body, None) as cam:
        f = cam.capture(1 / 60)
    staged = f.metadata["originals"][0]["path"]
    assert "rti-rig-dslr-" in staged and tmp_path.as_posix() not in staged
    # ... and go with the camera's close: a metered session had left each test shot's RAW in
    # the temporary directory for ever
    assert not Path(staged).parent.exists()


def test_mosaic_sessions_are_labelled_in_tiff_journal_and_manifest(tmp_path):
    import tifffile

    from rti_rig.drivers.cameras.raw_decode import decode_raw
    from rti_rig.drivers.cameras.settings import RawDecodeSettings

    src = tmp_path / "IMG_0001.DNG"
    src.write_bytes(render())
    f = decode_raw(src, RawDecodeSettings(mode="mosaic"))
    folder = SessionFolder.create(tmp_path / "s", 1)
    folder.begin({"rig": {}, "schedule": {"steps": [{}]}})
    rec = folder.write_step(0, f, _fields())
    assert rec.decode["content"] == "cfa-mosaic" and rec.decode["cfa_pattern"] == "RGGB"
    with tifffile.TiffFile(folder.root / rec.linear_image) as tif:
        assert "CFA mosaic (RGGB)" in tif.pages.first.description
    folder.finish([rec], {"finish_reason": "completed"}, {})
    manifest = json.loads((folder.root / "manifest.json").read_text())
    assert any("CFA mosaics" in n for n in manifest["notices"])
    assert manifest["steps"][0]["decode"]["mode"] == "mosaic"
    assert src.exists()  # a watched folder's file is copied, never taken away


def test_a_body_saving_at_the_root_is_not_taken_for_a_folder_made_since_connect(tmp_path):
    """A body left to its own target (no capture_target set) that keeps its shots in RAM,
    at "/": the connect's walk stores "/" as a folder there, but a busy spell compared "" (the
    root with its "/" stripped), took the root for a folder the body made since and every
    file in it for a picture the busy answer took: the owner's earlier one was downloaded as
    this session's stray. The root is the root."""
    body = Body(render=render)
    body.config["capturetarget"] = "Internal RAM"
    body.ram["capt9999.jpg"] = b"\xff\xd8 the owner's picture, still in the body's RAM"
    body.still_writing(1)  # the first shot comes after a busy answer: its folder is looked at
    with camera(body, tmp_path, capture_target=None) as cam:
        cam.list_card(lambda _: None)  # as a capture session does before its first shot
        frame = cam.capture(1 / 60)
    assert cam.retries_used == 1
    assert not frame.metadata.get("stray_files"), frame.metadata
    assert "capt9999.jpg" in body.ram


@pytest.mark.parametrize(
    "full, said",
    [
        (dict(folders=5, files=600, s_per_file=0.0), "after 8 folders, 2400 files, 0 s"),
        (dict(folders=2, files=300, s_per_file=0.13), "after 5 folders, 300 files, 39 s"),
    ],
    ids=["many-files", "slow-listing"],
)
def test_the_card_walk_before_a_session_is_said_and_bounded(tmp_path, full, said):
    """A full card on a body that lists slowly (a Nikon-type body fetches each file's info:
    gphoto2 issue #204, some 6 minutes for 2,700 files) had been walked at every connect,
    unsaid, bounded by its folders only. The walk now says it starts, and stops before
    another folder once 2,000 files are listed or 30 s spent, saying that the check before
    the first shot is off."""
    clock = VirtualClock()
    body = Body(render=render, list_s_per_file=full["s_per_file"], list_clock=clock)
    for n in range(full["folders"]):
        names = {f"DSC_{n * 1000 + i:04d}.NEF": b"" for i in range(full["files"])}
        body.older_folders[f"/store_00020001/DCIM/{100 + n}CANON"] = names
    body.card_folder = 100 + full["folders"]
    heard: list[str] = []
    with camera(body, tmp_path, clock, capture_target="Memory card") as cam:
        assert "folder_list_folders" not in body.calls  # not at connect
        cam.list_card(heard.append)
    assert "Listing the camera's card" in heard[0], heard
    assert len(heard) == 2 and said in heard[1] and "is off" in heard[1], heard
