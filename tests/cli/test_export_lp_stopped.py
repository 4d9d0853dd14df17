"""A stop (SIGTERM, Ctrl-C) of ``export-lp`` while it writes the .lp leaves no file half
written, neither under the name asked for nor beside it, and says what is on disk.

``export-lp`` had no SIGTERM handler: a SIGTERM (``timeout``, a scheduler) ended it at once,
mid-write, leaving its hidden ``.NAME.lp.tmp`` beside the .lp asked for, and said nothing.
The signal is raised from inside the write (the temporary file half written), in-process.
"""

from __future__ import annotations

import signal
from pathlib import Path
from typing import Any

import pytest
from conftest import dome_session
from typer.testing import CliRunner

from rti_rig.cli import app


class _NotHandled(Exception):
    """What the test's own SIGTERM handler raises: the export installed none of its own."""


@pytest.fixture(scope="module")
def small_session(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return dome_session(tmp_path_factory.mktemp("export_stop"), "relief", 64, 6)


@pytest.mark.parametrize("stop", [signal.SIGTERM, signal.SIGINT], ids=["SIGTERM", "Ctrl-C"])
def test_a_stop_mid_write_leaves_no_half_written_lp(
    small_session: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, stop: signal.Signals
) -> None:
    import rti_rig.core.lp_format as lp_format

    real_open = open

    class HalfThenStopped:
        def __init__(self, stream: Any) -> None:
            self._stream = stream

        def write(self, text: str) -> int:
            self._stream.write(text[: len(text) // 2])
            self._stream.flush()
            signal.raise_signal(stop)  # the stop lands with half the file written
            return self._stream.write(text[len(text) // 2 :])

        def __enter__(self) -> HalfThenStopped:
            return self

        def __exit__(self, *exc: object) -> None:
            self._stream.close()

    def opened(path: Any, *args: Any, **kwargs: Any) -> Any:
        return HalfThenStopped(real_open(path, *args, **kwargs))

    monkeypatch.setattr(lp_format, "open", opened, raising=False)
    out = tmp_path / "out"
    out.mkdir()
    lp = out / "export.lp"

    def not_handled(signum: int, frame: Any) -> None:
        raise _NotHandled()

    before = signal.signal(signal.SIGTERM, not_handled)  # never the runner's default (death)
    try:
        r = CliRunner().invoke(app, ["export-lp", str(small_session), "--out", str(lp)])
    finally:
        signal.signal(signal.SIGTERM, before)
    assert not isinstance(r.exception, _NotHandled), "export-lp has no SIGTERM handler"
    assert r.exit_code == 128 + int(stop), r.output
    assert list(out.iterdir()) == []  # neither the .lp nor its temporary file
    said = "SIGTERM" if stop == signal.SIGTERM else "Ctrl-C"
    assert f"Stopped ({said}): no .lp was written to {lp}." in r.output, r.output
