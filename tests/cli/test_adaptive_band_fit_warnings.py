"""`run --adaptive` on the shipped simulated arm in a band 3° high: every light within a few
degrees of the horizon, so the normals are poorly determined. The run had printed Python's
raw ``IllConditionedFitWarning`` (with ``.../adaptive.py:176:`` and ``.../qa.py:1374:``) three
times per image and again under the verdict; it now says once, in words, what that means for
the session and what to do (widen the band). Run as a user runs it (``python -m rti_rig``):
pytest's own warning capture would hide a raw warning from an in-process run."""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
from pathlib import Path

from conftest import CONFIGS, REPO


def _rti_rig(*argv: str) -> subprocess.CompletedProcess[str]:
    """``rti-rig`` as a user runs it, Python's default warning display in force."""
    env = {**os.environ, "PYTHONPATH": str(REPO), "COLUMNS": "200", "PYTHONWARNINGS": "default"}
    return subprocess.run(
        [sys.executable, "-m", "rti_rig", *argv],
        env=env,
        capture_output=True,
        text=True,
        timeout=300,
    )


def test_a_band_too_low_for_normals_is_said_in_words_not_as_python_warnings(
    tmp_path: Path,
) -> None:
    argv = [
        "run",
        str(CONFIGS / "simulated_arm.toml"),
        "--out",
        str(tmp_path / "s"),
        "--adaptive",
        "--lights",
        "8",
        "--max-elevation-deg",
        "3",
    ]
    proc = _rti_rig(*argv)
    assert proc.returncode == 0, proc.stderr
    text = " ".join((proc.stdout + proc.stderr).split())
    assert "Warning:" not in text, text
    assert not re.search(r"\.py:\d+", text), text
    # once, with what it means and what to do
    assert text.count("leave its surface normals poorly determined") == 1, text
    assert text.count("photometric stereo fit ill-conditioned") == 1, text  # the run's verdict
    assert "widen the elevation band" in text, text
    # the chooser's own decision fits (4 lights of a narrow band) are not said at all
    assert "for these 4 lights" not in text, text
    # and `rti-rig fit` of it: its QA's trust warning had been printed raw too (qa.py:1374)
    fitted = _rti_rig("fit", str(tmp_path / "s"), "--out", str(tmp_path / "fit"))
    assert fitted.returncode == 0, fitted.stderr
    words = " ".join((fitted.stdout + fitted.stderr).split())
    assert "Warning:" not in words and not re.search(r"\.py:\d+", words), words
    assert "photometric stereo fit ill-conditioned" in words, words  # said, not dropped
    # a warning about the user's result, as the PTM's and HSH's are (it had been a "note:",
    # the console's safety net catching the QA's warning outside the fit's own capture), once,
    # and recorded with them in fit.json
    assert "warning: photometric stereo fit ill-conditioned" in words, words
    assert words.count("photometric stereo fit ill-conditioned") == 1, words
    assert "warning: ptm fit" in words or "warning: hsh" in words, words
    recorded = json.loads((tmp_path / "fit" / "fit.json").read_text())["warnings"]
    assert any("photometric stereo fit ill-conditioned" in w for w in recorded), recorded
