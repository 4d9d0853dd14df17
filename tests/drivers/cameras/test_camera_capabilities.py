"""The camera drivers declare the capabilities ``check`` and the controller ask of them by
type (``rti_rig.core.devices``): those had been probed with ``getattr`` by name, so a driver
method renamed or misspelt was skipped without a word (no test shot, no exposure judged, no
card listed), and the check passed what the session then failed."""

from __future__ import annotations

import pytest

from rti_rig.core.devices import (
    CardListingCamera,
    ConnectNotingCamera,
    ExposureJudgingCamera,
    ExposureRefusingCamera,
    ShutterSpeedCamera,
    TrialShotCamera,
)
from rti_rig.drivers.cameras.gphoto2_camera import Gphoto2Camera
from rti_rig.drivers.cameras.opencv_camera import OpenCvCamera


@pytest.mark.parametrize(
    ("driver", "has", "lacks"),
    [
        (
            Gphoto2Camera,
            [
                CardListingCamera,
                ConnectNotingCamera,
                ExposureJudgingCamera,
                ShutterSpeedCamera,
                TrialShotCamera,
            ],
            [ExposureRefusingCamera],
        ),
        (
            OpenCvCamera,
            # a test frame since 2026-12-05: check had passed 8-bit frames with no response
            [ExposureJudgingCamera, ExposureRefusingCamera, TrialShotCamera],
            [CardListingCamera, ConnectNotingCamera, ShutterSpeedCamera],
        ),
    ],
)
def test_each_driver_declares_the_capabilities_it_has(
    driver: type, has: list[type], lacks: list[type]
) -> None:
    assert [p.__name__ for p in has if not issubclass(driver, p)] == []
    assert [p.__name__ for p in lacks if issubclass(driver, p)] == []
