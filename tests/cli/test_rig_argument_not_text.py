"""An image, a binary file, a folder or a config in another encoding given where a rig config
or an `.lp` goes, through every command that takes one: each says what the file is and what
to give, never Python's decoder's words.

Why: `run ACQ/image01.jpg --out S` said "not valid TOML: 'utf-8' codec can't decode byte 0xff
in position 0" (with a hint after it), and a binary file or a config saved in Windows ANSI
the decoder's words alone."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest
from conftest import CONFIGS
from typer.testing import CliRunner

from rti_rig.cli import app

ACQ = Path(__file__).resolve().parents[1] / "data" / "neuralrti_replay"
runner = CliRunner()


def _inputs(tmp_path: Path) -> dict[str, Path]:
    """A JPEG and a PNG of an acquisition (its dirs.lp beside them), a binary file, a folder."""
    acq = tmp_path / "acq"
    shutil.copytree(ACQ, acq)
    png = acq / "image01.png"
    png.write_bytes(b"\x89PNG\r\n\x1a\n" + (ACQ / "image01.jpg").read_bytes()[2:200])
    binary = tmp_path / "firmware.bin"
    binary.write_bytes(bytes(range(256)) * 8)
    folder = tmp_path / "empty"
    folder.mkdir()
    return {"jpeg": acq / "image01.jpg", "png": png, "binary": binary, "folder": folder}


COMMANDS = {
    "run": lambda f, t: ["run", str(f), "--out", str(t / "s")],
    "check": lambda f, t: ["check", str(f)],
    "plan": lambda f, t: ["plan", "--rig", str(f), "--out", str(t / "p.lp")],
    "fit": lambda f, t: ["fit", str(f), "--out", str(t / "f")],
    "export-lp": lambda f, t: ["export-lp", str(f), "--out", str(t / "e.lp")],
    "bench": lambda f, t: ["bench", "tradeoff", "--from", str(f)],
}


@pytest.mark.parametrize("command", list(COMMANDS))
def test_a_file_that_is_no_rig_or_lp_is_named_for_what_it_is(tmp_path: Path, command: str) -> None:
    for kind, given in _inputs(tmp_path).items():
        r = runner.invoke(app, COMMANDS[command](given, tmp_path))
        said = " ".join(r.output.split())
        assert r.exit_code == 2, (kind, said)
        assert said.startswith(f"error: {given}") or f" {given}" in said, (kind, said)
        assert "codec" not in said and "position" not in said, (kind, said)
        assert "Traceback" not in r.output, (kind, r.output)
        assert r.exception is None or isinstance(r.exception, SystemExit), (kind, r.exception)
        for out in ("s", "f", "p.lp", "e.lp"):
            assert not (tmp_path / out).exists(), (kind, out)
        if command in ("run", "check", "plan"):  # a rig config or an acquisition's .lp
            if kind in ("jpeg", "png"):
                image = "an image (JPEG)" if kind == "jpeg" else "an image (PNG)"
                assert f"this is {image}, not a rig config or an .lp: give the rig config" in said
                assert f"({given.parent} holds {given.parent / 'dirs.lp'}: give that)" in said
            if kind == "binary":
                assert "this is a binary file (not text), so not a rig config or an .lp" in said


def test_a_config_in_another_encoding_is_named_by_line_and_a_utf16_one_is_read(
    tmp_path: Path,
) -> None:
    """A config saved in Windows ANSI (an é as 0xe9) is told where and how to save it again;
    one saved as Notepad's "Unicode" (UTF-16 with its byte-order mark) is read."""
    text = (CONFIGS / "simulated_dome.toml").read_text(encoding="utf-8")
    assert "\nname = " in text
    ansi = tmp_path / "ansi.toml"
    ansi.write_bytes(text.replace("\nname = ", "\n# café\nname = ", 1).encode("latin-1"))
    r = runner.invoke(app, ["check", str(ansi)])
    said = " ".join(r.output.split())
    assert r.exit_code == 2 and "codec" not in said, said
    line = text.split("\nname = ")[0].count("\n") + 2
    assert f"{ansi}: line {line}: byte 0xe9 is not UTF-8 text" in said, said
    assert "save it again as UTF-8" in said
    unicode = tmp_path / "unicode.toml"
    unicode.write_bytes(text.encode("utf-16"))
    r = runner.invoke(app, ["check", str(unicode)])
    assert r.exit_code == 0 and "RESULT: PASS" in r.output, r.output
