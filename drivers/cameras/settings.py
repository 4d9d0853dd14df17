"""Camera settings: one pydantic model per backend, plus the RAW-decode and exposure rules.

Why models and not loose dicts: the rig TOML is written by hand, and a misspelt key
(``exposure_unti_s``) must fail loudly at load time instead of silently leaving the camera in an
automatic mode. Every model therefore forbids extra keys and is frozen once validated.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Annotated, Literal

from pydantic import (
    BaseModel,
    ConfigDict,
    Field,
    ValidationError,
    field_validator,
    model_validator,
)

CfaPattern = Literal["RGGB", "BGGR", "GRBG", "GBRG"]


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class RawDecodeSettings(_Strict):
    """How a RAW file becomes linear data (see ``raw_decode.decode_raw`` and docs/cameras.md).

    ``mode``:
      * ``"demosaic"`` (default) – colour at full resolution: bilinear demosaic of the
        black-corrected photosites, white balance, camera → sRGB primaries (linear).
      * ``"half"`` – colour at half resolution: 2×2 super-pixels (R, mean of the two greens, B),
        no interpolation at all.
      * ``"mosaic"`` – the sensor values themselves, black removed, no demosaic, no white
        balance: bit-exact with the file, one colour per pixel (shape H×W). Labelled as such in
        the journal, the manifest and the TIFF; its JPEG is a grey checkerboard, not a picture.
    Black levels are removed per CFA site exactly (``(raw − black_c) / (white − black_c)``),
    never LibRaw's scaling by the lowest black level; nothing is rescaled to the data maximum,
    nothing is rotated (images stay in sensor orientation; the Orientation tag is recorded).
    ``white_balance``: ``"camera"`` (as shot; unity when the file has none), ``"unity"`` (raw
    channel ratios) or four multipliers (R, G, B, G2). ``output_color``: ``"srgb"`` (linear
    sRGB primaries through the file's colour matrix; camera RGB when the file has none, and
    recorded so) or ``"raw"`` (camera RGB).
    """

    mode: Literal["mosaic", "half", "demosaic"] = "demosaic"
    white_balance: Literal["unity", "camera"] | tuple[float, float, float, float] = "camera"

    @field_validator("white_balance", mode="before")
    @classmethod
    def _one_of_its_forms(cls, v: object) -> object:
        """A word it knows, or four numbers, said in one message. Why: pydantic's union said
        "Input should be 'unity' or 'camera'" under the key
        ``white_balance.literal['unity','camera']``, the four-number form not named."""
        ok = v in ("unity", "camera") or (
            isinstance(v, list | tuple)
            and len(v) == 4
            and all(isinstance(m, int | float) and not isinstance(m, bool) for m in v)
        )
        if not ok:
            raise ValueError(
                f'white_balance {v!r}: give "camera" (as shot), "unity" (the raw '
                "channels' own ratios) or four multipliers (R, G, B, G2) each above 0, such as "
                "[2.0, 1.0, 1.5, 1.0]"
            )
        return v

    @field_validator("white_balance")
    @classmethod
    def _positive_multipliers(cls, v: object) -> object:
        """Four multipliers, each a finite number above 0. Why: ``[-1, 1, 1, 1]`` had been
        taken, and the red channel recorded as a constant, in silence, as a good image;
        ``[0, 0, 0, 0]`` made every image black, with numpy's warnings."""
        if isinstance(v, tuple) and not all(math.isfinite(m) and m > 0 for m in v):
            raise ValueError(
                f"white_balance {list(v)}: give four multipliers (R, G, B, G2) each above 0, "
                'such as [2.0, 1.0, 1.5, 1.0], or "camera" (as shot) or "unity"'
            )
        return v

    output_color: Literal["raw", "srgb"] = "srgb"
    saturation_level: float = Field(
        1.0,
        gt=0.0,
        le=1.0,
        description="fraction of (white - black) at which a raw value counts as saturated; "
        "some sensors clip a little below their nominal white level",
    )
    underexposed_level: float = Field(
        0.001,
        ge=0.0,
        lt=1.0,
        description="pixels at or below this fraction of white count as underexposed",
    )


