"""A ``[camera]`` exposure range that shares no exposure with ``[camera.device]``'s is refused
when the config loads, naming both keys and the file, before any device is opened.

The two ranges were compared only once the camera connected: ``rti-rig check`` opened the
dome's port and the camera (and failed there, or at the metering's start) for a config no
shot can come from, as every exposure is kept inside [camera]'s range and the camera refuses
any outside its own.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from conftest import at_key, said
from typer.testing import CliRunner

from rti_rig.app.config import load_rig_config
from rti_rig.cli import app

REPO = Path(__file__).resolve().parents[2]
SHIPPED = REPO / "rig_configs" / "example_dome_48.toml"
runner = CliRunner()


def _uvc_dome(tmp_path: Path, camera: dict[str, float], device: str) -> Path:
    """The shipped hardware dome (its .lp beside it) with a UVC camera: ``camera`` replaces
    its [camera] exposure keys, ``device`` is the [camera.device] table's extra lines."""
    text = SHIPPED.read_text(encoding="utf-8")
    shipped_range = "exposure_s = 0.125\nmin_exposure_s = 0.000125\nmax_exposure_s = 30.0\n"
    assert shipped_range in text
    lines = "".join(f"{key} = {value}\n" for key, value in camera.items())
    text = text.replace(shipped_range, lines)
    head, rest = text.split("[camera.device]\n", 1)
    text = f'{head}[camera.device]\nkind = "opencv"\ndevice = 0\n{device}\n'
    text += rest[rest.index("[timing]") :]
    (tmp_path / "example_dome_48.lp").write_bytes(
        (SHIPPED.parent / "example_dome_48.lp").read_bytes()
    )
    path = tmp_path / "rig.toml"
    path.write_text(text, encoding="utf-8")
    return path


def test_a_device_minimum_above_the_camera_maximum_is_refused_by_check(tmp_path: Path) -> None:
    cfg = _uvc_dome(
        tmp_path,
        {"exposure_s": 0.004, "min_exposure_s": 0.000125, "max_exposure_s": 0.005},
        "min_exposure_s = 0.01",
    )
    r = runner.invoke(app, ["check", str(cfg)])
    text = said(r)
    assert r.exit_code == 2, text
    assert (
        f"{at_key(cfg, 'camera.max_exposure_s')}: no exposure the camera takes lies between "
        in text
    )
    assert (
        "min_exposure_s = 0.01 s in [camera.device] and [camera] max_exposure_s = 0.005 s" in text
    )
    assert "lower the first or raise the second" in text, text
    assert "/dev/video0" not in text and "FAILED to connect" not in text, text  # nothing opened


def test_a_camera_minimum_above_the_devices_default_maximum_is_refused_by_run(
    tmp_path: Path,
) -> None:
    cfg = _uvc_dome(
        tmp_path, {"exposure_s": 3.0, "min_exposure_s": 3.0, "max_exposure_s": 30.0}, ""
    )
    out = tmp_path / "s"
    r = runner.invoke(app, ["run", str(cfg), "--out", str(out)])
    text = said(r)
    assert r.exit_code == 2, text
    assert f"{at_key(cfg, 'camera.min_exposure_s')}" in text, text
    assert (
        "between [camera] min_exposure_s = 3 s and max_exposure_s = 2 s in [camera.device] "
        "(its default)"
    ) in text, text
    assert not out.exists()  # refused before anything was written or opened


def test_ranges_that_meet_are_not_refused_at_load(tmp_path: Path) -> None:
    """Ranges that share one exposure load (no device is opened here: a check would try the
    dome's port and /dev/video0)."""
    cfg = _uvc_dome(
        tmp_path,
        {"exposure_s": 0.01, "min_exposure_s": 0.000125, "max_exposure_s": 0.01},
        "min_exposure_s = 0.01",
    )
    assert load_rig_config(cfg).config.camera.max_exposure_s == 0.01


class _DeviceRangeCamera:
    """A connected camera that takes ``[low, high]`` (what the metering's start asks of it)."""

    name = "uvc-camera"

    def __init__(self, low: float, high: float) -> None:
        self.low, self.high = low, high

    def shortest_exposure_s(self) -> tuple[float, str]:
        return self.low, f"min_exposure_s = {self.low:g} s in [camera.device]"

    def longest_exposure_s(self) -> tuple[float, str]:
        return self.high, f"max_exposure_s = {self.high:g} s in [camera.device]"


@pytest.mark.parametrize(
    ("camera_range", "device_range", "shared"),
    [
        ((0.000125, 0.005), (0.01, 30.0), False),  # the device's shortest above [camera]'s longest
        ((3.0, 30.0), (1e-5, 2.0), False),  # [camera]'s shortest above the device's longest
        ((0.000125, 0.01), (0.01, 30.0), True),  # they meet in one exposure
        ((0.01, 30.0), (1e-5, 0.01 * (1 - 1e-12)), True),  # they meet, apart in the last bits
        ((0.001, 0.5), (0.0001, 0.01), True),  # one inside the other
    ],
)
def test_the_config_check_and_the_metering_start_judge_the_ranges_alike(
    tmp_path: Path,
    camera_range: tuple[float, float],
    device_range: tuple[float, float],
    shared: bool,
) -> None:
    """What the config refuses at load, the metering's start refuses once the camera says the
    same range, and what loads, it starts within: one judgement
    (:func:`rti_rig.core.exposure_range.shared_range`), not two comparisons that could
    disagree at an edge."""
    from rti_rig.core.errors import ConfigError, DeviceError
    from rti_rig.runtime.exposure_policy import metering_start

    low, high = camera_range
    cfg = _uvc_dome(
        tmp_path,
        {"exposure_s": low, "min_exposure_s": low, "max_exposure_s": high},
        f"min_exposure_s = {device_range[0]!r}\nmax_exposure_s = {device_range[1]!r}",
    )
    try:
        load_rig_config(cfg)
        loads = True
    except ConfigError:
        loads = False
    within = ((low, "[camera] min_exposure_s"), (high, "[camera] max_exposure_s"))
    try:
        metering_start(_DeviceRangeCamera(*device_range), low, within)
        starts = True
    except DeviceError:
        starts = False
    assert loads == starts == shared, (loads, starts)
