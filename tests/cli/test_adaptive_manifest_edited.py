"""An adaptive session whose manifest.json was edited or damaged is refused before anything in
its folder moves, naming the key and the way on; put back, the resume continues as it began.

``rti-rig run --resume S`` had trusted the manifest's ``adaptive`` settings: with the table or
its ``max_lights`` removed, every image after the 4 starting lights was moved to
``recovered/`` as "outside the schedule" and the session called complete with 4 images (QA
verdict "good"); ``max_lights`` edited down set the later images aside and only then refused;
null or -1 did the same and then crashed or blamed a ``--lights`` never given; a value of
another type ended in "unexpected TypeError … please report it"; an ``upper_factor`` of 0.5
made the stop claim its target on an "upper" estimate half the point estimate.
"""

from __future__ import annotations

import json
import shutil
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest
from conftest import SMALL_DOME, interrupted, journal, said, write_config
from typer.testing import CliRunner

from rti_rig.cli import app

runner = CliRunner()


@pytest.fixture(scope="module")
def cut(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    """(config, session): an 8-light adaptive session stopped after 6 images."""
    base = tmp_path_factory.mktemp("edited")
    cfg = write_config(base, SMALL_DOME)
    out = base / "s"
    interrupted(cfg, out, 5, lights=8)
    assert len(journal(out)) == 6
    return cfg, out


def _files(out: Path) -> dict[str, bytes]:
    return {p.relative_to(out).as_posix(): p.read_bytes() for p in out.rglob("*") if p.is_file()}


def _drop(key: str) -> Callable[[dict[str, Any]], None]:
    return lambda m: m["adaptive"].pop(key)


def _set(key: str, value: object) -> Callable[[dict[str, Any]], None]:
    return lambda m: m["adaptive"].__setitem__(key, value)


EDITS: dict[str, tuple[Callable[[dict[str, Any]], None], str]] = {
    "table removed": (
        lambda m: m.pop("adaptive"),
        'has no "adaptive" table of settings, though its schedule\'s method is "adaptive"',
    ),
    "max_lights removed": (_drop("max_lights"), 'has no max_lights in its "adaptive" settings'),
    "max_lights null": (_set("max_lights", None), "says max_lights null"),
    "max_lights -1": (_set("max_lights", -1), "says max_lights -1"),
    "max_lights below the journal": (
        _set("max_lights", 5),
        "journal.jsonl records steps beyond what manifest.json plans (its adaptive settings' "
        "max_lights 5; line 6 of journal.jsonl)",
    ),
    "until_error_deg a word": (_set("until_error_deg", "abc"), 'says until_error_deg "abc"'),
    "start_lights null": (_set("start_lights", None), "says start_lights null"),
    "upper_factor below 1": (_set("upper_factor", 0.5), "says upper_factor 0.5"),
    "lamps without a distance": (_set("lamps", {"field_width_mm": 40}), "says lamps"),
}


@pytest.mark.parametrize("edit", list(EDITS))
def test_an_edited_adaptive_manifest_is_refused_before_anything_moves(
    cut: tuple[Path, Path], tmp_path: Path, edit: str
) -> None:
    _cfg, original = cut
    out = tmp_path / "s"
    shutil.copytree(original, out)
    path = out / "manifest.json"
    kept = path.read_bytes()
    manifest = json.loads(kept)
    change, expected = EDITS[edit]
    change(manifest)
    path.write_text(json.dumps(manifest), encoding="utf-8")
    before = _files(out)

    r = runner.invoke(app, ["run", "--resume", str(out)], terminal_width=400)
    text = said(r)
    assert r.exit_code == 2, r.output
    assert "Traceback" not in r.output and "please report it" not in text, r.output
    assert expected in text, text
    assert "restore manifest.json" in text and "from a backup copy of the folder" in text, text
    assert _files(out) == before  # nothing moved, rewritten or set aside

    path.write_bytes(kept)  # put back as told: the session continues to its 8 lights
    r = runner.invoke(app, ["run", "--resume", str(out), "--no-verdict"])
    assert r.exit_code == 0, r.output
    assert len(journal(out)) == 8 and not (out / "recovered").exists()
