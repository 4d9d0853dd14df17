"""``rti-rig plan PREVIEW_DIR`` of a preview whose image was replaced since capture.

Another preview's image (lit from elsewhere) copied over a preview session's had been planned
from as lit by the light the session recorded: its journal's record did not match the image,
so the manifest's step was taken, its checksum never compared. fit, calibrate-lights and
lights-from-sphere refuse such an image by name; plan now does too. A journal record that does
not match an image the manifest's step still vouches for (the journal damaged, the image as
captured) keeps its light, as before.
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest
from conftest import CONFIGS, said
from typer.testing import CliRunner

from rti_rig.cli import app

runner = CliRunner()
CONFIG = CONFIGS / "simulated_dome.toml"


@pytest.fixture(scope="module")
def previews(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    base = tmp_path_factory.mktemp("previews")
    made = []
    for name, light in (("a", []), ("b", ["--light", "0,20"])):
        out = base / name
        r = runner.invoke(app, ["preview", str(CONFIG), "--out", str(out), *light])
        assert r.exit_code == 0, r.output
        made.append(out)
    return made[0], made[1]


def _plan(preview: Path, tmp_path: Path) -> tuple[int, str]:
    out = tmp_path / "plan.lp"
    r = runner.invoke(
        app, ["plan", str(preview), "--rig", str(CONFIG), "--lights", "6", "--out", str(out)]
    )
    return r.exit_code, said(r)


def test_an_image_replaced_since_capture_is_refused(
    previews: tuple[Path, Path], tmp_path: Path
) -> None:
    a, b = previews
    swapped = tmp_path / "a"
    shutil.copytree(a, swapped)
    for name in ("image_001.jpg", "linear/image_001.tif"):
        shutil.copyfile(b / name, swapped / name)
    code, text = _plan(swapped, tmp_path)
    assert code == 2, text
    assert "linear/image_001.tif: the image is not as the session" in text, text
    assert "differs from the one recorded at capture" in text, text
    assert "--preview-light AZ,EL" in text and not (tmp_path / "plan.lp").exists()


def test_a_damaged_journal_record_of_an_intact_image_keeps_the_recorded_light(
    previews: tuple[Path, Path], tmp_path: Path
) -> None:
    a, _ = previews
    copy = tmp_path / "a"
    shutil.copytree(a, copy)
    journal = copy / "journal.jsonl"
    record = json.loads(journal.read_text().splitlines()[0])
    record["sha256"] = {k: "0" * 64 for k in record["sha256"]}
    journal.write_text(json.dumps(record) + "\n")
    code, text = _plan(copy, tmp_path)
    assert code == 0, text
    assert "recorded by the session a" in text, text
