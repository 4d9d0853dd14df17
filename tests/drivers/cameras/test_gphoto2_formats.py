"""The image-format names libgphoto2 publishes (camlibs/ptp2/config.c), judged for a RAW."""

from __future__ import annotations

import pytest

from rti_rig.drivers.cameras.gphoto2_formats import gives_raw, raw_choices

RAW = [
    "RAW",
    "mRAW",
    "sRAW",
    "cRAW",
    "RAW + Large Fine JPEG",
    "mRAW + Small Normal JPEG",
    "NEF (Raw)",
    "NEF+Basic",
    "NEF+Fine",
    "RAW + JPEG Fine",
    "RAW+JPEG",
]
NOT_RAW = [
    "Large Fine JPEG",
    "Medium Normal JPEG",
    "S1 Fine JPEG",
    "Smaller JPEG",
    "JPEG Basic",
    "JPEG Fine",
    "TIFF (RGB)",
    "Standard",
    "Fine",
    "Extra Fine",
]
#: names that say nothing of a RAW: judged by no rule, never guessed
UNKNOWN = ["Unknown value 0007", "Quality 3", "L", "Fine Plus"]


@pytest.mark.parametrize("name", RAW)
def test_names_of_a_raw_give_raw(name):
    assert gives_raw(name) is True


@pytest.mark.parametrize("name", NOT_RAW)
def test_jpeg_only_names_give_none(name):
    assert gives_raw(name) is False


@pytest.mark.parametrize("name", UNKNOWN)
def test_other_names_are_not_judged(name):
    assert gives_raw(name) is None


def test_raw_choices_keep_the_camera_s_order():
    offered = ["JPEG Fine", "NEF (Raw)", "Unknown value 0007", "NEF+Fine"]
    assert raw_choices(offered) == ["NEF (Raw)", "NEF+Fine"]
