"""A command started with a standard stream closed (``>&-``, ``2>&-``, a supervisor's doing),
or whose output cannot be written (a full disk), ends as it would have: its own exit code, no
traceback.

Python leaves ``sys.stdout`` (``sys.stderr``) ``None`` then, and the first word printed
raised ``AttributeError``: ``check … >&-`` exited 1 with a traceback, ``run`` ended before its
session began, and a refusal with stderr closed exited 1 (read as "a fault rti-rig did not
name"), not its 2. Through ``python -m rti_rig`` in a shell, as a script starts it.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest
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


def test_stderr_closed_a_refusal_exits_2(tmp_path: Path) -> None:
    out = tmp_path / "s"
    r = _rti_rig_closed(
        "2>&-", "run", str(CONFIGS / "simulated_dome.toml"), "--out", str(out), "--lights", "200"
    )
    assert r.returncode == 2, r.stdout
    assert "Traceback" not in r.stdout, r.stdout
    assert not out.exists()


@pytest.mark.skipif(not Path("/dev/full").exists(), reason="needs Linux's /dev/full")
def test_stdout_on_a_full_disk_is_said_once_and_the_check_ends_as_it_would() -> None:
    """``> log`` on a full disk: the first line's write failed with ``ENOSPC`` and the command
    ended there with a traceback and exit 1 (a run: before its session began)."""
    r = _rti_rig_closed(">/dev/full", "check", str(CONFIGS / "simulated_dome.toml"))
    assert "Traceback" not in r.stderr, r.stderr
    assert r.returncode == 0, r.stderr
    notes = [line for line in r.stderr.splitlines() if "output could not be written" in line]
    assert len(notes) == 1, r.stderr
    assert "No space left on device" in notes[0]


def test_a_write_failing_mid_way_drops_the_rest_and_is_said_once(tmp_path: Path) -> None:
    """A terminal gone with its ssh connection (``EIO``) after some lines were written: the
    rest is dropped, said once on the other stream, and no later write raises (a failure
    from a progress update would have ended a capture mid-way)."""
    import errno
    import io

    from rti_rig.cli.app import ReaderGoneTolerant

    target = open(tmp_path / "log.txt", "w")  # noqa: SIM115  (its descriptor is redirected)

    class GoneAfterOne(io.StringIO):
        writes = 0

        def write(self, text: str) -> int:
            GoneAfterOne.writes += 1
            if GoneAfterOne.writes > 1:
                raise OSError(errno.EIO, "Input/output error")
            return super().write(text)

        def fileno(self) -> int:
            return target.fileno()

    said = io.StringIO()
    stream = ReaderGoneTolerant(GoneAfterOne(), said_on=said)
    try:
        assert stream.write("Rig …\n") == len("Rig …\n")
        for _ in range(3):
            assert stream.write("capturing 2/6\n") == len("capturing 2/6\n")
        stream.flush()
    finally:
        target.close()
    assert said.getvalue().count("output could not be written (Input/output error)") == 1


@pytest.mark.skipif(not Path("/dev/full").exists(), reason="needs Linux's /dev/full")
def test_a_usage_error_exits_2_when_stderr_cannot_be_written() -> None:
    """Click said the usage error on its own stderr, whose failed write ended the command with
    exit 1 (a fault rti-rig did not name), not a usage error's 2."""
    r = _rti_rig_closed("2>/dev/full", "run", "--nope")
    assert r.returncode == 2, r.stdout


@pytest.mark.skipif(not Path("/dev/full").exists(), reason="needs Linux's /dev/full")
def test_help_on_a_full_disk_is_said_once_and_exits_0() -> None:
    """Typer's help is printed past rti-rig's consoles, to ``sys.stdout``: its failed write
    had ended ``--help > log`` with a traceback and exit 1."""
    r = _rti_rig_closed(">/dev/full", "run", "--help")
    assert "Traceback" not in r.stderr, r.stderr
    assert r.returncode == 0, r.stderr
    assert r.stderr.count("output could not be written (No space left on device)") == 1, r.stderr
