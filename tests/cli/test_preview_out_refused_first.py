"""`rti-rig preview` refuses an --out it cannot write before it says which LED it would fire.

Why: "note: no LED at az 135°, el 50°: the nearest ... led_036 ... is 14.5° away" was printed
above the refusal of an --out that is not empty or lies in a session: a word on a preview that
was never going to be shot.
"""

from __future__ import annotations

from pathlib import Path

from conftest import CONFIGS, said
from typer.testing import CliRunner

from rti_rig.cli import app

runner = CliRunner()
RIG = CONFIGS / "simulated_dome.toml"


def test_a_refused_out_says_only_the_refusal(tmp_path: Path) -> None:
    taken = tmp_path / "taken é"
    taken.mkdir()
    (taken / "notes.txt").write_text("mine")

    r = runner.invoke(app, ["preview", str(RIG), "--out", str(taken)])

    assert r.exit_code == 2, r.output
    text = said(r)
    assert "is not empty: refusing to write a session over existing files" in text, text
    assert "no LED at" not in text, text
    assert [p.name for p in taken.iterdir()] == ["notes.txt"]


def test_a_new_out_still_says_which_led_stands_in(tmp_path: Path) -> None:
    r = runner.invoke(app, ["preview", str(RIG), "--out", str(tmp_path / "new")])

    assert r.exit_code == 0, r.output
    assert "no LED at az 135°, el 50°: the nearest in the paper's 45–60° band" in said(r)


def test_the_led_standing_in_is_named_by_number_and_the_file_written(tmp_path: Path) -> None:
    """The note named the LED by the dome .lp's image name ("led_036"), a file of another
    acquisition, where the preview writes image_001.jpg: it names the LED by its number, as
    the session records it, and the file the preview wrote."""
    import json

    out = tmp_path / "new"
    r = runner.invoke(app, ["preview", str(RIG), "--out", str(out)])

    assert r.exit_code == 0, r.output
    text = said(r)
    step = json.loads((out / "manifest.json").read_text())["schedule"]["steps"][0]
    written = sorted(p.name for p in out.glob("*.jpg"))
    assert written == ["image_001.jpg"], written
    assert f"band, LED {step['led']} (az " in text, text
    assert "; the preview's image_001.jpg is shot under it" in text, text
    note = text[text.index("no LED at") : text.index("shot under it")]
    assert "led_" not in note, note  # the dome .lp's image name, not a file of this session
