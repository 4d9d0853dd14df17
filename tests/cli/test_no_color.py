"""What escape codes reach a user's screen or file.

In a terminal, ``NO_COLOR`` (https://no-color.org: "prevents the addition of ANSI color")
removes colour and only colour: bold and dim stay, as rich documents for ``NO_COLOR``; a
terminal without it gets colour. Where the stream is not a terminal (``| grep``, ``> log``)
nothing but the words is written, typer's help and usage errors included: typer forced its
help to be a terminal under ``GITHUB_ACTIONS`` and wrote bold, dim and colour codes into
``run --help > help.txt`` in a CI job. Through ``python -m rti_rig`` on a real pseudo-terminal
and on real pipes.
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest
from conftest import CONFIGS, REPO

#: Select Graphic Rendition codes that set a colour: foreground 30-39 and 90-97, background
#: 40-49 and 100-107 (38 and 48 start a 256-colour or true-colour one).
COLOUR = re.compile(rb"\x1b\[(?:[0-9;]*;)?(?:3[0-9]|4[0-9]|9[0-7]|10[0-7])(?:;[0-9;]*)?m")
BOLD = b"\x1b[1m"


def _on_a_terminal(env: dict[str, str], *args: str) -> tuple[int, bytes]:
    """``python -m rti_rig ARGS`` with stdin, stdout and stderr on one pseudo-terminal: its
    exit status and all it wrote there."""
    import pty

    leader, follower = pty.openpty()
    full_env = {**os.environ, "PYTHONPATH": str(REPO), "TERM": "xterm-256color", **env}
    for name in ("NO_COLOR", "FORCE_COLOR", "TTY_COMPATIBLE", "GITHUB_ACTIONS", "PY_COLORS"):
        if name not in env:
            full_env.pop(name, None)
    try:
        command = subprocess.Popen(
            [sys.executable, "-m", "rti_rig", *args],
            stdin=follower,
            stdout=follower,
            stderr=follower,
            env=full_env,
        )
    finally:
        os.close(follower)
    said = b""
    try:
        while True:
            try:
                chunk = os.read(leader, 65536)
            except OSError:  # EIO: the command ended and closed the terminal
                break
            if not chunk:
                break
            said += chunk
        code = command.wait(timeout=600)
    finally:
        os.close(leader)
        if command.poll() is None:
            command.kill()
            command.wait()
    return code, said


def _refusal_args(tmp_path: Path) -> list[str]:
    """A run refused before anything is lit (more lights than the dome has): ``error:`` in bold
    red, and typer is not involved."""
    cfg = str(CONFIGS / "simulated_dome.toml")
    return ["run", cfg, "--out", str(tmp_path / "s"), "--lights", "900"]


@pytest.fixture(scope="module")
def refusal_on_a_terminal(tmp_path_factory: pytest.TempPathFactory) -> dict[str, bytes]:
    tmp = tmp_path_factory.mktemp("no_color")
    said = {}
    for name, env in (("colour", {}), ("no_color", {"NO_COLOR": "1"})):
        code, said[name] = _on_a_terminal(env, *_refusal_args(tmp))
        assert code == 2, said[name]
    return said


def test_a_terminal_gets_colour(refusal_on_a_terminal: dict[str, bytes]) -> None:
    said = refusal_on_a_terminal["colour"]
    assert COLOUR.search(said), said


def test_no_color_removes_the_colour_and_keeps_the_bold(
    refusal_on_a_terminal: dict[str, bytes],
) -> None:
    said = refusal_on_a_terminal["no_color"]
    assert not COLOUR.search(said), said
    assert BOLD + b"error:" in said, said
    assert b"use --lights 48 or fewer" in said, said


def test_no_color_removes_the_colour_of_a_usage_error_box() -> None:
    """Typer's own console draws a usage error's box in red on a terminal."""
    code, said = _on_a_terminal({"NO_COLOR": "1"}, "run", "--nope")
    assert code == 2, said
    assert b"No such option" in said, said
    assert not COLOUR.search(said), said


def test_piped_help_and_usage_errors_have_no_escape_codes_in_a_ci_job() -> None:
    env = {**os.environ, "PYTHONPATH": str(REPO), "GITHUB_ACTIONS": "true"}
    for name in ("NO_COLOR", "FORCE_COLOR", "TTY_COMPATIBLE"):
        env.pop(name, None)
    for args, code in ((["run", "--help"], 0), (["run", "--nope"], 2)):
        r = subprocess.run(
            [sys.executable, "-m", "rti_rig", *args],
            capture_output=True,
            env=env,
            timeout=600,
        )
        assert r.returncode == code, r.stderr
        assert b"\x1b" not in r.stdout + r.stderr, r.stdout + r.stderr
        assert b"--lights" in r.stdout or b"No such option" in r.stderr, r.stdout + r.stderr


def test_a_piped_refusal_has_no_escape_codes(tmp_path: Path) -> None:
    env = {**os.environ, "PYTHONPATH": str(REPO)}
    for name in ("NO_COLOR", "FORCE_COLOR", "TTY_COMPATIBLE"):
        env.pop(name, None)
    r = subprocess.run(
        [sys.executable, "-m", "rti_rig", *_refusal_args(tmp_path)],
        capture_output=True,
        env=env,
        timeout=600,
    )
    assert r.returncode == 2, r.stderr
    assert r.stderr.startswith(b"error: asked for 900 lights"), r.stderr
    assert b"\x1b" not in r.stdout + r.stderr, r.stdout + r.stderr