class ExposureRule(_Strict):
    """The rule that fixes a session's exposure (see ``exposure.choose_exposure``)."""

    max_saturated_fraction: float = Field(0.001, ge=0.0, lt=1.0)
    headroom: float = Field(
        1.0,
        ge=1.0,
        description="predict as if the scene were this much brighter (margin for lights "
        "brighter than the metered one)",
    )
    min_exposure_s: float = Field(1e-5, gt=0.0)
    max_exposure_s: float = Field(30.0, gt=0.0)
    max_attempts: int = Field(6, ge=1, description="test shots before giving up")

    @model_validator(mode="after")
    def _ordered(self) -> ExposureRule:
        if self.min_exposure_s > self.max_exposure_s:
            raise ValueError("min_exposure_s must not exceed max_exposure_s")
        return self


class OpenCvCameraSettings(_Strict):
    """A UVC camera through OpenCV's V4L2 backend (or an image sequence for dry runs and tests).

    ``backend = "images"`` opens ``device`` as an OpenCV image-sequence pattern
    (``frames/f_%03d.png``); no camera controls exist there, so exposure is recorded as requested
    but cannot be applied (``metadata["exposure_applied"] = False``).
    """

    kind: Literal["opencv"] = "opencv"
    name: str = "uvc-camera"
    backend: Literal["v4l2", "images"] = "v4l2"
    device: int | str = 0
    width: int | None = Field(None, gt=0)
    height: int | None = Field(None, gt=0)
    fourcc: str | None = Field(
        "Y16 ",
        description="pixel format to request; 'Y16 ' gives 16-bit grey frames, one the camera "
        "offers such as 'YUYV' or 'MJPG' 8-bit gamma-encoded ones (with response = 'srgb'); "
        "None (Python only: TOML has no null, and an omitted key is 'Y16 ') keeps the camera "
        "default",
    )
    require_fourcc: bool = Field(
        True, description="fail at connect if the camera refuses the requested fourcc"
    )
    exposure_unit_s: float = Field(
        100e-6, gt=0.0, description="seconds per CAP_PROP_EXPOSURE unit (V4L2 absolute: 100 µs)"
    )
    auto_exposure_manual: float = Field(
        1.0, description="CAP_PROP_AUTO_EXPOSURE value meaning manual (V4L2 menu: 1)"
    )
    auto_exposure_auto: float = Field(
        3.0, description="value meaning auto (aperture priority: 3), written first as a toggle"
    )
    toggle_auto_exposure: bool = Field(
        True, description="write auto then manual: some UVC drivers only latch manual that way"
    )
    gain: float | None = Field(None, description="CAP_PROP_GAIN to set and verify; None = leave")
    wb_temperature_k: int | None = Field(None, gt=0)
    buffer_size: int = Field(1, ge=1, description="CAP_PROP_BUFFERSIZE requested at connect")
    fps: float | None = Field(
        None,
        gt=0.0,
        description="CAP_PROP_FPS set and verified at connect; None = the camera's. In manual "
        "exposure a UVC camera keeps its frame rate and clamps a longer exposure to the frame "
        "period (its exposure still reads back as set): an exposure longer than 1/fps is "
        "refused, so lower fps for longer ones",
    )
    drain_frames: int | None = Field(
        None,
        ge=0,
        description="frames grabbed and discarded before each capture so the returned frame "
        "was exposed after the exposure was set (V4L2 queues several buffers); unset: the "
        "queued buffers and 3 fresh frames (at least 4) on v4l2, 0 on an image sequence (one "
        "file per capture)",
    )
    exposure_tolerance: float = Field(
        0.02, ge=0.0, description="relative mismatch allowed between set and read-back exposure"
    )
    min_exposure_s: float = Field(100e-6, gt=0.0)
    max_exposure_s: float = Field(2.0, gt=0.0)
    response: Literal["linear", "srgb"] | None = Field(
        None,
        description="how 8-bit frames map to linear data: 'linear' (scale only) or 'srgb' "
        "(inverse sRGB curve); unset, an 8-bit frame is refused (gamma-encoded on nearly every "
        "camera: taken as linear it biases every normal). 16-bit frames are always linear.",
    )
    black_level: int = Field(0, ge=0, description="code value subtracted from 16-bit frames")
    white_level: int = Field(65535, gt=0, le=65535, description="saturation code of 16-bit frames")

    @property
    def frames_to_drain(self) -> int:
        """``drain_frames``, or its default for the backend: 4 on v4l2 (V4L2 queues buffers
        filled before the exposure changed), 0 on an image sequence, where each file is one
        capture. Why: the image sequence had drained 4 files a capture too, so a dry run over
        one file per light used files 5, 10, … and ran out after a fifth of its lights."""
        if self.drain_frames is not None:
            return self.drain_frames
        return 4 if self.backend == "v4l2" else 0

    @field_validator("device")
    @classmethod
    def _device_index_or_path(cls, v: int | str) -> int | str:
        """A camera's index (0 for /dev/video0) or its path: an index below 0 names no device.
        Why: ``device = -1`` was taken at load and failed at connect as "cannot open
        /dev/video-1", a name no system has; OpenCV's own "any camera" meaning of -1 would
        open whichever camera came first, not the one the rig was set up with."""
        if isinstance(v, int) and not isinstance(v, bool) and v < 0:
            raise ValueError(
                f"device = {v} names no camera: give its index (0 for /dev/video0; "
                '`v4l2-ctl --list-devices` lists them) or its path, e.g. "/dev/video0"'
            )
        if isinstance(v, str) and not v.strip():
            raise ValueError(
                'device = "" names no camera: give its index (0 for /dev/video0) or its path'
            )
        if isinstance(v, str) and v.strip().lstrip("+-").isdigit():
            # OpenCV opens a text as a file or URL: "0" in quotes is no camera index
            raise ValueError(
                f'device = "{v}" is a number in quotes, which is read as a file name: write '
                "the camera's index without quotes (device = 0 for /dev/video0) or its path"
            )
        return v

    @field_validator("fourcc")
    @classmethod
    def _four_chars(cls, v: str | None) -> str | None:
        if v is not None and len(v) != 4:
            raise ValueError(f"fourcc must be exactly 4 characters (pad with spaces), got {v!r}")
        return v


