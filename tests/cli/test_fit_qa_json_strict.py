"""qa.json is JSON every reader parses: a measure not taken is ``null``, never ``NaN``.

Python's ``json`` had written ``"neighbour_gain_ratio": NaN`` for the images the QA did not
compare with their neighbours (most of a good session): not JSON (RFC 8259), refused whole by
a browser's ``JSON.parse`` and by ``jq``.
"""

from __future__ import annotations

import json
from pathlib import Path

from typer.testing import CliRunner

from rti_rig.cli import app
from tests.fit_sessions import make_session


def _refuse(token: str) -> None:
    raise ValueError(f"non-standard JSON number {token}")


def test_qa_json_holds_no_nan(tmp_path: Path) -> None:
    session, _, _ = make_session(tmp_path / "s", size=(48, 56))
    r = CliRunner().invoke(app, ["fit", str(session), "--out", str(tmp_path / "f"), "--no-ptm"])
    assert r.exit_code == 0, r.output
    qa = json.loads((tmp_path / "f" / "qa.json").read_text(), parse_constant=_refuse)
    assert any(c.get("neighbour_gain_ratio", 0) is None for c in qa["images"])
