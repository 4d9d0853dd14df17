"""A batch's attempt folders are named and read by one value (the names had been built and
matched in five places with two differing patterns)."""

from __future__ import annotations

from pathlib import Path

from rti_rig.app.usecases.fit_attempts import AttemptFolder, Kind


def test_a_name_reads_back_as_the_folder_it_names() -> None:
    for output in ("s1", "s1.x", "coin-day2"):
        made = AttemptFolder.new(output)
        for folder in (made, made.as_kind(Kind.EARLIER)):
            assert AttemptFolder.parse(folder.name, output) == folder
            assert AttemptFolder.parse(folder.name) == folder
            assert folder.pid is not None
            assert folder.path(Path("/o")) == Path("/o") / folder.name


def test_a_session_s_folders_are_told_from_another_s_whose_name_begins_alike() -> None:
    assert AttemptFolder.parse(".s1.x.77-abcd.partial", "s1") is None  # session s1.x's
    assert AttemptFolder.parse(".s1.partial", "s1") == AttemptFolder("s1", None, Kind.PARTIAL)
    assert AttemptFolder.parse(".s1.earlier", "s1") is None  # a swap's always names its attempt
    assert AttemptFolder.parse(".s1..partial", "s1") is None
    assert AttemptFolder.parse(".s1.77-abcd.partial", "s2") is None


def test_an_older_run_s_folder_names_no_process() -> None:
    assert AttemptFolder.parse(".s1.partial") is None
    assert AttemptFolder("s1", None, Kind.PARTIAL).pid is None
    assert AttemptFolder.parse(".s1.77-abcd.earlier") == AttemptFolder(
        "s1", "77-abcd", Kind.EARLIER
    )
