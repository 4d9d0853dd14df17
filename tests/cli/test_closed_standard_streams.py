"""A command started with a standard stream closed (``>&-``, ``2>&-``, a supervisor's doing)
ends as it would have with that stream at ``/dev/null``: its own exit code, no traceback.

Python leaves ``sys.stdout`` (``sys.stderr``) ``None`` then, and the first word printed
raised ``AttributeError``: ``check … >&-`` exited 1 with a traceback, ``run`` ended before its
session began, and a refusal with stderr closed exited 1 (read as "a fault rti-rig did not
name"), not its 2. Through ``python -m rti_rig`` in a shell, as a script starts it.
"""

from __future__ import annotations

import os
import subprocess
import sys

from conftest import CONFIGS, REPO


def _rti_rig_closed(redirections: str, *args: str) -> subprocess.CompletedProcess[str]:
    """``python -m rti_rig ARGS`` with ``redirections`` (``>&-`` …) applied by a shell; what
    the shell leaves open is captured."""
    env = {**os.environ, "PYTHONPATH": str(REPO)}
    script = f'exec "$@" {redirections}'
    return subprocess.run(
        ["sh", "-c", script, "sh", sys.executable, "-m", "rti_rig", *args],
        capture_output=True,
        text=True,
        env=env,
        timeout=600,
    )


def test_stdout_closed_the_check_passes_and_says_so_by_its_exit_code() -> None:
    r = _rti_rig_closed(">&- <&-", "check", str(CONFIGS / "simulated_dome.toml"))
    assert "Traceback" not in r.stderr, r.stderr
    assert r.returncode == 0, r.stderr


def test_stderr_closed_a_refusal_exits_2(tmp_path) -> None:  # type: ignore[no-untyped-def]
    out = tmp_path / "s"
    r = _rti_rig_closed(
        "2>&-", "run", str(CONFIGS / "simulated_dome.toml"), "--out", str(out), "--lights", "200"
    )
    assert r.returncode == 2, r.stdout
    assert "Traceback" not in r.stdout, r.stdout
    assert not out.exists()
