"""A command whose stdout cannot encode its words (a Latin-1 locale, ``PYTHONIOENCODING=ascii``,
Windows' code page for a redirected stream) says them with ``?`` for what it cannot hold.

The first ``…`` or ``→`` raised ``UnicodeEncodeError``: ``check`` ended with a traceback and
exit 1, and ``run`` before its session began. Through ``python -m rti_rig``, as a script runs it.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from conftest import CONFIGS, REPO


def test_an_ascii_stdout_gets_the_words_with_replacements_and_the_check_passes() -> None:
    env = {**os.environ, "PYTHONPATH": str(REPO), "PYTHONIOENCODING": "ascii"}
    r = subprocess.run(
        [sys.executable, "-m", "rti_rig", "check", str(CONFIGS / "simulated_dome.toml")],
        capture_output=True,
        env=env,
        timeout=600,
    )
    assert b"Traceback" not in r.stderr, r.stderr
    assert r.returncode == 0, r.stderr
    assert b"(Ctrl-C stops the check at once)?" in r.stdout, r.stdout
    assert b"RESULT: PASS" in r.stdout, r.stdout


def test_an_ascii_stdout_gets_a_folder_named_in_another_script_as_a_word_a_shell_reads_back(
    tmp_path: Path,
) -> None:
    """``--out é`` was said as ``→ ?``: a glob, not the folder. The name is said as ``$'...'``
    of its bytes, which a shell reads back as that folder."""
    out = tmp_path / "é" / "S"
    env = {**os.environ, "PYTHONPATH": str(REPO), "PYTHONIOENCODING": "ascii"}
    config = str(CONFIGS / "simulated_dome.toml")
    run = ["run", config, "--lights", "3", "--out", str(out), "--no-verdict"]
    r = subprocess.run(
        [sys.executable, "-m", "rti_rig", *run],
        capture_output=True,
        env=env,
        timeout=600,
    )
    assert r.returncode == 0, r.stderr
    first = r.stdout.decode("ascii").splitlines()[0]
    word = first.rsplit(" ", 1)[-1]
    assert word == "$'" + str(out).replace("é", "\\xc3\\xa9") + "'", first
    if shutil.which("bash"):
        named = subprocess.run(["bash", "-c", f"printf %s {word}"], capture_output=True)
        assert named.stdout == os.fsencode(out), named
        assert (out / "lights.lp").is_file()


@pytest.mark.parametrize(
    ("name", "word"),
    [
        ("/s/plain", "/s/plain"),
        ("/s/é", "$'/s/\\xc3\\xa9'"),
        ("/s/it's é", "$'/s/it\\'s \\xc3\\xa9'"),
        ("/s/\udcff", "$'/s/\\xff'"),  # a name whose byte is not UTF-8 (surrogateescape)
    ],
)
def test_a_path_on_an_ascii_stdout_is_said_as_its_bytes(
    monkeypatch: pytest.MonkeyPatch, name: str, word: str
) -> None:
    import io

    from rti_rig.cli.app import shell_word, shown_path

    monkeypatch.setattr(sys, "stdout", io.TextIOWrapper(io.BytesIO(), encoding="ascii"))
    assert shown_path(Path(name)) == word
    assert shell_word(Path(name)) == (word if word != name else name)
    assert shell_word("/s/a b") == "'/s/a b'"
