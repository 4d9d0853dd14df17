"""A dry run whose camera is an image sequence (`[camera.device] backend = "images"`) cannot be
resumed: the sequence is read from its first file again on every run, so the resumed lights
were given the files of the lights already shot (image_006 held f_000's picture), labelled as
lit by LEDs that never lit them. The resume is refused before anything in the folder changes.

Through `rti-rig run` on the shipped hardware dome example, its camera swapped for an image
sequence and its port redirected to the dome firmware emulator on a pty.
"""

from __future__ import annotations

import shutil
from pathlib import Path

import cv2
import numpy as np
import pytest
from conftest import CONFIGS, shipped_dome_on_pty
from typer.testing import CliRunner

from rti_rig.cli import app

pytestmark = [pytest.mark.pty, pytest.mark.e2e]

runner = CliRunner()
SOURCE = CONFIGS / "example_dome_48.toml"


def _config(tmp: Path, frames: Path) -> Path:
    """The shipped hardware example with an image sequence for its camera, and no settle
    before a shot: the config's 0.2 s is slept in earnest on this real-clock stack (1.2 s of a
    5-image run's ~2 s), and a file read from a sequence does not wait on an LED's light."""
    text = SOURCE.read_text()
    head, rest = text.split("[camera.device]", 1)
    tail = rest[rest.index("[timing]") :]
    assert "settle_s = 0.2" in tail, tail
    tail = tail.replace("settle_s = 0.2", "settle_s = 0.0", 1)
    head = head.replace("width = 6000", "width = 32").replace("height = 4000", "height = 24")
    device = (
        '[camera.device]\nkind = "opencv"\nbackend = "images"\nresponse = "srgb"\n'
        f'device = "{frames}/f_%03d.png"\n\n'
    )
    shutil.copy(CONFIGS / "example_dome_48.lp", tmp / "example_dome_48.lp")
    path = tmp / "sequence_dome.toml"
    path.write_text(head + device + tail)
    return path


@pytest.fixture
def dome(monkeypatch):  # type: ignore[no-untyped-def]
    with shipped_dome_on_pty(monkeypatch, SOURCE) as firmware:
        yield firmware


def test_a_session_shot_from_an_image_sequence_is_not_resumed(dome, tmp_path: Path) -> None:
    frames = tmp_path / "frames"
    frames.mkdir()
    for i in range(5):  # five files for eight lights: the sequence runs out at the sixth
        cv2.imwrite(str(frames / f"f_{i:03d}.png"), np.full((24, 32, 3), 40 + 30 * i, np.uint8))
    config = _config(tmp_path, frames)
    out = tmp_path / "s"
    r = runner.invoke(app, ["run", str(config), "--out", str(out), "--lights", "8"])
    assert r.exit_code != 0, r.output
    stopped = " ".join(r.output.split())
    assert "--resume" not in stopped, stopped  # it had said "Continue with: rti-rig run --resume"
    assert "It cannot be resumed: its camera is an image sequence" in stopped, stopped
    assert sorted(p.name for p in out.glob("image_*.jpg"))[-1:] == ["image_005.jpg"], r.output
    r = runner.invoke(app, ["fit", str(out), "--out", str(tmp_path / "fit")])
    verdict = " ".join(r.output.split())
    assert "the session is not finished" in verdict, verdict
    assert "--resume" not in verdict, verdict  # it had said "continue it with rti-rig run --resume"
    assert "its camera is an image sequence" in verdict, verdict
    shutil.rmtree(tmp_path / "fit", ignore_errors=True)
    for i in range(5, 8):  # the user adds the files the run lacked, then resumes
        cv2.imwrite(str(frames / f"f_{i:03d}.png"), np.full((24, 32, 3), 200, np.uint8))
    before = sorted((p.relative_to(out), p.read_bytes()) for p in out.rglob("*") if p.is_file())
    r = runner.invoke(app, ["run", "--resume", str(out)])
    assert r.exit_code == 2, r.output
    said = " ".join(r.output.split())
    assert "image sequence" in said and "backend = 'images'" in said, said
    assert "this session cannot be resumed (nothing was changed)" in said, said
    assert "from its first file" in said, said
    assert f"rti-rig run {config} --out {out}-again" in said, said  # free, beside it
    assert "DIR" not in said and "ACQ/" not in said, said  # no placeholder to paste
    assert "Traceback" not in r.output
    after = sorted((p.relative_to(out), p.read_bytes()) for p in out.rglob("*") if p.is_file())
    assert after == before  # refused before the folder was touched


