"""A session folder and an exported `.lp`, read as relight-cli and RTIBuilder read them.

The two readers below are written from the published parsers, not from our writer:

* relight-cli given a folder (cnr-isti-vclab/relight, ``ImageSet::initFromFolder`` and
  ``parseLP``): the first ``*.lp`` of the folder by name; a first line that is a whole number in
  1..1000; then that many lines, each split on whitespace into exactly four fields (name, x, y,
  z: C-locale numbers), the vector normalised and refused under 1e-4; the folder's ``*.jpg`` and
  ``*.JPG`` sorted by name, as many as the lights, image *i* lit by light *i* (the names in the
  ``.lp`` are not used).
* RTIBuilder (CHI / Universidade do Minho, ``LPparser`` and ``DomeLDSetup.loadDirectory``):
  every line split on LF; numbers found only as ``0.ddd`` or ``-0.ddd``; a line with fewer than
  three is skipped (more overrun its array of three); each number found is removed from the line
  with ``replaceAll`` (the number read as a regular expression), and the last run of digits left
  is the light's key; each image file of the folder is keyed by the last run of digits in its
  name and given that light.

Each must pair every image of the session with the light that fired for it (its record's
``actual_direction``), the pairing rti-rig itself reads from ``lights.lp``.
"""

from __future__ import annotations

import json
import re
import shutil
from pathlib import Path

import numpy as np
from conftest import CONFIGS
from typer.testing import CliRunner

from rti_rig.cli import app

REPLAY = Path(__file__).resolve().parents[1] / "data" / "neuralrti_replay" / "dirs.lp"
_QT_NUMBER = re.compile(r"[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?")


def relight_cli_folder(folder: Path) -> dict[str, np.ndarray]:
    """What relight-cli pairs when given ``folder`` (see the module docstring)."""
    lps = sorted((p for p in folder.iterdir() if p.name.endswith(".lp")), key=lambda p: p.name)
    assert lps, "relight-cli: Could not find .lp file"
    lines = lps[0].read_bytes().decode("utf-8").split("\n")  # QTextStream.readLine
    lines = [ln[:-1] if ln.endswith("\r") else ln for ln in lines]
    assert re.fullmatch(r"\d+", lines[0]), f"Invalid format or number of lights: {lines[0]!r}"
    n = int(lines[0])
    assert 0 < n <= 1000, "Invalid format or number of lights in .lp."
    lights = []
    for line in lines[1 : n + 1]:
        tokens = [t for t in re.split(r"\s+", line) if t]
        assert len(tokens) == 4, f"Invalid line in .lp: {line!r}"
        assert all(_QT_NUMBER.fullmatch(t) for t in tokens[1:]), f"Failed reading: {line!r}"
        v = np.array([float(t) for t in tokens[1:]])
        assert np.linalg.norm(v) >= 1e-4, f"Light direction too close to the origin! {line}"
        lights.append(v / np.linalg.norm(v))
    images = sorted(
        (p.name for p in folder.iterdir() if p.name.endswith((".jpg", ".JPG"))),
        key=str.lower,  # QDir's default sort: by name, case ignored
    )
    assert len(images) == len(lights), (
        f"Lp number of lights ({len(lights)}) different from the number of images found "
        f"({len(images)})"
    )
    return dict(zip(images, lights, strict=True))


def rtibuilder_pairs(folder: Path, lp: Path) -> dict[str, np.ndarray]:
    """What RTIBuilder pairs for the images of ``folder`` and the lights of ``lp`` (see the
    module docstring)."""
    table: dict[int, np.ndarray] = {}
    for line in lp.read_bytes().decode("latin-1").split("\n"):
        found = re.findall(r"-0\.[0-9]+|0\.[0-9]+", line)
        if len(found) < 3:
            continue
        assert len(found) == 3, f"ArrayIndexOutOfBounds: {len(found)} numbers in {line!r}"
        rest = line
        for number in found:
            rest = re.sub(number, "", rest)  # Java's replaceAll: a pattern, '.' any character
        digits = re.findall(r"[0-9]+", rest)
        assert digits, f"no number left for a key in {line!r}"
        table[int(digits[-1])] = np.array([float(f) for f in found])
    pairs = {}
    for f in folder.iterdir():
        if f.is_file() and f.suffix.lower() in (".jpg", ".jpeg"):
            digits = re.findall(r"[0-9]+", f.name)
            if digits and int(digits[-1]) in table:
                pairs[f.name] = table[int(digits[-1])]
    return pairs


def fired(session: Path) -> dict[str, np.ndarray]:
    """Each image of the session and the light that fired for it, from its step record."""
    out = {}
    for record in sorted((session / "records").glob("*.json")):
        step = json.loads(record.read_text())
        v = np.asarray(step["actual_direction"], dtype=np.float64)
        out[step["image"]] = v / np.linalg.norm(v)
    return out


def assert_same_pairs(got: dict[str, np.ndarray], want: dict[str, np.ndarray]) -> None:
    assert sorted(got) == sorted(want)
    for name, v in want.items():
        # six decimals, then normalised by the reader
        np.testing.assert_allclose(got[name] / np.linalg.norm(got[name]), v, atol=3e-6)


def _run(args: list[str]) -> None:
    r = CliRunner().invoke(app, args)
    assert r.exit_code == 0, r.output


def test_a_dome_session_reads_in_relight_cli_and_rtibuilder_as_it_was_shot(
    tmp_path: Path,
) -> None:
    session = tmp_path / "Tablet 3" / "session"
    config = CONFIGS / "simulated_dome.toml"
    _run(["run", str(config), "--out", str(session), "--lights", "8", "--no-verdict"])
    want = fired(session)
    assert len(want) == 8
    # relight's GUI pairs by file name: each name, as written, is a file there (exact case)
    names = [line.split()[0] for line in (session / "lights.lp").read_text().splitlines()[1:]]
    assert sorted(names) == sorted(p.name for p in session.glob("*.jpg")) == sorted(want)
    assert_same_pairs(relight_cli_folder(session), want)
    assert_same_pairs(rtibuilder_pairs(session, session / "lights.lp"), want)

    # the exported .lp, beside the session, pairs the same in both
    exported = tmp_path / "exported.lp"
    _run(["export-lp", str(session), "--out", str(exported)])
    assert_same_pairs(rtibuilder_pairs(session, exported), want)
    alone = tmp_path / "alone"
    alone.mkdir()
    for name in want:
        shutil.copy(session / name, alone / name)
    shutil.copy(exported, alone / "exported.lp")
    assert_same_pairs(relight_cli_folder(alone), want)


def test_a_replayed_acquisition_reads_as_its_recording_lit_it(tmp_path: Path) -> None:
    """A replay of a real acquisition: each session image is one of the recording's, and both
    tools give it the recording's light for that image."""
    session = tmp_path / "My Sessions" / "replay"
    _run(["run", str(REPLAY), "--out", str(session), "--lights", "6", "--no-verdict"])
    want = fired(session)
    recorded = {
        tuple(np.round(np.array([float(t) for t in line.split()[1:]]), 5))
        for line in REPLAY.read_text().splitlines()[1:]
    }
    for v in want.values():  # every light fired is one of the recording's
        assert tuple(np.round(v, 5)) in recorded, v
    assert_same_pairs(relight_cli_folder(session), want)
    assert_same_pairs(rtibuilder_pairs(session, session / "lights.lp"), want)
