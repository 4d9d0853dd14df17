"""`rti-rig run` with a UVC camera, through the real stack from the rig config (the dome's
firmware emulated on a pty, the camera a stream that converts frames as OpenCV's V4L2 backend
does: tests/fake_uvc.py): a grey camera's frames are written as grey, a 16-bit one's at its
16 bits, never as 8-bit sRGB colour. The fake stream had ignored ``CAP_PROP_CONVERT_RGB``, so
a driver that left OpenCV converting a Y16 stream to 8-bit BGR would have passed unseen."""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np
import pytest
import tifffile
from conftest import shipped_dome_on_pty
from fake_uvc import BufferedUvcStream, LightHistory
from test_camera_uvc_stream import _uvc_dome_config
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.core.clock import SystemClock


def _shot(
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    pixel_format: str,
    device: str,
    opencv_4_11: bool = False,
):
    """``run --lights 2`` with a UVC camera offering only ``pixel_format`` (as OpenCV 4.11.0
    hands it over, with ``opencv_4_11``); ``device`` is added to its [camera.device] table.
    The CLI's result, its output on one line, the session folder and the stream."""
    cfg = _uvc_dome_config(tmp_path, max_on_s=1.5)
    text = cfg.read_text().replace('kind = "opencv"\n', f'kind = "opencv"\n{device}')
    cfg.write_text(text)
    stream = BufferedUvcStream(
        LightHistory(SystemClock()),  # type: ignore[arg-type]  # the session's own clock
        fps=20.0,
        scale=6e5,  # 0.05 s under light 1: 30000 of 65535, well inside the range
        pixel_format=pixel_format,
        opencv_4_11=opencv_4_11,
    )
    out = tmp_path / "s"
    monkeypatch.setattr(cv2, "VideoCapture", lambda device, api: stream)
    with shipped_dome_on_pty(monkeypatch, cfg):
        stream.light.set(1.0)  # constant: the frames need a value to carry, not a light
        r = CliRunner().invoke(app, ["run", str(cfg), "--out", str(out), "--lights", "2"])
    return r, " ".join(r.output.split()), out, stream


def _run(tmp_path: Path, monkeypatch: pytest.MonkeyPatch, pixel_format: str, device: str):
    """Two lights shot with a UVC camera offering only ``pixel_format`` (:func:`_shot`): the
    session's linear TIFFs, and the stream."""
    r, said, out, stream = _shot(tmp_path, monkeypatch, pixel_format, device)
    assert r.exit_code == 0 and "Traceback" not in said, said
    frames = [tifffile.imread(p) for p in sorted((out / "linear").glob("*.tif"))]
    assert len(frames) == 2, said
    return frames, stream


@pytest.mark.pty
def test_a_y16_camera_is_written_as_16_bit_grey(tmp_path, monkeypatch) -> None:
    frames, stream = _run(tmp_path, monkeypatch, "Y16 ", 'fourcc = "Y16 "\n')
    assert stream.props[cv2.CAP_PROP_CONVERT_RGB] == 0  # OpenCV told to hand over Y16 as is
    for pixels in frames:
        assert pixels.dtype == np.uint16 and pixels.ndim == 2, pixels.shape  # grey
        # the camera's 16 bits, not its high byte scaled back up (8-bit data read as sRGB)
        assert np.any(pixels % 256 != 0), pixels


@pytest.mark.pty
def test_a_grey_8_bit_camera_is_written_as_grey(tmp_path, monkeypatch) -> None:
    frames, _ = _run(tmp_path, monkeypatch, "GREY", 'fourcc = "GREY"\nresponse = "srgb"\n')
    for pixels in frames:
        assert pixels.ndim == 2, pixels.shape  # one channel, as the camera sent it


@pytest.mark.pty
def test_a_yuyv_camera_is_written_as_colour_from_srgb(tmp_path, monkeypatch) -> None:
    frames, _ = _run(tmp_path, monkeypatch, "YUYV", 'fourcc = "YUYV"\nresponse = "srgb"\n')
    for pixels in frames:
        assert pixels.ndim == 3 and pixels.shape[2] == 3, pixels.shape


@pytest.mark.pty
@pytest.mark.parametrize(
    ("pixel_format", "device"),
    [("Y16 ", 'fourcc = "Y16 "\n'), ("GREY", 'fourcc = "GREY"\nresponse = "srgb"\n')],
)
def test_opencv_4_11s_flat_row_is_refused_naming_the_release(
    tmp_path, monkeypatch, pixel_format: str, device: str
) -> None:
    """OpenCV 4.11.0 hands an unconverted Y16 or GREY frame over as one row of its bytes
    (opencv/opencv#27166): taken as an image, a 4×8 Y16 frame was a 64×1 8-bit one, written
    into the session. Refused at the first frame, naming the bug and the release that fixes
    it; nothing is written."""
    r, said, out, _ = _shot(tmp_path, monkeypatch, pixel_format, device, opencv_4_11=True)
    assert r.exit_code != 0 and "Traceback" not in said, said
    assert "as one flat row" in said and "not as its 4×8 pixels" in said, said
    assert "opencv/opencv#27166, fixed in 4.12.0" in said, said
    assert "opencv-contrib-python-headless>=4.12" in said, said
    assert not list(out.glob("linear/*")), said  # no flat row kept as an image


