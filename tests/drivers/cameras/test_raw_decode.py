"""RAW decoding: DNGs written by the test itself, read back as linear data (no camera files)."""

from __future__ import annotations

import io

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from rti_rig.core.errors import CaptureError
from rti_rig.drivers.cameras.dng_writer import dng_bytes, linear_to_mosaic, write_dng
from rti_rig.drivers.cameras.raw_decode import (
    DamagedRawError,
    RawDecodeError,
    average_frames,
    decode_raw,
    exposure_stats,
    libraw_printed,
    subtract_dark,
)
from rti_rig.drivers.cameras.settings import RawDecodeSettings

BLACK, WHITE = 512, 16383  # a 14-bit sensor with a black pedestal


MOSAIC = RawDecodeSettings(mode="mosaic")


def random_mosaic(seed: int = 0, shape: tuple[int, int] = (48, 64)) -> np.ndarray:
    rng = np.random.default_rng(seed)
    return rng.integers(BLACK, WHITE, shape, endpoint=False).astype(np.uint16)


def patch_mosaic(levels: list[float], width: int = 8, height: int = 32) -> np.ndarray:
    """Vertical stripes, each a uniform fraction of full scale (above black)."""
    cols = [np.full((height, width), lv) for lv in levels]
    return linear_to_mosaic(np.hstack(cols), "RGGB", BLACK, WHITE)


def test_mosaic_mode_is_bit_exact_from_file(tmp_path):
    mosaic = random_mosaic()
    path = write_dng(
        tmp_path / "r.dng",
        mosaic,
        black_level=BLACK,
        white_level=WHITE,
        exposure_s=1 / 125,
        iso=200,
    )
    frame = decode_raw(path, MOSAIC)
    assert frame.pixels.dtype == np.uint16
    assert frame.pixels.shape == mosaic.shape
    np.testing.assert_array_equal(frame.pixels, mosaic.astype(np.int64) - BLACK)
    assert frame.white_level == WHITE - BLACK
    assert frame.exposure_s == pytest.approx(1 / 125, rel=1e-6)
    assert frame.gain == 200.0
    assert frame.metadata["cfa_pattern"] == "RGGB"
    assert frame.metadata["source_file"] == str(path)
    assert frame.metadata["raw_black_level"] == [BLACK] * 4
    assert frame.saturated_fraction == 0.0


def test_per_channel_black_levels_are_removed_per_photosite():
    mosaic = random_mosaic(4)
    blacks = (500, 510, 520, 530)  # R, G (row 0), G (row 1), B
    f = decode_raw(dng_bytes(mosaic, black_level=blacks, white_level=WHITE), MOSAIC)
    per_site = np.tile(np.array(blacks).reshape(2, 2), (24, 32))
    np.testing.assert_array_equal(
        f.pixels, np.clip(mosaic.astype(np.int64) - per_site, 0, WHITE - 530)
    )
    assert f.white_level == WHITE - 530
    assert sorted(f.metadata["raw_black_level"]) == sorted(blacks)


def test_bytes_and_file_decode_identically(tmp_path):
    mosaic = random_mosaic(3)
    data = dng_bytes(mosaic, black_level=BLACK, white_level=WHITE)
    (tmp_path / "a.dng").write_bytes(data)
    a = decode_raw(data, MOSAIC)
    b = decode_raw(tmp_path / "a.dng", MOSAIC)
    np.testing.assert_array_equal(a.pixels, b.pixels)
    assert a.metadata["source_file"] is None


