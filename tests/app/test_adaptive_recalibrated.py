"""An interrupted adaptive session resumed on a re-measured dome (`run --resume`).

A calibration `.lp` written again differs from the session's by rounding: the same rig, the
session continues as it began (it had been refused, "light positions: changed", and with
--accept-rig-change refused again at step 1). A real move is refused with how far the LEDs
moved; accepted with --accept-rig-change, the steps taken are kept as recorded and the rest
is decided on the rig as it is now (every such resume had been refused), also across a second
interruption.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from conftest import journal, manifest, said, write_config
from typer.testing import CliRunner

from rti_rig.cli import app

runner = CliRunner()

#: a small dome (8 LEDs at 20°, 4 at 50°: symmetric, so its ties are broken by the last digit)
RINGS = ((20.0, 8, 0.0), (50.0, 4, 45.0))

DOME_LP = """
name = "small-lp"
kind = "dome"
backend = "simulated"
[dome]
layout = "lp"
lp_file = "dome.lp"
[camera]
width = 64
height = 64
exposure_s = 0.05
[scene]
seed = 3
"""


def ring_directions(raise_deg: float = 0.0) -> np.ndarray:
    out = []
    for el, count, offset in RINGS:
        e = np.radians(el + raise_deg)
        for k in range(count):
            a = np.radians(offset + 360.0 * k / count)
            out.append([np.cos(e) * np.cos(a), np.cos(e) * np.sin(a), np.sin(e)])
    return np.asarray(out)


def write_lp(path: Path, dirs: np.ndarray, decimals: int = 6) -> None:
    lines = [str(len(dirs))]
    lines += [
        f"led_{i:02d}.jpg " + " ".join(f"{x:.{decimals}f}" for x in d) for i, d in enumerate(dirs)
    ]
    path.write_text("\n".join(lines) + "\n")


def cut_session(cfg: Path, out: Path, after_step: int) -> None:
    """An adaptive session of 8 lights begun as `run` begins it (the rig identity recorded),
    cancelled once step ``after_step`` (0-based) is committed."""
    from rti_rig.app.usecases.session import NewSessionRequest, open_new_session
    from rti_rig.app.usecases.session import run_opened_session as run_it

    opened = open_new_session(NewSessionRequest(cfg, out, lights=8, adaptive=True))
    run_it(opened, *_cancel_after(after_step))
    assert len(journal(out)) == after_step + 1


def _cancel_after(after_step: int):  # type: ignore[no-untyped-def]
    from rti_rig.runtime.controller import CancelToken, StepCompleted

    cancel = CancelToken()

    def on_event(event) -> None:  # type: ignore[no-untyped-def]
        if isinstance(event, StepCompleted) and event.index == after_step:
            cancel.cancel()

    return cancel, on_event


@pytest.fixture(scope="module")
def reference(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, list[int]]:
    """The dome's config on its `.lp`, and the LEDs an uninterrupted session fires."""
    base = tmp_path_factory.mktemp("recal")
    write_lp(base / "dome.lp", ring_directions())
    cfg = write_config(base, DOME_LP)
    out = base / "whole"
    r = runner.invoke(app, ["run", str(cfg), "--out", str(out), "--adaptive", "--lights", "8"])
    assert r.exit_code == 0, r.output
    return cfg, [s["led"] for s in journal(out)]


def _own_copy(reference: tuple[Path, list[int]], tmp_path: Path) -> Path:
    cfg, _ = reference
    write_lp(tmp_path / "dome.lp", ring_directions())
    return write_config(tmp_path, cfg.read_text())


def test_a_dome_re_measured_to_rounding_resumes_as_it_began(
    reference: tuple[Path, list[int]], tmp_path: Path
) -> None:
    cfg = _own_copy(reference, tmp_path)
    out = tmp_path / "cut"
    cut_session(cfg, out, after_step=1)  # within the start: its LEDs are a tie on this dome
    # the .lp measured again: each position within a micro-radian, written with more digits
    rng = np.random.default_rng(7)
    noisy = ring_directions() + rng.uniform(-8e-7, 8e-7, (12, 3))
    write_lp(tmp_path / "dome.lp", noisy / np.linalg.norm(noisy, axis=1)[:, None], 9)
    r = runner.invoke(app, ["run", "--resume", str(out), "--no-verdict"])
    assert r.exit_code == 0, r.output
    assert "light positions" not in said(r)
    assert [s["led"] for s in journal(out)] == reference[1]
    assert not any(run.get("rig_change") for run in manifest(out)["runs"])


def test_a_dome_whose_leds_moved_is_refused_by_how_much_and_continues_once_accepted(
    reference: tuple[Path, list[int]], tmp_path: Path
) -> None:
    cfg = _own_copy(reference, tmp_path)
    out = tmp_path / "cut"
    cut_session(cfg, out, after_step=4)
    shot = [s["led"] for s in journal(out)]
    write_lp(tmp_path / "dome.lp", ring_directions(raise_deg=0.3))
    r = runner.invoke(app, ["run", "--resume", str(out), "--no-verdict"])
    assert r.exit_code == 2, r.output
    assert "light positions: 12 of 12 LEDs moved, by up to 0.30°" in said(r)
    assert "add --accept-rig-change" in said(r)
    # the config is untouched: what to put back is the .lp it reads (it had been told to set
    # the config back, from a recorded copy that holds no position)
    assert "The config itself is as the session began; the light calibration it reads" in said(r)
    assert "dome.lp" in said(r) and "edited since" not in said(r)

    from rti_rig.app.usecases.session import (
        ResumeRequest,
        open_resumed_session,
        run_opened_session,
    )

    # accepted, and interrupted again after one more light
    opened = open_resumed_session(ResumeRequest(out, accept_rig_change=True))
    run_opened_session(opened, *_cancel_after(5))
    assert len(journal(out)) == 6
    # the next resume needs no flag: the change is recorded, and the steps taken on the rig
    # as it was are not decided again on this one
    r = runner.invoke(app, ["run", "--resume", str(out), "--no-verdict"])
    assert r.exit_code == 0, r.output
    steps = journal(out)
    assert len(steps) == 8 and len({s["led"] for s in steps}) == 8
    assert [s["led"] for s in steps[:5]] == shot  # as recorded
    # the lights fired after the change are where the re-measured dome has them
    moved = ring_directions(raise_deg=0.3)
    for s in steps[5:]:
        assert np.allclose(s["actual_direction"], moved[s["led"]], atol=2e-6)
    changes = [run["rig_change"] for run in manifest(out)["runs"] if run.get("rig_change")]
    assert changes == [["light positions: 12 of 12 LEDs moved, by up to 0.30° (LED index 0)"]]