def test_the_dependency_excludes_opencv_4_11_0() -> None:
    """The OpenCV release that flattens Y16 and GREY frames (opencv/opencv#27166: 4.11.0,
    whose one wheel is 4.11.0.86) is not installable with rti-rig; the release that fixes it
    (4.12.0, opencv/opencv#27193) and those before it are."""
    import tomllib

    from packaging.requirements import Requirement

    project = Path(__file__).resolve().parents[3] / "pyproject.toml"
    deps = tomllib.loads(project.read_text())["project"]["dependencies"]
    (req,) = [
        Requirement(d) for d in deps if Requirement(d).name == "opencv-contrib-python-headless"
    ]
    assert "4.11.0.86" not in req.specifier, req
    for allowed in ("4.8.0.76", "4.10.0.84", "4.12.0.88", "5.0.0.93"):
        assert allowed in req.specifier, (req, allowed)


@pytest.mark.pty
def test_a_refused_pixel_format_is_answered_with_settings_the_config_can_hold(
    tmp_path, monkeypatch
) -> None:
    """A camera without Y16 (the default fourcc) is refused at connect with what to set. The
    advice had been "set fourcc = null", which TOML cannot write: omitting the key is "Y16 "
    again and "" is not four characters. The settings advised, written into [camera.device]
    as said, load and run."""
    import re
    import tomllib

    cfg = _uvc_dome_config(tmp_path, max_on_s=1.5)  # no fourcc: "Y16 " asked
    out = tmp_path / "s"

    def run():  # type: ignore[no-untyped-def]
        stream = BufferedUvcStream(
            LightHistory(SystemClock()),  # type: ignore[arg-type]  # the session's own clock
            fps=20.0,
            scale=6e5,
            pixel_format="YUYV",
        )
        monkeypatch.setattr(cv2, "VideoCapture", lambda device, api: stream)
        with shipped_dome_on_pty(monkeypatch, cfg):
            stream.light.set(1.0)
            r = CliRunner().invoke(app, ["run", str(cfg), "--out", str(out), "--lights", "2"])
        return r, " ".join(r.output.split())

    r, said = run()
    assert r.exit_code != 0 and "Traceback" not in said, said
    assert "camera refused pixel format 'Y16 ' (delivers 'YUYV')" in said, said
    assert "null" not in said, said
    advice = said.split("and set fourcc to one it offers in [camera.device], or set ", 1)[1]
    advice = advice.split(" in [camera.device] to accept", 1)[0]
    keys = re.findall(r'(\w+) = ("[^"]*"|\w+)', advice)
    assert keys == [("fourcc", '"YUYV"'), ("response", '"srgb"')], advice
    table = "".join(f"{k} = {v}\n" for k, v in keys)  # [camera.device] edited as advised
    cfg.write_text(cfg.read_text().replace('kind = "opencv"\n', f'kind = "opencv"\n{table}'))
    device = tomllib.loads(cfg.read_text())["camera"]["device"]
    assert device["fourcc"] == "YUYV" and device["response"] == "srgb", device
    r, said = run()
    assert r.exit_code == 0 and "Traceback" not in said, said
    assert len(list((out / "linear").glob("*.tif"))) == 2, said


def test_the_fake_converts_y16_to_bgr_by_its_high_byte_as_cap_v4l_does() -> None:
    """OpenCV's ``convertToRgb`` (cap_v4l.cpp, 4.11-era source) makes a Y16 frame 8-bit by
    ``extractChannel(Mat(size, CV_8UC2), temp, 1)``: each little-endian sample's high byte,
    truncated. The fake had rounded (``convertTo(CV_8U, 1/256)``, an older source's), written
    from memory: 0x01FF came back as 2, where OpenCV gives 1."""
    stream = BufferedUvcStream(LightHistory(SystemClock()), pixel_format="Y16 ")  # type: ignore[arg-type]
    assert stream.get(cv2.CAP_PROP_CONVERT_RGB) == 1  # OpenCV's default: converted
    light16 = np.array([[0x01FF, 0x0280, 0xFFFF, 0x00FF]], np.uint16)
    bgr = stream._retrieve(light16)
    assert bgr.dtype == np.uint8 and bgr.shape == (1, 4, 3), bgr.shape
    assert bgr[..., 0].tolist() == [[1, 2, 255, 0]], bgr[..., 0]
    assert stream.set(cv2.CAP_PROP_CONVERT_RGB, 0)
    raw = stream._retrieve(light16)  # unconverted: the samples as sent, rows × cols
    assert raw.dtype == np.uint16 and raw.tolist() == light16.tolist()
