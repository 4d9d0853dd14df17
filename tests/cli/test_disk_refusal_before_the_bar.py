"""A disk that cannot hold the session is refused before the rig opens and before any bar.

``rti-rig run`` (new, adaptive, resumed) and ``rti-rig preview`` on the shipped configs with
too little free disk under ``--out``: the refusal had come from the controller's start-up
check, after the rig opened and below a drawn "capturing 0/48" progress bar, as if the
capture had begun. The free space is faked with ``shutil.disk_usage`` (no real full disk).
"""

from __future__ import annotations

import re
import shutil
from pathlib import Path

import pytest
from conftest import CONFIGS, said
from typer.testing import CliRunner

from rti_rig.cli import app

runner = CliRunner()


def _disk_full(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    usage = shutil.disk_usage(tmp_path)
    monkeypatch.setattr(shutil, "disk_usage", lambda _p: usage._replace(free=1_000_000))


@pytest.mark.parametrize(
    ("command", "extra"),
    [
        ("run", ["rig_configs/simulated_dome.toml"]),
        ("run", ["rig_configs/emulated_dome.toml"]),
        ("run", ["rig_configs/simulated_dome.toml", "--adaptive", "--lights", "20"]),
        ("preview", ["rig_configs/simulated_dome.toml"]),
    ],
)
def test_a_full_disk_is_refused_before_the_capture_bar(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, command: str, extra: list[str]
) -> None:
    _disk_full(monkeypatch, tmp_path)
    out = tmp_path / "s"
    config = str(CONFIGS.parent / extra[0])
    r = runner.invoke(app, [command, config, *extra[1:], "--out", str(out)])
    text = said(r)
    assert r.exit_code == 2, text
    assert "not enough free disk space" in text and "free space or choose another --out" in text
    # a bar's count ("0/48"), not a "0/" in a path (pytest's first basetemp is pytest-0/)
    assert "capturing" not in text and not re.search(r"(?<![\w/.-])0/\d+", text), text
    assert "switched off" not in text and "check the dome's lights" not in text, text
    assert "Traceback" not in text and not out.exists()


@pytest.mark.parametrize("mode", [[], ["--adaptive"]])
def test_a_resume_onto_a_full_disk_is_refused_before_the_capture_bar(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, mode: list[str]
) -> None:
    """A session (planned or adaptive) stopped by a full disk after two of six images, resumed
    while the disk is still full: refused before the rig opens, its images left as they are,
    in a resume's words. It had said "free space or choose another --out", which ``run
    --resume S --out X`` refuses, and not that the images taken are kept or how to go on."""
    out = tmp_path / "s"
    real = shutil.disk_usage

    def fills_after_two(path):  # type: ignore[no-untyped-def]
        usage = real(path)
        full = out.is_dir() and len(list(out.glob("image_*.jpg"))) >= 2
        return usage._replace(free=1_000_000) if full else usage

    monkeypatch.setattr(shutil, "disk_usage", fills_after_two)
    config = str(CONFIGS / "simulated_dome.toml")
    r = runner.invoke(
        app, ["run", config, "--out", str(out), "--lights", "6", *mode, "--no-verdict"]
    )
    assert r.exit_code == 2 and "not enough free disk space" in said(r), said(r)
    # a session with images goes on in its own folder only: "choose another --out" had
    # followed its "Continue with: rti-rig run --resume S"
    stopped = " ".join(said(r).split())
    assert "choose another --out" not in stopped, stopped
    assert re.search(r"free at least \d+ MB on that disk to go on", stopped), stopped
    kept = sorted(p.name for p in out.glob("image_*.jpg"))
    assert len(kept) == 2
    r = runner.invoke(app, ["run", "--resume", str(out), "--no-verdict"])
    text = " ".join(said(r).split())
    assert r.exit_code == 2, text
    assert "2 of 6 images verified on disk" in text, text
    assert "the 4 image(s) still to shoot need about" in text, text
    assert re.search(r"free at least \d+ MB there", text), text
    assert "The 2 image(s) already taken are kept, listed in lights.lp" in text, text
    assert text.rstrip().endswith(f"then continue with: rti-rig run --resume {out}"), text
    assert "--out" not in text, text
    assert "capturing" not in text and "Traceback" not in text, text
    assert sorted(p.name for p in out.glob("image_*.jpg")) == kept
