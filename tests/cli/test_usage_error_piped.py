"""A usage error with stderr piped (a script's log) is said in plain lines, its message whole.

Typer drew it in a box at 80 columns with the message wrapped inside it, so a log kept
``│ Invalid value for '--out': an empty path (a shell variable that was not      │`` and the
rest of the sentence on the next line. Through ``python -m rti_rig``, as a script runs it.
"""

from __future__ import annotations

import os
import subprocess
import sys

from conftest import REPO


def _rti_rig(*args: str) -> subprocess.CompletedProcess[str]:
    env = {**os.environ, "PYTHONPATH": str(REPO)}
    env.pop("COLUMNS", None)  # rich's width without a terminal: 80, unless COLUMNS says
    return subprocess.run(
        [sys.executable, "-m", "rti_rig", *args],
        capture_output=True,
        text=True,
        env=env,
        timeout=600,
    )


def test_a_piped_usage_error_is_one_plain_line_and_exit_2() -> None:
    r = _rti_rig("run", "--out", "", "--no-such-option-" + "x" * 60)
    assert r.returncode == 2, r.stderr
    assert "│" not in r.stderr and "╭" not in r.stderr, r.stderr
    errors = [line for line in r.stderr.splitlines() if line.startswith("Error: ")]
    assert len(errors) == 1, r.stderr
    assert "--no-such-option-" + "x" * 60 in errors[0], r.stderr
    assert r.stdout == ""


def test_a_piped_empty_path_names_its_option_on_one_line() -> None:
    r = _rti_rig("fit", "somewhere", "--out", "")
    assert r.returncode == 2, r.stderr
    errors = [line for line in r.stderr.splitlines() if line.startswith("Error: ")]
    assert len(errors) == 1, r.stderr
    assert "'--out': an empty path (a shell variable that was not set?)" in errors[0], r.stderr