@pytest.mark.parametrize("mode", ["half", "demosaic"])
def test_postprocess_modes_are_linear_and_never_rescaled(mode):
    # The brightest patch is 0.9 of white: LibRaw's default adjust_maximum_thr=0.75 would
    # rescale it to 1.0 (LibRaw's adjust_maximum_thr); the decode must keep it at 0.9.
    levels = [0.01, 0.1, 0.25, 0.5, 0.75, 0.9]
    frame = decode_raw(
        dng_bytes(patch_mosaic(levels), black_level=BLACK, white_level=WHITE),
        RawDecodeSettings(mode=mode),
    )
    assert frame.white_level == 65535
    assert frame.pixels.ndim == 3 and frame.pixels.shape[2] == 3
    step = 4 if mode == "half" else 8
    for i, lv in enumerate(levels):
        centre = frame.pixels[frame.pixels.shape[0] // 2, i * step + step // 2] / 65535
        np.testing.assert_allclose(centre, lv, atol=2e-4)


def test_unity_white_balance_keeps_channel_ratios_camera_wb_changes_them():
    mosaic = patch_mosaic([0.4, 0.4, 0.4])
    data = dng_bytes(mosaic, black_level=BLACK, white_level=WHITE, as_shot_neutral=(0.5, 1.0, 0.8))
    unity = decode_raw(data, RawDecodeSettings(mode="half", white_balance="unity"))
    cam = decode_raw(data, RawDecodeSettings(mode="half", white_balance="camera"))
    px = unity.pixels[8, 2].astype(float)
    assert px[0] == pytest.approx(px[1], rel=1e-3) == pytest.approx(px[2], rel=1e-3)
    cpx = cam.pixels[8, 2].astype(float)
    assert cpx[0] / cpx[1] == pytest.approx(2.0, rel=0.02)  # 1 / 0.5 for red
    assert cpx[2] / cpx[1] == pytest.approx(1.25, rel=0.02)  # 1 / 0.8 for blue


@pytest.mark.parametrize("mode", ["half", "demosaic"])
@pytest.mark.parametrize("pattern", ["RGGB", "BGGR", "GRBG", "GBRG"])
def test_cfa_pattern_places_colours_where_the_decoder_expects_them(pattern, mode):
    h, w = 24, 24
    rgb = np.zeros((h, w, 3))
    rgb[..., 0], rgb[..., 1], rgb[..., 2] = 0.2, 0.5, 0.8
    frame = decode_raw(
        dng_bytes(
            linear_to_mosaic(rgb, pattern, BLACK, WHITE),
            cfa_pattern=pattern,
            black_level=BLACK,
            white_level=WHITE,
        ),
        RawDecodeSettings(mode=mode),
    )
    assert frame.metadata["cfa_pattern"] == pattern
    np.testing.assert_allclose(frame.pixels[5, 5] / 65535, [0.2, 0.5, 0.8], atol=2e-4)


def test_saturation_detected_on_raw_and_pinned_through_processing():
    mosaic = patch_mosaic([0.3, 1.5], width=16)  # second stripe clips at the white level
    data = dng_bytes(mosaic, black_level=BLACK, white_level=WHITE)
    m = decode_raw(data, MOSAIC)
    assert m.saturated_fraction == pytest.approx(0.5)
    assert m.metadata["saturated_fraction"] == pytest.approx(0.5)
    h = decode_raw(data, RawDecodeSettings(mode="half"))
    assert np.all(h.pixels[:, 8:] == 65535)
    assert np.all(h.pixels[:, :8] < 65535)
    d = decode_raw(data, RawDecodeSettings(mode="demosaic"))
    assert d.saturated_fraction >= 0.5  # the 3×3 dilation marks the border pixels too


def test_saturation_level_below_nominal_white():
    mosaic = patch_mosaic([0.3, 0.97], width=16)
    data = dng_bytes(mosaic, black_level=BLACK, white_level=WHITE)
    assert decode_raw(data, MOSAIC).saturated_fraction == 0.0
    f = decode_raw(data, RawDecodeSettings(mode="mosaic", saturation_level=0.95))
    assert f.saturated_fraction == pytest.approx(0.5)
    assert np.all(f.pixels[:, 16:] == f.white_level)


def test_underexposure_fraction():
    mosaic = patch_mosaic([0.0, 0.0005, 0.5, 0.5])
    f = decode_raw(dng_bytes(mosaic, black_level=BLACK, white_level=WHITE), MOSAIC)
    assert f.metadata["underexposed_fraction"] == pytest.approx(0.5)
    assert exposure_stats(f.pixels, f.white_level, 0.0)["underexposed_fraction"] == 0.25


def test_dark_subtraction_keeps_saturated_pixels_flagged(tmp_path):
    rng = np.random.default_rng(7)
    scene = np.hstack([np.full((32, 16), 0.4), np.full((32, 16), 2.0)])
    dark_lin = rng.uniform(0.0, 0.01, size=scene.shape)
    light = linear_to_mosaic(scene + dark_lin, "RGGB", BLACK, WHITE)
    dark = linear_to_mosaic(dark_lin, "RGGB", BLACK, WHITE)
    write_dng(tmp_path / "dark.dng", dark, black_level=BLACK, white_level=WHITE, exposure_s=0.5)
    dark_frame = decode_raw(tmp_path / "dark.dng", MOSAIC)
    img = decode_raw(
        dng_bytes(light, black_level=BLACK, white_level=WHITE, exposure_s=0.5),
        MOSAIC,
        dark=dark_frame,
    )
    assert img.metadata["dark_subtracted"] is True
    assert img.metadata["dark_file"] == str(tmp_path / "dark.dng")
    expected = light[:, :16].astype(np.int64) - dark[:, :16].astype(np.int64)
    np.testing.assert_array_equal(img.pixels[:, :16], expected)
    assert np.all(img.pixels[:, 16:] == img.white_level)
    assert img.saturated_fraction == pytest.approx(0.5)


def test_dark_with_other_exposure_or_shape_is_refused():
    a = decode_raw(
        dng_bytes(random_mosaic(1), black_level=BLACK, white_level=WHITE, exposure_s=0.5), MOSAIC
    )
    b = decode_raw(
        dng_bytes(random_mosaic(2), black_level=BLACK, white_level=WHITE, exposure_s=0.25), MOSAIC
    )
    with pytest.raises(CaptureError, match="exposure"):
        subtract_dark(a, b)
    c = decode_raw(
        dng_bytes(random_mosaic(2, (48, 48)), black_level=BLACK, white_level=WHITE), MOSAIC
    )
    with pytest.raises(CaptureError, match="shape"):
        subtract_dark(a, c)


def test_average_frames_is_a_rounded_mean():
    a = decode_raw(dng_bytes(random_mosaic(1), black_level=BLACK, white_level=WHITE), MOSAIC)
    b = decode_raw(dng_bytes(random_mosaic(2), black_level=BLACK, white_level=WHITE), MOSAIC)
    m = average_frames([a, b])
    want = np.rint((a.pixels.astype(float) + b.pixels) / 2).astype(np.uint16)
    np.testing.assert_array_equal(m.pixels, want)


def test_unreadable_and_missing_files_name_the_file(tmp_path):
    bad = tmp_path / "broken.dng"
    bad.write_bytes(b"not a raw file at all" * 10)
    with pytest.raises(CaptureError, match=r"broken\.dng"):
        decode_raw(bad, MOSAIC)
    with pytest.raises(CaptureError, match="not found"):
        decode_raw(tmp_path / "missing.dng", MOSAIC)


@pytest.mark.parametrize("head", [b"II*\x00\x08\x00", b"MM\x00*\x00"])
def test_a_file_cut_inside_its_tiff_header_is_refused_naming_it(tmp_path, head):
    """LibRaw calls it unsupported, and the DNG tag reader asked of it had raised
    struct.error (a traceback, not a refusal naming the file)."""
    cut = tmp_path / "cut.dng"
    cut.write_bytes(head)
    with pytest.raises(CaptureError, match=r"cut\.dng"):
        decode_raw(cut, MOSAIC)


@pytest.mark.parametrize("source", ["file", "bytes"])
def test_libraws_own_line_about_a_cut_file_is_kept_off_the_terminal_and_said_in_the_refusal(
    tmp_path, capfd, source
):
    """LibRaw prints "<the file it read>: Unexpected end of file" straight to the C stderr
    (fd 2) for a RAW cut short: a watched folder's session copy (``raw/.incoming/...``)
    reached the terminal beside rti-rig's own refusal. It is held off fd 2 and its words
    carried into the refusal, which names the file only through its fields."""
    whole = tmp_path / "whole.dng"
    mosaic = linear_to_mosaic(np.full((32, 32), 0.3), "RGGB", 256, 4095)
    write_dng(whole, mosaic, black_level=256, white_level=4095)
    cut = tmp_path / "cut.dng"
    cut.write_bytes(whole.read_bytes()[: whole.stat().st_size // 2])
    capfd.readouterr()
    with pytest.raises(RawDecodeError) as info:
        decode_raw(cut if source == "file" else cut.read_bytes(), MOSAIC)
    err = capfd.readouterr().err
    assert "Unexpected end of file" not in err and "cut.dng" not in err, err
    assert info.value.libraw_printed == ("Unexpected end of file",)
    assert "LibRaw reports unexpected end of file; is it a complete" in info.value.problem


def test_libraws_line_about_a_file_it_decodes_anyway_is_kept_with_the_image(
    tmp_path, capfd, monkeypatch
):
    """LibRaw's data-error handler prints "<file>: data corrupted at <offset>" and goes on
    decoding (its default callback): the line is kept with the image (a notice, the decode
    record) rather than on the terminal, where it had named the file LibRaw read."""
    import os

    import rawpy

    real = rawpy.imread
    path = write_dng(
        tmp_path / "IMG_0001.dng",
        linear_to_mosaic(np.full((32, 32), 0.3), "RGGB", 256, 4095),
        black_level=256,
        white_level=4095,
    )

    def corrupt_noted(source, *args, **kwargs):  # LibRaw's callback, as its C code prints it
        os.write(2, f"{source}: data corrupted at 4096\n".encode())
        return real(source, *args, **kwargs)

    monkeypatch.setattr(rawpy, "imread", corrupt_noted)
    capfd.readouterr()
    frame = decode_raw(path, MOSAIC)
    assert capfd.readouterr().err == ""
    assert frame.metadata["decode"]["libraw_reported"] == ["data corrupted at 4096"]
    assert any(
        "LibRaw reported data corrupted at 4096 while decoding this file" in n
        for n in frame.metadata["notices"]
    )


def test_lines_not_libraws_written_to_fd_2_meanwhile_are_written_back(capfd):
    """fd 2 is the process's: another thread's line written while LibRaw reads is held back
    for the read, never lost; fd 2 is the terminal's again afterwards."""
    import os

    printed: list[str] = []
    capfd.readouterr()
    with libraw_printed("/s/raw/.incoming/IMG_1.dng", printed):
        os.write(2, b"/s/raw/.incoming/IMG_1.dng: data corrupted at 1024\n")
        os.write(2, b"another thread's warning\n")
    os.write(2, b"after\n")
    assert printed == ["data corrupted at 1024"]
    assert capfd.readouterr().err == "another thread's warning\nafter\n"


def test_a_signal_landing_as_fd_2_is_given_back_still_gives_it_back(capfd, monkeypatch):
    """A Ctrl-C (the signal's handler raising) landing in the flush made just before fd 2 is
    given back had skipped the restore: fd 2 stayed on the deleted sink for good, and every
    later line (the run's error, its teardown) was lost. The signal goes through; fd 2 is the
    terminal's again."""
    import os
    import signal
    import sys

    class StderrWhereTheSignalLands:
        """``sys.stderr``: its second flush, the one before the restore, takes a SIGINT."""

        def __init__(self) -> None:
            self.flushes = 0

        def write(self, text: str) -> int:
            return len(text)

        def flush(self) -> None:
            self.flushes += 1
            if self.flushes == 2:
                signal.raise_signal(signal.SIGINT)

    def interrupted(signum, frame):  # Python's own Ctrl-C, whatever the runner installed
        raise KeyboardInterrupt

    before = os.fstat(2)
    previous = signal.signal(signal.SIGINT, interrupted)
    try:
        monkeypatch.setattr(sys, "stderr", StderrWhereTheSignalLands())
        with pytest.raises(KeyboardInterrupt), libraw_printed("/s/IMG_1.dng", []):
            os.write(2, b"/s/IMG_1.dng: Unexpected end of file\n")
    finally:
        signal.signal(signal.SIGINT, previous)
    after = os.fstat(2)
    assert (after.st_dev, after.st_ino) == (before.st_dev, before.st_ino)
    capfd.readouterr()
    os.write(2, b"after\n")
    assert capfd.readouterr().err == "after\n"


def test_dng_writer_validates_its_input():
    with pytest.raises(ValueError, match="at least 22"):
        dng_bytes(np.zeros((20, 20), np.uint16))
    with pytest.raises(ValueError, match="uint16"):
        dng_bytes(np.zeros((32, 32), np.float32))
    with pytest.raises(ValueError, match="even"):
        dng_bytes(np.zeros((33, 32), np.uint16))
    with pytest.raises(ValueError, match="black_level"):
        dng_bytes(np.zeros((32, 32), np.uint16), black_level=5000, white_level=4000)
    with pytest.raises(ValueError, match="cfa_pattern"):
        linear_to_mosaic(np.zeros((4, 4, 3)), "RGBW")


def test_linear_to_mosaic_clips_and_quantises():
    m = linear_to_mosaic(np.array([[0.0, 0.5], [1.0, 7.0]]), "RGGB", 100, 1100)
    np.testing.assert_array_equal(m, [[100, 600], [1100, 1100]])
    with pytest.raises(ValueError, match="NaN"):
        linear_to_mosaic(np.array([[np.nan, 0.0]]))


@settings(max_examples=25, deadline=None)
@given(
    h=st.integers(11, 40).map(lambda v: 2 * v),
    w=st.integers(11, 40).map(lambda v: 2 * v),
    black=st.integers(0, 4000),
    span=st.integers(100, 60000),
    pattern=st.sampled_from(["RGGB", "BGGR", "GRBG", "GBRG"]),
    seed=st.integers(0, 2**32 - 1),
)
def test_any_dng_round_trips_bit_exactly(h, w, black, span, pattern, seed):
    white = min(black + span, 65535)
    rng = np.random.default_rng(seed)
    mosaic = rng.integers(black, white, (h, w), endpoint=False).astype(np.uint16)
    f = decode_raw(
        dng_bytes(mosaic, cfa_pattern=pattern, black_level=black, white_level=white), MOSAIC
    )
    np.testing.assert_array_equal(f.pixels, mosaic.astype(np.int64) - black)
    assert f.white_level == white - black
    assert f.metadata["cfa_pattern"] == pattern


def test_half_size_saturation_mask_fits_odd_sensor_sizes():
    """An odd visible size (301×401) leaves an incomplete last super-pixel row and column: the
    mask must still map onto LibRaw's half-size output (it used to fail to reshape)."""
    from rti_rig.drivers.cameras.raw_decode import half_size_mask

    mask = np.zeros((301, 401), dtype=bool)
    mask[300, 400] = True  # the lone photosite of the last, incomplete super-pixel
    mask[0, 1] = True
    out = half_size_mask(mask, 151, 201)
    assert out.shape == (151, 201)
    assert out[150, 200] and out[0, 0]
    assert out.sum() == 2
    even = np.zeros((4, 6), dtype=bool)
    even[3, 5] = True
    np.testing.assert_array_equal(half_size_mask(even, 2, 3), [[0, 0, 0], [0, 0, 1]])


@pytest.mark.parametrize("mode", ["half", "demosaic"])
def test_unequal_black_levels_are_corrected_exactly_in_colour_modes(mode):
    # blacks 512/600/540/580 at white 4095: LibRaw's min-black scaling would be 2.6 % off
    blacks = (512, 600, 540, 580)
    rgb = np.broadcast_to(np.array([0.2, 0.5, 0.8]), (32, 48, 3))
    h_, w_ = rgb.shape[:2]
    raw = np.empty((h_, w_), np.uint16)
    codes = (0, 1, 1, 2)  # RGGB
    for k, (dy, dx) in enumerate(((0, 0), (0, 1), (1, 0), (1, 1))):
        raw[dy::2, dx::2] = np.rint(blacks[k] + rgb[dy::2, dx::2, codes[k]] * (4095 - blacks[k]))
    f = decode_raw(
        dng_bytes(raw, black_level=blacks, white_level=4095),
        RawDecodeSettings(mode=mode, white_balance="unity"),
    )
    inner = f.pixels[6:-6, 6:-6].reshape(-1, 3) / 65535
    np.testing.assert_allclose(inner, np.broadcast_to([0.2, 0.5, 0.8], inner.shape), rtol=1e-3)
    assert f.metadata["decode"]["black_level_per_channel"] == {
        "R": 512,
        "G": 600,
        "B": 580,
        "G2": 540,
    }


def test_srgb_from_camera_keeps_neutrals_and_is_identity_for_srgb_primaries():
    from rti_rig.drivers.cameras.raw_decode import XYZ_FROM_SRGB, srgb_from_camera

    assert srgb_from_camera(np.zeros((4, 3))) is None  # minimal DNG: no matrix, no conversion
    ident = srgb_from_camera(np.linalg.inv(XYZ_FROM_SRGB))
    np.testing.assert_allclose(ident, np.eye(3), atol=1e-9)
    rng = np.random.default_rng(3)
    cam_xyz = np.eye(3) + 0.2 * rng.standard_normal((3, 3))
    m = srgb_from_camera(cam_xyz)
    np.testing.assert_allclose(m @ np.ones(3), np.ones(3), atol=1e-9)  # white stays white


def test_orientation_is_recorded_not_applied_and_a_rotation_is_noticed():
    import tifffile

    buf = dng_bytes(random_mosaic(), black_level=BLACK, white_level=WHITE)
    # rewrite the file with an Orientation tag (6: rotate 90° CW to view)
    with tifffile.TiffFile(io.BytesIO(buf)) as tif:
        arr = tif.pages.first.asarray()
    upright = decode_raw(buf)
    assert upright.metadata["decode"]["orientation"]["camera_rotated"] is False
    assert upright.metadata["notices"] == []
    from dng_spec_writer import dng as spec_dng

    rotated = decode_raw(spec_dng(arr, "RGGB", (BLACK,) * 4, WHITE, orientation=6))
    o = rotated.metadata["decode"]["orientation"]
    assert o["orientation_tag"] == 6 and o["libraw_flip"] == 6 and o["applied"] is False
    assert rotated.pixels.shape[:2] == arr.shape  # not rotated
    assert "sensor orientation" in rotated.metadata["notices"][0]


def test_file_colour_matrix_takes_a_camera_back_to_srgb():
    """A camera whose primaries mix sRGB (camera = A · sRGB) and says so in ColorMatrix1
    (XYZ → camera = A · sRGB←XYZ, DNG 1.4 §6) decodes to the scene's sRGB values."""
    from dng_spec_writer import dng as spec_dng
    from dng_spec_writer import mosaic_from_rgb

    from rti_rig.drivers.cameras.raw_decode import XYZ_FROM_SRGB

    srgb = np.array([0.2, 0.5, 0.6])
    a = np.array([[0.7, 0.25, 0.05], [0.15, 0.75, 0.1], [0.05, 0.2, 0.75]])
    camera_rgb = np.broadcast_to(a @ srgb, (32, 48, 3))
    raw = mosaic_from_rgb(np.array(camera_rgb), "RGGB", (0, 0, 0, 0), 16383)
    data = spec_dng(raw, "RGGB", (0, 0, 0, 0), 16383, color_matrix=a @ np.linalg.inv(XYZ_FROM_SRGB))
    f = decode_raw(data)
    inner = f.pixels[4:-4, 4:-4].reshape(-1, 3) / 65535
    np.testing.assert_allclose(inner, np.broadcast_to(srgb, inner.shape), rtol=1e-3)
    assert f.metadata["decode"]["color_space"].startswith("linear sRGB")
    cam = decode_raw(data, RawDecodeSettings(output_color="raw"))
    np.testing.assert_allclose(cam.pixels[16, 24] / 65535, a @ srgb, rtol=1e-3)


def test_a_decode_reads_only_the_dngs_structure_of_its_own_accord(tmp_path, monkeypatch):
    """Whether a DNG's CFAPattern is lost is asked of every decode, and its tags had been read
    from the whole file read into memory (48 MB of a 24-MP DNG, per image): of a 12 MB DNG, at
    most one read buffer's worth is read through Python (LibRaw reads the file itself, in C),
    and the tags read are the file's, as a damaged copy of it shows."""
    from pathlib import Path

    from rti_rig.drivers.cameras.dng_tags import dng_refusal, read_dng_tags

    mosaic = linear_to_mosaic(np.full((2000, 3000), 0.3), "RGGB", BLACK, WHITE)
    path = write_dng(tmp_path / "big.dng", mosaic, black_level=BLACK, white_level=WHITE)
    size = path.stat().st_size
    assert size > 10_000_000
    read = [0]
    real_open = Path.open

    class Counted(io.RawIOBase):
        def __init__(self, raw):
            self.raw = raw

        def readable(self):
            return True

        def seekable(self):
            return True

        def seek(self, *args):
            return self.raw.seek(*args)

        def readinto(self, b):
            n = self.raw.readinto(b)
            read[0] += n or 0
            return n

        def fileno(self):
            return self.raw.fileno()

        def close(self):
            self.raw.close()
            super().close()

    def counted(self, mode="r", *args, **kwargs):
        if "b" in mode and not set("wax+") & set(mode):
            return io.BufferedReader(Counted(real_open(self, mode, buffering=0)))
        return real_open(self, mode, *args, **kwargs)

    monkeypatch.setattr(Path, "open", counted)
    frame = decode_raw(path, MOSAIC)
    assert frame.pixels.shape == mosaic.shape
    assert read[0] <= 16384, read[0]
    assert read_dng_tags(path).damage == []
    # its StripByteCounts said to run a byte past the file's end: read where the tag lies
    data = bytearray(path.read_bytes())
    monkeypatch.setattr(Path, "open", real_open)
    for n in range(int.from_bytes(data[8:10], "little")):
        at = 10 + 12 * n
        if int.from_bytes(data[at : at + 2], "little") == 279:
            data[at + 8 : at + 12] = (size + 1).to_bytes(4, "little")
    path.write_bytes(bytes(data))
    read[0] = 0
    monkeypatch.setattr(Path, "open", counted)
    assert "its main image's data runs past the end of the file" in dng_refusal(path)
    assert read[0] <= 16384, read[0]


def _tag_renumbered(data: bytes, tag: int) -> bytes:
    """``data`` (a little-endian DNG, IFD 0 at 8) with ``tag``'s number damaged (to 250)."""
    out = bytearray(data)
    for n in range(int.from_bytes(out[8:10], "little")):
        at = 10 + 12 * n
        if int.from_bytes(out[at : at + 2], "little") == tag:
            out[at : at + 2] = (250).to_bytes(2, "little")
            return bytes(out)
    raise AssertionError(f"no tag {tag}")


def test_a_dng_whose_strip_offsets_are_lost_is_refused_before_libraw_reads_it(tmp_path):
    """LibRaw decodes a DNG whose StripOffsets entry is lost without an error or a line
    printed, its pixels read from bytes that are not the picture's (shown here of LibRaw
    itself): it had gone into the session as that picture. It is refused, by name, before
    LibRaw reads it; a lost StripByteCounts alone, which LibRaw does without for an
    uncompressed strip, still decodes as the picture taken."""
    import rawpy

    mosaic = random_mosaic(3)
    whole = dng_bytes(mosaic, black_level=BLACK, white_level=WHITE)
    lost = tmp_path / "offsets_lost.dng"
    lost.write_bytes(_tag_renumbered(whole, 273))
    with rawpy.imread(str(lost)) as raw:  # what LibRaw makes of it: not the picture
        assert not np.array_equal(np.array(raw.raw_image_visible), mosaic)
    with pytest.raises(DamagedRawError) as info:
        decode_raw(lost, MOSAIC)
    assert "gives no StripOffsets or TileOffsets" in info.value.problem
    counts_lost = tmp_path / "counts_lost.dng"
    counts_lost.write_bytes(_tag_renumbered(whole, 279))
    frame = decode_raw(counts_lost, MOSAIC)
    np.testing.assert_array_equal(frame.pixels, mosaic.astype(np.int64) - BLACK)


def test_a_dng_whose_sub_ifds_name_an_offset_past_any_file_still_decodes(tmp_path):
    """A damaged SubIFDs entry of an 8-byte type (LONG8, which no classic TIFF has) naming an
    IFD at 0xFFFF_FFFF_FFFF_FFFF: the whole-file reader this one replaced skipped it, while the
    seeking one passed the offset to ``seek``, whose ValueError (not an OSError) ended the
    decode. It is no IFD, and the picture, whose own IFD is whole, decodes as taken."""
    import struct

    mosaic = random_mosaic(4)
    data = bytearray(dng_bytes(mosaic, black_level=BLACK, white_level=WHITE))
    end = len(data)
    data += b"\xff" * 8
    for n in range(int.from_bytes(data[8:10], "little")):
        at = 10 + 12 * n
        if int.from_bytes(data[at : at + 2], "little") == 305:  # Software: not needed
            struct.pack_into("<HHII", data, at, 330, 16, 1, end)
            break
    else:
        raise AssertionError("no Software tag")
    path = tmp_path / "sub_ifds_garbage.dng"
    path.write_bytes(bytes(data))
    frame = decode_raw(path, MOSAIC)
    np.testing.assert_array_equal(frame.pixels, mosaic.astype(np.int64) - BLACK)
