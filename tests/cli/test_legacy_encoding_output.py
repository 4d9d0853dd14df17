"""A command whose stdout cannot encode its words (a Latin-1 locale, ``PYTHONIOENCODING=ascii``,
Windows' code page for a redirected stream) says them with ``?`` for what it cannot hold.

The first ``…`` or ``→`` raised ``UnicodeEncodeError``: ``check`` ended with a traceback and
exit 1, and ``run`` before its session began. Through ``python -m rti_rig``, as a script runs it.
"""

from __future__ import annotations

import os
import subprocess
import sys

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
