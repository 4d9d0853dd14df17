"""What a run says `rti-rig fit` will make of its lights is what `rti-rig fit` then makes.

A run of 4 raking lights (one azimuth, ``--allow-no-normals``) said "fit.ptm and fit.rti only"
and, in the next note, "will make a normal map"; plain `rti-rig fit` then made nothing (without
photometric stereo its simplest model needs 5 lights). Each case here runs a session through
the CLI, reads the promise from the run's own words, fits, and compares with the files written.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest
from conftest import CONFIGS
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.core.lp_format import LpEntry, write_lp

DOME = str(CONFIGS / "simulated_dome.toml")
#: What the notes call each output, and the file that shows it was written.
FILES = {"normal map": "normals.png", "fit.ptm": "fit.ptm", "fit.rti": "fit.rti"}


def _raking(path: Path, az_el: list[tuple[float, float]]) -> Path:
    """A hand-written plan of LEDs of the shipped dome at azimuth 0° and 180° only."""
    a, e = np.radians(np.array(az_el)).T
    dirs = np.stack([np.cos(e) * np.cos(a), np.cos(e) * np.sin(a), np.sin(e)], axis=1)
    write_lp(path, [LpEntry(f"i{k}.jpg", tuple(d)) for k, d in enumerate(dirs)])
    return path


def _said(args: list[str]) -> str:
    r = CliRunner().invoke(app, args)
    text = " ".join(r.output.split())
    assert r.exit_code == 0, text
    return text


def _named(words: str) -> set[str]:
    return {f for w, f in FILES.items() if w in words}


def _promise(said: str, normals: bool) -> tuple[set[str], set[str]] | None:
    """The files the run's notes say plain `rti-rig fit` writes, and those it says it does not;
    None where they say it fits nothing. Where no note speaks of them, every file (less the
    normal maps of lights that cannot determine a normal, which their own note says)."""
    if "--model auto cannot fit them" in said or "will write nothing" in said:
        assert "will make" not in said and "will write the" not in said, said  # one story
        return None
    if m := re.search(
        r"`rti-rig fit`(?: with its default --model auto)? will (?:make|write) (.+?) "
        r"(?:but no|without) (.+?)[(.;]",
        said,
    ):
        return _named(m.group(1)), _named(m.group(2))
    every = set(FILES.values()) if normals else {"fit.ptm", "fit.rti"}
    return every, set(FILES.values()) - every


def _fit(session: Path, out: Path, *model: str) -> tuple[int, set[str]]:
    r = CliRunner().invoke(app, ["fit", str(session), "--out", str(out), "--no-qa", *model])
    return r.exit_code, {p.name for p in out.glob("*")} if out.exists() else set()


def _kept(said: str, session: Path, tmp: Path, normals: bool) -> None:
    promise = _promise(said, normals)
    code, written = _fit(session, tmp / "fit")
    if promise is None:
        assert code == 2 and not written, (said, written)
    else:
        made, not_made = promise
        assert code == 0, said
        assert made <= written, (said, written)
        assert not (not_made & written), (said, written)
    # the fit by name the note offers instead writes what it says
    for model, words in re.findall(
        r"`rti-rig fit --model (\w+)` (?:writes|makes) (.+?)[(;,]", said
    ):
        code, written = _fit(session, tmp / f"fit_{model}", "--model", model)
        assert code == 0 and _named(words) <= written, (model, words, written)


@pytest.mark.parametrize("n", [3, 4, 5, 6])
def test_run_lights_n_keeps_its_word(tmp_path: Path, n: int) -> None:
    s = tmp_path / "s"
    said = _said(["run", DOME, "--lights", str(n), "--out", str(s), "--no-verdict"])
    _kept(said, s, tmp_path, normals=True)


@pytest.mark.parametrize(
    "az_el",
    [
        [(0, 10), (0, 40), (0, 70), (180, 10)],
        [(0, 10), (0, 40), (0, 70), (180, 10), (180, 40)],
    ],
)
def test_a_raking_plan_keeps_its_word(tmp_path: Path, az_el: list[tuple[float, float]]) -> None:
    plan, s = _raking(tmp_path / "raking.lp", az_el), tmp_path / "s"
    said = _said(
        ["run", DOME, "--plan", str(plan), "--out", str(s), "--no-verdict", "--allow-no-normals"]
    )
    assert "captured as asked (--allow-no-normals)" in said
    assert "normal map but" not in said  # lights that give none were promised one
    _kept(said, s, tmp_path, normals=False)


def test_an_adaptive_stop_keeps_its_word(tmp_path: Path) -> None:
    s = tmp_path / "s"
    said = _said(
        ["run", DOME, "--adaptive", "--until-error", "45", "--out", str(s), "--no-verdict"]
    )
    assert "reached the normal-error target" in said
    _kept(said, s, tmp_path, normals=True)


def test_a_raking_plan_made_by_plan_keeps_its_word(tmp_path: Path) -> None:
    """`rti-rig plan --allow-no-normals` says the same of its lights as run does."""
    text = (CONFIGS / "simulated_dome.toml").read_text()
    start, end = text.index("rings = ["), text.index("]\n", text.index("rings = [")) + 2
    rig = tmp_path / "ring.toml"
    ring = "rings = [{ elevation_deg = 0.0, count = 20, azimuth_offset_deg = 0.0 }]\n"
    rig.write_text(text[:start] + ring + text[end:])
    plan, s = tmp_path / "p.lp", tmp_path / "s"
    said = _said(
        [
            *("plan", "--rig", str(rig), "--lights", "4", "--objective", "relight"),
            *("--out", str(plan), "--allow-no-normals"),
        ]
    )
    assert "normal map but" not in said
    _said(
        [
            "run",
            str(rig),
            "--plan",
            str(plan),
            "--out",
            str(s),
            "--no-verdict",
            "--allow-no-normals",
        ]
    )
    _kept(said, s, tmp_path, normals=False)