def test_a_stop_once_every_image_is_in_says_what_fit_will_say(
    dome, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A SIGTERM as the last image is committed (held by the commit, acted on after it): every
    image is in, but the run has not recorded its end, and it cannot be resumed to record it.
    It had said "the session is complete, nothing is left to resume", and fit then called the
    session "not finished"."""
    import signal

    from rti_rig.runtime.session import SessionFolder

    frames = tmp_path / "frames"
    frames.mkdir()
    for i in range(4):
        cv2.imwrite(str(frames / f"f_{i:03d}.png"), np.full((24, 32, 3), 40 + 30 * i, np.uint8))
    real_write = SessionFolder.write_step

    def write_step(self, i, *args, **kwargs):  # type: ignore[no-untyped-def]
        if i == 3:  # the last image: the commit holds the signal until it is written
            signal.raise_signal(signal.SIGTERM)
        return real_write(self, i, *args, **kwargs)

    monkeypatch.setattr(SessionFolder, "write_step", write_step)
    out = tmp_path / "s"
    argv = ["run", str(_config(tmp_path, frames)), "--out", str(out), "--lights", "4"]
    r = runner.invoke(app, [*argv, "--no-verdict"])
    said = " ".join(r.output.split())
    assert r.exit_code == 143 and "Emergency stop (SIGTERM)" in said, said
    assert len(list(out.glob("image_*.jpg"))) == 4 and "Traceback" not in said, said
    assert "session is complete" not in said and "--resume" not in said, said
    assert "every image is in, but the stop came before the run recorded its end" in said, said
    fit_it = f"rti-rig fit {out} --out {out}-fit` fits the images as they are."
    assert f"{fit_it} It cannot be resumed: its camera is an image sequence" in said, said
    r = runner.invoke(app, ["fit", str(out), "--out", str(tmp_path / "fit")])
    assert "the session is not finished" in " ".join(r.output.split()), r.output


def _run_with_lp_refused(tmp_path: Path, after: int, out: str) -> tuple[Path, str]:
    """A 6-image run of the image-sequence dome into ``out`` (the argument as given; the
    session is ``tmp_path/s``) whose lights.lp writes are refused (ENOSPC) after ``after`` of
    them: the session, and what the run said, as one line."""
    import errno

    from rti_rig.testing.disk_faults import failing_writes

    frames = tmp_path / "frames"
    frames.mkdir()
    for i in range(6):
        cv2.imwrite(str(frames / f"f_{i:03d}.png"), np.full((24, 32, 3), 40 + 30 * i, np.uint8))
    config = _config(tmp_path, frames)
    with failing_writes("lp", after=after, errno_code=errno.ENOSPC):
        r = runner.invoke(app, ["run", str(config), "--out", out, "--lights", "6"])
    assert r.exit_code == 2, r.output
    return tmp_path / "s", " ".join(r.output.split())


def test_a_lights_lp_its_write_failed_is_exported_by_a_command_that_pastes(
    dome, tmp_path: Path
) -> None:
    """A session that cannot be resumed and whose lights.lp could not be written (a full disk)
    is told to export one from the journal: it had said ``--out FILE.lp``, which pasted wrote a
    file named FILE.lp; the command names the session's own lights.lp, and pasted writes it."""
    import shlex

    from rti_rig.core.lp_format import read_lp

    out, said = _run_with_lp_refused(tmp_path, 0, str(tmp_path / "s"))
    assert "lights.lp could not be written and is missing" in said, said
    command = said.split("(`", 1)[1].split("` writes one from the journal", 1)[0]
    assert command == f"rti-rig export-lp {out} --out {out / 'lights.lp'}", command
    done = runner.invoke(app, shlex.split(command)[1:])
    assert done.exit_code == 0, done.output
    assert len(read_lp(out / "lights.lp")) == 1


@pytest.mark.parametrize("given", ["path", "dot"])
def test_a_lights_lp_left_short_is_exported_beside_the_session_never_inside_it(
    dome, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, given: str
) -> None:
    """lights.lp there but short of the journal (its second write refused): the export advised
    is a file beside the session. It had been ``lights-2.lp`` inside it, which relight-cli given
    the folder reads first (the first .lp by name, case ignored) while fit and RTIBuilder read
    lights.lp: one folder, two listings. The session's lights.lp is left as it was. A session
    given as ``--out .`` (run from inside it) is named by its absolute path: the hint had ended
    in a ValueError there ('.' has no name to add '.lp' to)."""
    import shlex

    from rti_rig.core.lp_format import read_lp

    (tmp_path / "s").mkdir()
    if given == "dot":
        monkeypatch.chdir(tmp_path / "s")
    out, said = _run_with_lp_refused(tmp_path, 1, "." if given == "dot" else str(tmp_path / "s"))
    assert "lights.lp could not be written and lists only 1 of them" in said, said
    command = said.split("(`", 1)[1].split("` writes one from the journal", 1)[0]
    shown = "." if given == "dot" else str(out)
    assert command == f"rti-rig export-lp {shown} --out {tmp_path / 's.lp'}", command
    assert "lights-2.lp inside it would be the .lp relight-cli reads first" in said, said
    own = (out / "lights.lp").read_bytes()
    done = runner.invoke(app, shlex.split(command)[1:])
    assert done.exit_code == 0, done.output
    assert len(read_lp(tmp_path / "s.lp")) == 2
    assert (out / "lights.lp").read_bytes() == own  # never replaced
    assert sorted(p.name for p in out.glob("*.lp")) == ["lights.lp"]
