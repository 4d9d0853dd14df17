"""A resume on another rig is refused once, naming every difference, with the way out.

``rti-rig run rig_configs/emulated_dome.toml --resume DIR`` of a session shot on
``rig_configs/simulated_dome.toml`` was refused naming only "camera size: 512×512 → 256×256 …
set it back to continue": what the images are was checked, and refused, before the rest.
With the size matched, the same config was refused again for its backend, all 48 LEDs moved,
its firmware profile and its scene (docs/guide.md §7 promises the refusal names each
difference). The user fixed one thing, ran again and was told the next, and "set it back" is
the wrong advice when the whole rig is another one: the way out is the session's own config
(the path its manifest records) or a new session. What is refused, and that nothing is
captured, is unchanged.
"""

from __future__ import annotations

from pathlib import Path

from conftest import CONFIGS, cut_new_session, journal, said
from typer.testing import CliRunner

from rti_rig.cli import app

runner = CliRunner()
SIMULATED = CONFIGS / "simulated_dome.toml"
EMULATED = CONFIGS / "emulated_dome.toml"


def _cut(out: Path, config: Path = SIMULATED) -> None:
    """A 6-light session on ``config``, cancelled after three images as Ctrl-C does."""
    from rti_rig.app.usecases.session import NewSessionRequest

    cut_new_session(NewSessionRequest(config, out, 6), after_step=2)
    assert len(journal(out)) == 3


def _resume(out: Path, config: Path | None, *extra: str):  # type: ignore[no-untyped-def]
    args = ["run", *([str(config)] if config else []), "--resume", str(out), "--no-verdict"]
    return runner.invoke(app, [*args, *extra], terminal_width=400)


def _files(out: Path) -> dict[str, bytes]:
    return {p.relative_to(out).as_posix(): p.read_bytes() for p in out.rglob("*") if p.is_file()}


def test_another_rig_is_refused_once_naming_every_difference_and_the_way_out(
    tmp_path: Path,
) -> None:
    out = tmp_path / "r1"
    _cut(out)
    before = _files(out)
    for flag in ([], ["--accept-rig-change"]):
        r = _resume(out, EMULATED, *flag)
        text = said(r)
        assert r.exit_code == 2, r.output
        assert "Traceback" not in text, r.output
        assert f"{EMULATED} describes another rig than the one this session began on" in text
        for difference in (
            "backend: simulated → emulated",
            "light positions: 48 of 48 LEDs moved",
            "dome firmware profile: none → default",
            "camera size: 512×512 → 256×256",
            "simulated scene: changed",
        ):
            assert difference in text, text
        # what no flag accepts: the backend (since 2026-12-04: a backend change had gone
        # through with --accept-rig-change) and what the images are
        assert "Its backend is 'emulated', and this session was begun on 'simulated'" in text
        assert "camera size, simulated scene change what this session's images are" in text, text
        assert "cannot be accepted into this session, even with --accept-rig-change" in text
        # the way out: the session's own config, as its manifest records it, or a new session
        assert f"Resume with the session's own config, {SIMULATED}" in text, text
        assert f"{out / 'manifest.json'} under rig.config_path): rti-rig run --resume {out};" in (
            text
        )
        assert f"or shoot a new session on this rig: rti-rig run {EMULATED} --out " in text
        assert "set it back" not in text, text
        assert _files(out) == before  # nothing captured, nothing written

    # the command it gives continues the session
    r = _resume(out, None)
    assert r.exit_code == 0, r.output
    assert len(journal(out)) == 6


def test_another_rig_with_the_camera_size_matched_is_still_another_rig(tmp_path: Path) -> None:
    """Once the size was set back as told, the same config was refused for the rest, with the
    advice to accept it as a deliberate change."""
    out = tmp_path / "r1"
    _cut(out)
    text = EMULATED.read_text(encoding="utf-8")
    lp = (CONFIGS / "example_dome_48.lp").resolve()
    text = text.replace('lp_file = "example_dome_48.lp"', f'lp_file = "{lp.as_posix()}"')
    text = text.replace("width = 256", "width = 512").replace("height = 256", "height = 512")
    matched = tmp_path / "emulated_512.toml"
    matched.write_text(text, encoding="utf-8")
    r = _resume(out, matched)
    said_ = said(r)
    assert r.exit_code == 2, r.output
    assert f"{matched} describes another rig than the one this session began on" in said_
    assert "4 differences: backend: simulated → emulated" in said_, said_
    assert "camera size" not in said_, said_
    assert "add --accept-rig-change to record it" not in said_, said_
    assert "not for another rig" in said_ and "rti-rig run --resume" in said_, said_
    assert len(journal(out)) == 3


def test_the_sessions_own_config_edited_twice_is_told_both_edits_at_once(tmp_path: Path) -> None:
    """An exposure and a scene edited in the session's own config: the refusal named the
    exposure alone, and the scene only once the exposure was set back. Neither is accepted,
    with the flag or without (a dry run's scene is its object: another seed had gone through
    with --accept-rig-change, and the session held images of two objects, fitted as one)."""
    own = tmp_path / "dome.toml"
    original = SIMULATED.read_text(encoding="utf-8")
    own.write_text(original, encoding="utf-8")
    out = tmp_path / "r1"
    _cut(out, own)
    before = _files(out)
    own.write_text(
        original.replace("exposure_s = 0.05", "exposure_s = 0.04").replace("seed = 0", "seed = 1"),
        encoding="utf-8",
    )
    for flag in ([], ["--accept-rig-change"]):
        r = _resume(out, None, *flag)
        text = said(r)
        assert r.exit_code == 2, r.output
        assert f"{own} does not describe the rig this session began on (" in text, text
        assert "exposure (s): 0.05 → 0.04; simulated scene: changed)" in text, text
        assert "Exposure (s), simulated scene change what this session's images are" in text, text
        assert "It is this session's own config, edited since the session began: set it back" in (
            text
        )
        assert "another rig" not in text, text
    own.write_text(original.replace("seed = 0", "seed = 1"), encoding="utf-8")
    for flag in ([], ["--accept-rig-change"]):
        r = _resume(out, None, *flag)
        text = said(r)
        assert r.exit_code == 2, r.output
        assert "Simulated scene changes what this session's images are" in text, text
        assert "cannot be accepted into this session, even with --accept-rig-change" in text, text
        assert "set it back" in text, text
    assert _files(out) == before  # nothing captured, nothing written
    own.write_text(original, encoding="utf-8")  # set back, as told: the session goes on
    r = _resume(out, None)
    assert r.exit_code == 0, r.output
    assert len(journal(out)) == 6


def test_the_new_session_advised_for_a_dome_with_fewer_leds_fits_on_it(tmp_path: Path) -> None:
    """A 10-light session resumed on a dome of 8 LEDs and another camera: the refusal's
    new-session command had repeated --lights 10, which that dome refuses."""
    from conftest import SMALL_DOME, write_config

    from rti_rig.app.usecases.session import NewSessionRequest

    twelve = write_config(tmp_path, SMALL_DOME, "twelve.toml")
    out = tmp_path / "s"
    cut_new_session(NewSessionRequest(twelve, out, 10), after_step=2)
    eight = write_config(
        tmp_path,
        SMALL_DOME.replace(
            "  { elevation_deg = 50.0, count = 4, azimuth_offset_deg = 45.0 },\n", ""
        ).replace("width = 64", "width = 48"),
        "eight.toml",
    )
    r = _resume(out, eight)
    text = said(r)
    assert r.exit_code == 2, r.output
    assert f"rti-rig run {eight} --out " in text and " --lights 8" in text, text
    assert "--lights 10" not in text, text
