"""A Ctrl-C while a run's stop (a SIGTERM's) is under way: said in one line, naming the stop
that began it, and the stop goes on (its teardown's all-off, its record, its exit code).

Before, a Ctrl-C delivered by the same hold as the SIGTERM was told "Stopping after this
image" (none was to come), and a second one raised "second Ctrl-C", which the hold dropped
unsaid (it raises only the first exception it collected); one delivered after the teardown's
hold replaced the stop: said "Emergency stop (second Ctrl-C)", exit 130, while the manifest
recorded the SIGTERM. The signals are raised in the run's own process at the point under
test, where a hold keeps them (no timing).
"""

from __future__ import annotations

import signal
import sys
from pathlib import Path

import pytest
from conftest import CONFIGS, manifest, said, signal_as_the_teardown_switches_off
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.runtime.session import SessionFolder

pytestmark = pytest.mark.skipif(sys.platform != "linux", reason="signals tested on Linux")

ALSO = "Ctrl-C also arrived: the stop (SIGTERM) is already under way"


def _signals_as_the_second_image_is_committed(
    monkeypatch: pytest.MonkeyPatch, sent: list[signal.Signals]
) -> None:
    """``sent`` raised in order while the second image is committed (one hold keeps them all
    and delivers them as it ends)."""
    real = SessionFolder.write_step

    def write_step(self, index, *args, **kwargs):  # type: ignore[no-untyped-def]
        record = real(self, index, *args, **kwargs)
        if index == 1:
            for sig in sent:
                signal.raise_signal(sig)
        return record

    monkeypatch.setattr(SessionFolder, "write_step", write_step)


@pytest.mark.parametrize(
    ("in_one_hold", "in_teardown", "also_said"),
    [
        # SIGTERM, then Ctrl-C twice (the user's "stop at once"), all in one hold
        ([signal.SIGTERM, signal.SIGINT, signal.SIGINT], False, 2),
        # Ctrl-C (stop after this image), the SIGTERM, then Ctrl-C again during its teardown
        ([signal.SIGINT, signal.SIGTERM], True, 1),
    ],
    ids=["sigterm-then-two-ctrl-c", "second-ctrl-c-in-the-sigterms-teardown"],
)
def test_a_ctrl_c_during_a_sigterms_stop_is_said_and_the_stop_goes_on(
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    in_one_hold: list[signal.Signals],
    in_teardown: bool,
    also_said: int,
) -> None:
    _signals_as_the_second_image_is_committed(monkeypatch, in_one_hold)
    teardown = (
        signal_as_the_teardown_switches_off(monkeypatch, signal.SIGINT) if in_teardown else None
    )
    out = tmp_path / "s"
    argv = ["run", str(CONFIGS / "simulated_dome.toml"), "--lights", "6", "--out", str(out)]
    r = CliRunner().invoke(app, [*argv, "--no-verdict"], terminal_width=400)
    words = said(r)
    assert teardown is None or teardown == [True], words
    assert "Traceback" not in words, words
    assert r.exit_code == 143, words  # the SIGTERM's stop, not a Ctrl-C's (130)
    assert "Emergency stop (SIGTERM): lights were switched off." in words, words
    assert "second Ctrl-C" not in words, words
    assert words.count(ALSO) == also_said, words
    if in_one_hold[0] == signal.SIGTERM:  # no image was left to come after the SIGTERM
        assert "Stopping after this image" not in words, words
    assert "2 image(s)" in words and "Continue with: rti-rig run --resume" in words, words
    runner = manifest(out)["runner"]
    assert runner["finish_reason"] == "emergency-stop", runner
    assert runner["error"] == "emergency stop: SIGTERM", runner


@pytest.mark.skipif(not hasattr(signal, "SIGUSR1"), reason="SIGUSR1 is POSIX")
def test_a_sigusr1_during_a_sigterms_teardown_does_not_say_it_pauses(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """SIGUSR1 is not held (a pause acts between images): in a stop's teardown it had been
    told "Pausing after this image", of a run that was ending."""
    _signals_as_the_second_image_is_committed(monkeypatch, [signal.SIGTERM])
    sent = signal_as_the_teardown_switches_off(monkeypatch, signal.SIGUSR1)
    out = tmp_path / "s"
    argv = ["run", str(CONFIGS / "simulated_dome.toml"), "--lights", "6", "--out", str(out)]
    r = CliRunner().invoke(app, [*argv, "--no-verdict"], terminal_width=400)
    words = said(r)
    assert sent == [True], words
    assert r.exit_code == 143 and "Traceback" not in words, words
    assert "Pausing" not in words, words
    assert "SIGUSR1 ignored: the stop (SIGTERM) is under way" in words, words
