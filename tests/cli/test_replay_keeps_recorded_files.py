"""A replayed acquisition's session holds the recorded files themselves, byte for byte, under
``raw/`` (issue 28), with their checksums journaled; a resume of a cut replay keeps them so.

Why: the session's JPEG of an 8-bit source is a re-encoding (quality 95), so a user who
replayed a real acquisition did not hold its real images: only a 16-bit TIFF written by
rti-rig came out the same bytes. The replay camera now hands its recorded file to the session
as the step's original, as a watched folder's or a DSLR's camera does."""

from __future__ import annotations

import hashlib
import math
from pathlib import Path

import cv2
import numpy as np
from typer.testing import CliRunner

from rti_rig.cli import app
from tests.conftest import cut_new_session, journal, manifest, said

runner = CliRunner()
#: the acquisition's files: upper- and lower-case JPEGs, a 16-bit TIFF, an 8-bit PNG
NAMES = (
    "IMG_0001.JPG",
    "img_0002.jpeg",
    "IMG_0003.TIF",
    "IMG_0004.JPG",
    "IMG_0005.PNG",
    "IMG_0006.JPG",
    "IMG_0007.JPG",
    "IMG_0008.JPG",
)


def _acquisition(folder: Path) -> Path:
    """A tiny recorded acquisition (8 lights, 32x24 images) and its ``dirs.lp``."""
    folder.mkdir()
    rng = np.random.default_rng(28)
    lines = [str(len(NAMES))]
    for i, name in enumerate(NAMES):
        az, el = 2 * math.pi * i / len(NAMES), math.radians(30 + 10 * (i % 3))
        if name.endswith(".TIF"):
            img = rng.integers(1000, 60000, (24, 32, 3)).astype(np.uint16)
        else:
            img = rng.integers(10, 240, (24, 32, 3)).astype(np.uint8)
        assert cv2.imwrite(str(folder / name), img, [cv2.IMWRITE_JPEG_QUALITY, 80])
        x, y, z = math.cos(el) * math.cos(az), math.cos(el) * math.sin(az), math.sin(el)
        lines.append(f"{name} {x:.6f} {y:.6f} {z:.6f}")
    (folder / "dirs.lp").write_text("\n".join(lines) + "\n")
    return folder / "dirs.lp"


def _holds_the_recorded_files(acq: Path, session: Path) -> None:
    """Every step's ``raw/`` file is its recorded file's bytes, journaled (and in the manifest)
    with that file's sha256 and recorded name."""
    steps = {e["index"]: e for e in journal(session)}
    listed = {s["index"]: s for s in manifest(session)["steps"]}
    assert sorted(steps) == sorted(listed) == list(range(len(NAMES)))
    for i, name in enumerate(NAMES):
        raw = f"raw/image_{i + 1:03d}{Path(name).suffix.lower()}"
        recorded = (acq / name).read_bytes()
        assert (session / raw).read_bytes() == recorded, raw
        digest = hashlib.sha256(recorded).hexdigest()
        for entry in (steps[i], listed[i]):
            assert entry["sha256"][raw] == digest
            assert entry["originals"] == {raw: name}


def test_a_replay_holds_its_recorded_files_byte_for_byte(tmp_path: Path) -> None:
    lp = _acquisition(tmp_path / "acq")
    out = tmp_path / "s"
    r = runner.invoke(app, ["run", str(lp), "--out", str(out), "--no-verdict"])
    assert r.exit_code == 0, said(r)
    _holds_the_recorded_files(lp.parent, out)
    assert all((lp.parent / n).is_file() for n in NAMES)  # copied, never moved


def test_a_resumed_replay_holds_them_too(tmp_path: Path) -> None:
    from rti_rig.app.usecases.session import NewSessionRequest
    from rti_rig.runtime.controller import FinishReason

    lp = _acquisition(tmp_path / "acq")
    out = tmp_path / "s"
    run = cut_new_session(NewSessionRequest(lp, out), after_step=2)
    assert run.finish_reason is FinishReason.CANCELLED
    # what a run killed while writing step 4 leaves: its copy, never committed
    (out / "raw" / "image_004.jpg").write_bytes(b"half a copy")
    r = runner.invoke(app, ["run", "--resume", str(out), "--no-verdict"])
    assert r.exit_code == 0, said(r)
    _holds_the_recorded_files(lp.parent, out)
    aside = list((out / "recovered").glob("*/raw/image_004.jpg"))
    assert [p.read_bytes() for p in aside] == [b"half a copy"]  # set aside, not lost


def test_a_replays_disk_check_counts_the_recorded_files(tmp_path: Path) -> None:
    from rti_rig.app.config import load_rig_config
    from rti_rig.app.disk_estimate import bytes_per_image
    from rti_rig.runtime.session import estimated_bytes_per_image

    lp = _acquisition(tmp_path / "acq")
    largest = max((lp.parent / n).stat().st_size for n in NAMES)  # the 16-bit TIFF
    assert bytes_per_image(load_rig_config(lp)) >= estimated_bytes_per_image(32, 24) + largest
