"""``line_within`` (tests/conftest.py): the tests that wait for a child process's first line
fail in bounded time, naming what they waited for, where a bare ``readline()`` on the pipe
hung the run for ever when the child never printed."""

from __future__ import annotations

import subprocess
import sys

import pytest
from conftest import line_within


def _child(code: str) -> subprocess.Popen[str]:
    return subprocess.Popen(
        [sys.executable, "-c", code], stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True
    )


def test_a_child_that_never_prints_fails_the_wait_and_is_killed() -> None:
    child = _child("import sys; sys.stdin.read()")  # silent until its stdin closes: never
    try:
        with pytest.raises(pytest.fail.Exception, match="the silent child's line: no line"):
            line_within(child, 1, "the silent child's line")
        assert child.wait(timeout=120) != 0  # killed, not left waiting
    finally:
        child.kill()
        child.wait(timeout=120)


def test_a_child_that_ends_without_a_line_fails_the_wait_with_its_status() -> None:
    child = _child("raise SystemExit(3)")
    with pytest.raises(pytest.fail.Exception, match=r"ended \(exit status 3\) without a line"):
        line_within(child, 120, "the child's line")


def test_the_line_a_child_prints_is_returned() -> None:
    child = _child("print('ready', flush=True)")
    try:
        assert line_within(child, 120, "the child's 'ready'") == "ready\n"
    finally:
        child.wait(timeout=120)
