"""A session shot on one dome firmware profile is not resumed on another without a word.

``rig_configs/emulated_nichlock.toml`` and ``rig_configs/emulated_minirti.toml`` describe the
same LED positions and camera on two controller boards: a stepping nichlock board, which
counts its LEDs in its wiring's order, and a minirti board, which addresses a 64-bit mask
(/work/shared/reference/dome-firmwares.md). Another board drives its LEDs with another command
set, timing and possibly numbering, so the same LED index may not be the same light: a resume
on the other config had gone on without complaint. It is refused naming both profiles and
``--accept-rig-change``, which records a deliberate change; a session recorded before the
profile was part of the rig's identity resumes as it did.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from conftest import CONFIGS, cut_new_session, journal, said
from typer.testing import CliRunner

from rti_rig.cli import app

runner = CliRunner()
NICHLOCK = CONFIGS / "emulated_nichlock.toml"
MINIRTI = CONFIGS / "emulated_minirti.toml"


def _cut(out: Path, config: Path = NICHLOCK) -> None:
    """A 6-light session on ``config`` (the nichlock dome), cancelled after three images as
    Ctrl-C does."""
    from rti_rig.app.usecases.session import NewSessionRequest

    cut_new_session(NewSessionRequest(config, out, 6), after_step=2)
    assert len(journal(out)) == 3


def _resume(out: Path, config: Path, *extra: str):  # type: ignore[no-untyped-def]
    args = ["run", str(config), "--resume", str(out), "--no-verdict", *extra]
    return runner.invoke(app, args, terminal_width=400)


@pytest.mark.e2e
def test_a_resume_on_another_firmware_profile_is_refused_naming_both(tmp_path: Path) -> None:
    out = tmp_path / "S"
    _cut(out)
    r = _resume(out, MINIRTI)
    text = said(r)
    assert r.exit_code == 2, r.output
    assert "Traceback" not in text, r.output
    assert f"{MINIRTI} does not describe the rig this session began on" in text, r.output
    assert "dome firmware profile: nichlock → minirti (another controller board" in text, text
    assert "add --accept-rig-change to record it" in text, r.output
    assert len(journal(out)) == 3  # nothing captured
    r = _resume(out, MINIRTI, "--accept-rig-change")  # a deliberate change: recorded
    text = said(r)
    assert r.exit_code == 0, r.output
    assert "rig change accepted" in text and "nichlock → minirti" in text, r.output
    assert len(journal(out)) == 6


@pytest.mark.e2e
def test_a_session_recorded_before_the_profile_was_in_the_identity_resumes(
    tmp_path: Path,
) -> None:
    out = tmp_path / "S"
    _cut(out)
    manifest = out / "manifest.json"
    data = json.loads(manifest.read_text(encoding="utf-8"))
    assert data["rig"]["identity"].pop("dome_firmware") == "nichlock"
    manifest.write_text(json.dumps(data, indent=1), encoding="utf-8")
    r = _resume(out, NICHLOCK)
    assert r.exit_code == 0, r.output
    assert "dome firmware" not in said(r), r.output
    assert len(journal(out)) == 6


def _protocol_variant(tmp_path: Path, protocol_extra: str, config: Path = NICHLOCK) -> Path:
    """The shipped nichlock config (or ``config``) with more keys in its
    [dome.serial.protocol] table."""
    text = config.read_text()
    assert "[dome.serial.protocol]\n" in text
    cfg = tmp_path / f"{config.stem}_variant.toml"
    cfg.write_text(
        text.replace("[dome.serial.protocol]\n", f"[dome.serial.protocol]\n{protocol_extra}")
    )
    return cfg


@pytest.mark.e2e
def test_a_resume_whose_config_describes_another_protocol_under_one_name_is_refused(
    tmp_path: Path,
) -> None:
    """The profile's name alone had been the identity: a config describing other LED numbering
    (here from 1) under the same name resumed as the same rig, so index k lit another LED. A
    session recorded before the protocol was part of the identity resumes as it did."""
    out = tmp_path / "S"
    _cut(out)
    r = _resume(out, _protocol_variant(tmp_path, "index_base = 1\n"))
    text = said(r)
    assert r.exit_code == 2 and "Traceback" not in text, r.output
    assert "dome protocol described in the config: changed" in text, text
    assert "profile name 'nichlock'" in text and "add --accept-rig-change" in text, text
    assert len(journal(out)) == 3  # nothing captured

    manifest = out / "manifest.json"
    data = json.loads(manifest.read_text(encoding="utf-8"))
    assert data["rig"]["identity"].pop("dome_protocol")
    manifest.write_text(json.dumps(data, indent=1), encoding="utf-8")
    r = _resume(out, NICHLOCK)
    assert r.exit_code == 0 and "dome protocol" not in said(r), r.output
    assert len(journal(out)) == 6


@pytest.mark.e2e
def test_a_protocol_renamed_or_given_unused_columns_resumes_as_the_same_rig(
    tmp_path: Path,
) -> None:
    """A protocol's ``name`` is a label, and ``columns`` only numbers ``{row}``/``{col}``,
    which the minirti board's commands do not use (0x42 + a 64-bit mask: the mask alone says
    which LED lights). Both had been in the protocol's digest, so a resume with either was
    refused as "its commands or LED numbering differ", which was untrue."""
    out = tmp_path / "S"
    _cut(out, MINIRTI)
    variant = _protocol_variant(tmp_path, 'name = "our-minirti"\ncolumns = 4\n', MINIRTI)
    r = _resume(out, variant)
    assert r.exit_code == 0 and "dome protocol" not in said(r), r.output
    assert len(journal(out)) == 6


def _minirti_64(tmp_path: Path, name: str, table: str) -> Path:
    """The shipped minirti dome with all 64 LEDs its firmware addresses: without a
    [dome.serial.protocol] table the built-in protocol is the board's, as named."""
    text = MINIRTI.read_text().replace("count = 12\n", "count = 64\n", 1)
    head, sep, rest = text.partition("[dome.serial.protocol]\n")
    assert sep and rest.startswith("led_count = 12 ")
    rest = rest.split("\n", 1)[1]
    cfg = tmp_path / f"{name}.toml"
    cfg.write_text(head + (sep + table if table else "") + rest)
    return cfg


@pytest.mark.e2e
def test_a_table_restating_the_builtin_protocol_resumes_as_the_same_rig(tmp_path: Path) -> None:
    """A session begun without a protocol table, resumed with one that changes nothing that
    addresses the LEDs (a longer boot wait), had been refused as "dome protocol described in
    the config: none → 4d016391974ed4e4"; reply timeouts and delays are not the rig."""
    out = tmp_path / "S"
    _cut(out, _minirti_64(tmp_path, "bare", ""))
    r = _resume(out, _minirti_64(tmp_path, "wait", "boot_wait_s = 3.0\n"))
    assert r.exit_code == 0 and "dome protocol" not in said(r), r.output
    assert len(journal(out)) == 6
