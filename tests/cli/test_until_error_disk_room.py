"""``rti-rig run --until-error`` asks the disk for the images it is sure to take, not its most.

Without ``--lights`` an --until-error session stops at an unknown count (on simulated_dome
``--until-error 8``: after 4 of at most 48); the start-up check had asked room for all 48
(about 103 MB) and refused sessions that fit. It now asks for its starting lights (or
``--min-lights`` if larger), a resumed one for what is left of those, and the rest is checked
image by image. Where the count is known (``--lights N``) the whole is still asked for. Free
space is faked with ``shutil.disk_usage``.
"""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest
from conftest import CONFIGS, said
from typer.testing import CliRunner

from rti_rig.app.usecases.adaptive import images_sure
from rti_rig.cli import app
from rti_rig.runtime.session import estimated_bytes_per_image, steps_to_hold

runner = CliRunner()
CONFIG = str(CONFIGS / "simulated_dome.toml")  # 512 × 512, 48 LEDs; adaptive starts from 4


def _room_for(images: int) -> int:
    """Free bytes that hold ``images`` images of simulated_dome and not one more."""
    per = estimated_bytes_per_image(512, 512)
    return images * per + 8 * 1024 * 1024 + per // 2


def _free(monkeypatch: pytest.MonkeyPatch, free: int) -> None:
    real = shutil.disk_usage
    monkeypatch.setattr(shutil, "disk_usage", lambda p: real(p)._replace(free=free))


def test_images_sure_follows_what_the_session_knows() -> None:
    until = {"max_lights": 48, "until_error_deg": 8.0, "start_lights": 4, "design_lights": None}
    assert images_sure(until) == 4
    assert images_sure({**until, "min_lights": 6}) == 6
    assert images_sure({**until, "min_lights": 60}) == 48
    assert images_sure({**until, "max_lights": 10, "design_lights": 10}) == 10  # --lights 10
    assert images_sure({**until, "until_error_deg": None}) == 48  # --adaptive: its maximum
    assert steps_to_hold(48, 2, 4) == 2
    assert steps_to_hold(48, 5, 4) == 1  # past the sure ones: the next image
    assert steps_to_hold(48, 48, 4) == 0
    assert steps_to_hold(6, 2, 6) == 4


def test_until_error_without_lights_asks_room_for_its_starting_lights_only(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    _free(monkeypatch, _room_for(4))
    out = tmp_path / "s"
    r = runner.invoke(app, ["run", CONFIG, "--out", str(out), "--until-error", "8", "--no-verdict"])
    assert r.exit_code == 0, said(r)
    assert "not enough free disk space" not in said(r)
    assert len(list(out.glob("image_*.jpg"))) >= 4


@pytest.mark.parametrize(
    ("extra", "count"),
    [(["--min-lights", "6"], 6), (["--lights", "10"], 10)],
)
def test_until_error_with_a_known_count_asks_room_for_it(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, extra: list[str], count: int
) -> None:
    _free(monkeypatch, _room_for(4))
    out = tmp_path / "s"
    r = runner.invoke(
        app, ["run", CONFIG, "--out", str(out), "--until-error", "8", *extra, "--no-verdict"]
    )
    text = said(r)
    assert r.exit_code == 2, text
    assert f"not enough free disk space for {count} image(s)" in text, text
    assert "capturing" not in text and not out.exists(), text


def test_a_resumed_until_error_session_asks_room_for_the_rest_of_its_starting_lights(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Stopped by a full disk after 2 of its 4 starting lights, resumed with room for 2 more:
    it had been refused (room asked for the 46 left of its maximum)."""
    out = tmp_path / "s"
    real = shutil.disk_usage

    def fills_after_two(path):  # type: ignore[no-untyped-def]
        full = out.is_dir() and len(list(out.glob("image_*.jpg"))) >= 2
        return real(path)._replace(free=1_000_000 if full else _room_for(4))

    monkeypatch.setattr(shutil, "disk_usage", fills_after_two)
    r = runner.invoke(app, ["run", CONFIG, "--out", str(out), "--until-error", "8", "--no-verdict"])
    assert r.exit_code == 2 and "not enough free disk space" in said(r), said(r)
    assert len(list(out.glob("image_*.jpg"))) == 2
    _free(monkeypatch, _room_for(2))
    r = runner.invoke(app, ["run", "--resume", str(out), "--no-verdict"])
    assert r.exit_code == 0, said(r)
    assert len(list(out.glob("image_*.jpg"))) >= 4


def test_a_refused_until_error_session_says_the_rest_is_checked_image_by_image(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    _free(monkeypatch, _room_for(3))
    out = tmp_path / "s"
    r = runner.invoke(app, ["run", CONFIG, "--out", str(out), "--until-error", "8", "--no-verdict"])
    text = " ".join(said(r).split())
    assert r.exit_code == 2, text
    assert "not enough free disk space for 4 image(s)" in text, text
    assert "the 4 are the lights it is sure to take; it may take up to 48" in text, text
    assert "capturing" not in text and not out.exists(), text