class Gphoto2CameraSettings(_Strict):
    """A DSLR or mirrorless camera through python-gphoto2 (one session kept open).

    Config names differ between makers (Nikon: ``f-number``, Canon: ``aperture``); the defaults
    are the common ones and each can be overridden. Values are the camera's own strings
    (``iso = "100"``, ``aperture = "8"``); the shutter is chosen from the camera's list to match
    the requested ``exposure_s``.
    """

    kind: Literal["gphoto2"] = "gphoto2"
    name: str = "dslr"
    port: str | None = Field(None, description="e.g. 'usb:001,004'; None = the only camera found")
    iso: str | None = "100"
    aperture: str | None = None
    image_format: str | None = Field(
        None, description="camera's own value for RAW (or RAW+JPEG), e.g. 'RAW' or 'NEF (Raw)'"
    )
    keep_jpeg: bool = Field(False, description="download a JPEG delivered with the RAW")
    capture_target: str | None = Field(
        "Internal RAM", description="camera's own capturetarget value; None = leave"
    )
    shutter_config: str = "shutterspeed"
    iso_config: str = "iso"
    aperture_config: str = "aperture"
    image_format_config: str = "imageformat"
    shutter_tolerance: float = Field(
        0.06,
        ge=0.0,
        description="relative mismatch allowed between requested exposure and the "
        "nearest shutter speed the camera offers (1/3 stop is 0.26)",
    )
    busy_retries: int = Field(5, ge=0)
    retry_delay_s: float = Field(0.5, ge=0.0, description="first wait after a 'busy' reply")
    retry_backoff: float = Field(2.0, ge=1.0, description="each further wait is this much longer")
    retry_max_delay_s: float = Field(4.0, ge=0.0, description="longest wait between retries")
    retry_codes: tuple[int, ...] = Field(
        (-110,), description="GPhoto2Error codes retried: -110 = camera busy / not ready"
    )
    event_timeout_s: float = Field(
        5.0, gt=0.0, description="how long to wait for the remaining files of a RAW+JPEG shot"
    )
    delete_from_camera: bool = Field(
        True, description="delete each file on the camera after it is downloaded"
    )
    decode: RawDecodeSettings = RawDecodeSettings()

    @field_validator("iso", "aperture", "image_format", "capture_target", mode="before")
    @classmethod
    def _empty_is_leave(cls, v: object) -> object:
        """``""`` leaves the camera's own setting alone (what ``None`` means here).

        TOML has no null, so a rig config could not say "leave it": a body without a
        'capturetarget' setting (one libgphoto2 offers only on some makes) could not be used
        at all, the default "Internal RAM" being asked of it at every connect."""
        return None if v == "" else v


