"""The facts of a stopped run, read from folders the real session writer wrote.

Why: ``run``'s stop wording had read some ten facts of the session folder inline (are all
images in? did this run record its end? is ``lights.lp`` whole? …); they are read once by
:func:`read_run_ending`, and each is checked here against the folder state that decides it,
so that a fact read wrongly fails here by name, not as one sentence among ten in the CLI.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest

from rti_rig.core.devices import Frame
from rti_rig.runtime.disowned import MARKER, disown
from rti_rig.runtime.run_ending import read_run_ending
from rti_rig.runtime.session import LP_NAME, RAW_DIR, SessionFolder

FIELDS: dict[str, Any] = {
    "planned_direction": (0.0, 0.0, 1.0),
    "actual_direction": (0.0, 0.0, 1.0),
    "rig_start_s": 0.0,
    "light_s": 0.0,
    "settle_s": 0.0,
    "capture_s": 0.0,
}


def _frame(level: int) -> Frame:
    return Frame(
        pixels=np.full((4, 4, 3), level, np.uint16),
        exposure_s=0.1,
        gain=100.0,
        white_level=65535,
        timestamp_s=0.0,
        metadata={},
    )


def _session(
    root: Path,
    total: int,
    shot: int,
    reason: str | None,
    header: dict[str, Any] | None = None,
    source_result: dict[str, Any] | None = None,
) -> SessionFolder:
    """A session of ``total`` steps, ``shot`` of them written, its run finished with
    ``reason`` (None: the run has not reached its teardown's ``finish``)."""
    folder = SessionFolder.create(root, total)
    folder.begin({"rig": {}, "schedule": {"steps": [{}] * total}, **(header or {})})
    records = [folder.write_step(i, _frame(1000 + i), {**FIELDS, "led": i}) for i in range(shot)]
    if reason is not None:
        folder.finish(records, {"finish_reason": reason}, {}, source_result)
    return folder


def test_a_run_stopped_midway_has_images_kept_but_not_all_in(tmp_path: Path) -> None:
    ending = read_run_ending(_session(tmp_path / "s", 4, 2, "emergency_stop"), 4)
    assert (ending.images_kept, ending.total_steps) == (2, 4)
    assert (ending.lp_whole, ending.lp_listed) == (True, 2)
    assert ending.begun and not ending.last_run_completed and not ending.run_completed
    assert not ending.end_recorded and not ending.every_image_in and ending.stopped_short
    assert ending.labels_disowned is None and not ending.holds_no_image


def test_a_completed_run_has_every_image_in_and_its_end_recorded(tmp_path: Path) -> None:
    ending = read_run_ending(_session(tmp_path / "s", 3, 3, "completed"), 3)
    assert ending.every_image_in and ending.end_recorded and ending.run_completed
    assert not ending.stopped_short and not ending.adaptive_outcome_unrecorded


def test_every_image_in_before_the_run_recorded_its_end(tmp_path: Path) -> None:
    """The last image committed, the stop before ``finish``: every image is in (the count
    says so), though neither the run nor the session recorded completing."""
    folder = _session(tmp_path / "s", 3, 3, None)
    ending = read_run_ending(folder, 3)
    assert ending.every_image_in
    assert not ending.end_recorded and not ending.last_run_completed
    folder.finish([], {"finish_reason": "emergency_stop"}, {})
    assert not read_run_ending(folder, 3).end_recorded


def test_an_adaptive_run_its_rule_ended_short_is_all_in(tmp_path: Path) -> None:
    """Fewer images than the maximum, the run completed: all in (its rule ended it), short,
    its outcome recorded with the end."""
    folder = _session(
        tmp_path / "s", 5, 3, "completed", {"adaptive": {"max": 5}}, {"reason": "until_error"}
    )
    ending = read_run_ending(folder, 5)
    assert ending.every_image_in and ending.stopped_short and ending.run_completed
    assert not ending.adaptive_outcome_unrecorded


def test_an_adaptive_run_stopped_before_its_end_has_its_outcome_unrecorded(
    tmp_path: Path,
) -> None:
    folder = _session(tmp_path / "s", 3, 3, None, {"adaptive": {"max": 3}})
    ending = read_run_ending(folder, 3)
    assert ending.every_image_in and ending.adaptive_outcome_unrecorded
    # not an adaptive session: nothing adaptive to record
    assert not read_run_ending(_session(tmp_path / "t", 3, 3, None), 3).adaptive_outcome_unrecorded


def test_an_adaptive_run_stopped_short_of_its_maximum_is_not_all_in(tmp_path: Path) -> None:
    """Fewer images than the maximum and the run did not complete: more is left to shoot."""
    ending = read_run_ending(_session(tmp_path / "s", 5, 3, "emergency_stop"), 5)
    assert not ending.every_image_in and ending.stopped_short


def test_a_lights_lp_behind_the_journal_is_not_whole(tmp_path: Path) -> None:
    folder = _session(tmp_path / "s", 3, 3, "completed")
    lp = folder.root / LP_NAME
    lines = lp.read_text().splitlines()
    lp.write_text("\n".join(["1", *lines[2:3]]) + "\n")  # the count line, then one light
    ending = read_run_ending(folder, 3)
    assert (ending.lp_whole, ending.lp_listed) == (False, 1)
    assert not ending.every_image_in  # all shot, but not all listed
    lp.unlink()
    assert (read_run_ending(folder, 3).lp_whole, read_run_ending(folder, 3).lp_listed) == (
        False,
        0,
    )


def test_disowned_labels_are_named_by_their_marker(tmp_path: Path) -> None:
    folder = _session(tmp_path / "s", 2, 2, "completed")
    assert read_run_ending(folder, 2).labels_disowned is None
    disown(folder.root, "the proof frame was never shot")
    assert read_run_ending(folder, 2).labels_disowned == folder.root / MARKER


def test_a_run_that_never_began_wrote_nothing(tmp_path: Path) -> None:
    folder = SessionFolder.create(tmp_path / "s", 3)
    ending = read_run_ending(folder, 3)
    assert not ending.begun and ending.images_kept == 0 and ending.holds_no_image
    assert not (tmp_path / "s").exists()


def test_a_begun_run_without_an_image_holds_none_until_a_camera_file_is_left(
    tmp_path: Path,
) -> None:
    folder = _session(tmp_path / "s", 3, 0, "emergency_stop")
    ending = read_run_ending(folder, 3)
    assert ending.begun and ending.images_kept == 0 and ending.holds_no_image
    (folder.root / RAW_DIR).mkdir(exist_ok=True)
    (folder.root / RAW_DIR / "IMG_0001.CR2").write_bytes(b"a download for a failed step")
    assert not read_run_ending(folder, 3).holds_no_image


@pytest.mark.parametrize("reason", ["completed", "emergency_stop"])
def test_a_reopened_session_not_begun_reads_the_earlier_runs_end(
    tmp_path: Path, reason: str
) -> None:
    """A --reshoot-lost of a completed session stopped before it wrote anything: its last run
    entry is the earlier run's, completed, which is not this run's completing."""
    root = tmp_path / "s"
    _session(root, 3, 3 if reason == "completed" else 2, reason)
    (root / "image_002.jpg").unlink()  # lost since capture: what --reshoot-lost is for
    folder = SessionFolder.reopen(root, reshoot_lost=reason == "completed")
    ending = read_run_ending(folder, 3)
    assert not ending.begun
    assert ending.last_run_completed is (reason == "completed")
    assert not ending.run_completed
    folder.begin({"rig": {}, "schedule": {"steps": [{}] * 3}})
    begun = read_run_ending(folder, 3)  # this run's entry now: not yet completed
    assert begun.begun and not begun.last_run_completed and not begun.run_completed


def test_a_refused_reshoot_of_a_run_that_recorded_no_end_reads_its_journal_once(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """--reshoot-lost of a session whose run recorded no end is refused, saying how it ended
    from the journal's last image; that journal is the one the resume already read (it had
    been read a second time for the words)."""
    import rti_rig.runtime.unrecorded_end as unrecorded_end
    from rti_rig.runtime.session import SessionError, prepare_resume, unlock_session

    root = tmp_path / "s"
    _session(root, 3, 1, None)
    unlock_session(root)

    def read_again(root: Path) -> None:
        raise AssertionError("the journal was read again")

    monkeypatch.setattr(unrecorded_end, "_journal_lines", read_again)
    with pytest.raises(SessionError, match="its last run: it stopped without recording why"):
        prepare_resume(root, reshoot_lost=True)
