"""A port that did not close cleanly is told from a failure that leaves the lights in doubt by
its type, never by its wording.

Before, :func:`unsafe_failures` dropped every failure whose text began "port close: ": a
rewording of the dome's close line would have made it unsafe, and any other failure worded
alike (an all-off's error quoting a port) would have been taken as safe.
"""

from __future__ import annotations

import json

from rti_rig.runtime.lighting import PortCloseFailure, port_close_failures, unsafe_failures


class _Lights:
    """A lighting whose last close said ``said`` (None: it closed cleanly)."""

    def __init__(self, said: str | None) -> None:
        self.said = said

    def port_close_failure(self) -> str | None:
        return self.said


def test_a_port_close_is_no_doubt_about_the_lights_whatever_its_words() -> None:
    (close,) = port_close_failures(_Lights("the adapter went away"))  # type: ignore[arg-type]
    reworded = PortCloseFailure("the dome's serial port could not be released")
    off = "all LEDs off: no answer from the dome"
    assert unsafe_failures([close, reworded, off]) == [off]


def test_a_text_that_reads_like_a_port_close_is_still_unsafe() -> None:
    """Only the record the lighting's close made is safe to leave out: a plain text with the
    same words (an all-off's failure worded so, a record read back from a file) is kept."""
    alike = "port close: all LEDs off was not acknowledged"
    assert unsafe_failures([alike]) == [alike]


def test_the_manifest_keeps_the_text_readers_know() -> None:
    """On disk a port close is the same ``"port close: …"`` string as before (a str)."""
    failures = port_close_failures(_Lights("[Errno 5] Input/output error"))  # type: ignore[arg-type]
    assert json.loads(json.dumps(failures)) == ["port close: [Errno 5] Input/output error"]
    assert port_close_failures(_Lights(None)) == []  # type: ignore[arg-type]