class FolderWatchSettings(_Strict):
    """A camera fired by someone else (the dome's shutter line, a vendor program).

    The driver waits for the next file matching ``patterns`` to appear in ``folder`` and be
    complete (size unchanged over ``stable_polls`` polls), with a timeout.
    """

    kind: Literal["folder_watch"] = "folder_watch"
    name: str = "folder-camera"
    folder: Path
    trigger: Literal["none", "dome_shutter"] = Field(
        "none",
        description="who fires the camera: 'none' (someone else: a vendor program, an "
        "intervalometer) or 'dome_shutter' (rti-rig pulses the dome's camera-release line, "
        "[dome.serial] shutter_pulse_ms long, once the LED is lit and settled)",
    )
    patterns: tuple[str, ...] = ("*.dng", "*.DNG")
    timeout_s: float = Field(10.0, gt=0.0)
    shutter_lag_s: float = Field(
        0.5,
        ge=0.0,
        le=10.0,
        description="with trigger = 'dome_shutter': the longest time from the release pulse "
        "to the start of the exposure (the camera's shutter lag, autofocus off). The LED stays "
        "lit this long plus the exposure after the pulse, then goes off while the file is "
        "awaited; set the camera's own shutter to [camera] exposure_s",
    )
    poll_interval_s: float = Field(0.05, gt=0.0)
    stable_polls: int = Field(2, ge=1)
    exposure_tolerance: float | None = Field(
        0.06,
        ge=0.0,
        description="relative mismatch allowed between requested exposure and the file's "
        "ExposureTime; None = do not check",
    )
    gain: float = Field(0.0, description="recorded in the frame when the file has no ISO")
    eight_bit_response: Literal["refuse", "linear", "srgb"] = Field(
        "refuse",
        description="8-bit files (JPEG, PNG) are gamma-encoded: refuse them, or "
        "linearise with the curve the file says (the sRGB curve, or Adobe RGB's or ProPhoto's "
        "where its profile or Exif says that space), or take them as linear. A file whose ICC "
        "profile's curve is linear (gamma 1.0) is taken as linear whatever this says",
    )
    decode: RawDecodeSettings = RawDecodeSettings()

    @field_validator("patterns")
    @classmethod
    def _some_pattern(cls, v: tuple[str, ...]) -> tuple[str, ...]:
        """At least one pattern, none empty. Why: ``patterns = []`` was taken, and the run
        then waited out its timeout for a file none could match, the dome lit."""
        if not v or any(not p.strip() for p in v):
            raise ValueError(
                'give the file patterns the camera\'s files match, such as ["*.CR2", '
                '"*.cr2"] (none, or an empty one, matches no file)'
            )
        return v

    @field_validator("folder")
    @classmethod
    def _home(cls, v: Path) -> Path:
        """``~/Pictures/...`` as a user writes it in a config shared between machines."""
        return v.expanduser()


CameraSettings = Annotated[
    OpenCvCameraSettings | Gphoto2CameraSettings | FolderWatchSettings,
    Field(discriminator="kind"),
]
"""Any real camera's settings, told apart by ``kind`` (``[camera] kind = "gphoto2"``)."""


def parse_camera_settings(data: dict[str, object]) -> BaseModel:
    """Validate a rig config's ``[camera.device]`` table into its kind's settings.

    The kind (``kind = "gphoto2"``) picks the settings model from the registry
    (:mod:`rti_rig.drivers.cameras.kinds`). Raises pydantic's ``ValidationError`` (the config
    loader turns it into a ConfigError that names the file and key).
    """
    from rti_rig.drivers.cameras.kinds import camera_kind, camera_kind_names

    kind = camera_kind(data.get("kind"))
    if kind is None:
        known = ", ".join(repr(k) for k in camera_kind_names())
        raise ValidationError.from_exception_data(
            "camera",
            [
                {
                    "type": "value_error",
                    "loc": ("kind",),
                    "input": data.get("kind"),
                    "ctx": {
                        "error": ValueError(
                            f"unknown camera kind; use one of {known}"
                            if "kind" in data
                            # absent, not unknown: said as the missing key it is
                            else f"required, and not given: add a line kind = … (one of {known})"
                        )
                    },
                }
            ],
        )
    return kind.settings.model_validate(data)
