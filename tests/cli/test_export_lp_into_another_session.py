"""`export-lp A --out B/x.lp` is refused when B is another session's folder.

Why: every session names its images alike (image_001.jpg, ...), and relight, RTIBuilder and
`rti-rig fit` read an `.lp`'s names beside it. The file was written there with a note to move
it; left in B, relight or RTIBuilder given it paired B's images with A's lights without a word
(`rti-rig fit B/x.lp` fitted them too, its verdict naming the lights the journal disagrees on).
"""

from __future__ import annotations

import shlex
from pathlib import Path

from conftest import CONFIGS, said
from typer.testing import CliRunner

from rti_rig.cli import app

runner = CliRunner()
RIG = CONFIGS / "simulated_dome.toml"


def _session(tmp_path: Path, name: str, lights: str) -> Path:
    s = tmp_path / name
    r = runner.invoke(app, ["run", str(RIG), "--out", str(s), "--lights", lights, "--no-verdict"])
    assert r.exit_code == 0, r.output
    return s


def test_an_export_into_another_sessions_folder_is_refused(tmp_path: Path) -> None:
    a, b = _session(tmp_path, "séance a", "6"), _session(tmp_path, "séance b", "8")
    before = sorted(p.name for p in b.iterdir())

    for out in (b / "a.lp", b / "linear" / "a.lp"):
        r = runner.invoke(app, ["export-lp", str(a), "--out", str(out), "--linear"])

        assert r.exit_code == 2, r.output
        assert "Traceback" not in r.output
        text = said(r)
        assert f"--out {out} is in another session ({b})" in text, text
        assert "names " + str(a) + "'s images (linear/image_001.tif, ...)" in text, text
        assert not out.exists()
    assert sorted(p.name for p in b.iterdir()) == before


def test_an_export_into_its_own_session_or_outside_any_is_written(tmp_path: Path) -> None:
    a = _session(tmp_path, "a", "6")
    for out in (a / "mine.lp", tmp_path / "outside.lp"):
        r = runner.invoke(app, ["export-lp", str(a), "--out", str(out)])
        assert r.exit_code == 0, r.output
        assert out.is_file()


def test_an_export_into_a_subfolder_of_another_session_is_refused_for_what_it_is(
    tmp_path: Path,
) -> None:
    """B's images do not lie in B/exports (nor A's --linear names in B/linear): the refusal had
    said they did; it says the .lp would sit inside B, where it could be taken for B's own."""
    a, b = _session(tmp_path, "séance a", "6"), _session(tmp_path, "séance b", "8")
    (b / "exports").mkdir()
    before = sorted(p.name for p in b.iterdir())

    for out, linear in ((b / "exports" / "a.lp", []), (b / "linear" / "a.lp", ["--linear"])):
        r = runner.invoke(app, ["export-lp", str(a), "--out", str(out), *linear])

        assert r.exit_code == 2, r.output
        assert "Traceback" not in r.output
        text = said(r)
        assert f"--out {out} is in another session ({b})" in text, text
        assert "own images of the same names lie" not in text, text
        assert (
            f"the .lp would sit inside the session {b.name}, where relight or RTIBuilder (or "
            f"whoever opens {b.name}) could take it for that session's own; write it into {a} "
            "or outside any session"
        ) in text, text
        assert not out.exists()
    assert sorted(p.name for p in b.iterdir()) == before


def test_an_export_beside_another_sessions_images_says_they_lie_there(tmp_path: Path) -> None:
    a, b = _session(tmp_path, "a", "6"), _session(tmp_path, "b", "8")

    r = runner.invoke(app, ["export-lp", str(a), "--out", str(b / "a.lp")])

    assert r.exit_code == 2, r.output
    assert "where b's own images of the same names lie" in said(r), r.output


def test_an_export_into_its_own_session_says_so_and_never_replaces_its_lights_lp(
    tmp_path: Path,
) -> None:
    """An export written at the top of its own session had been written without a word: it
    says it is inside the session, beside the session's lights.lp left as captured (and which
    of the two `rti-rig fit` of the folder reads); --force onto lights.lp itself is refused,
    and a lights.lp the session lost is written again, said as such."""
    a = _session(tmp_path, "séance a", "6")
    own = a / "lights.lp"
    captured = own.read_bytes()
    wide = CliRunner(env={"COLUMNS": "400"})

    r = wide.invoke(app, ["export-lp", str(a), "--out", str(a / "mine.lp"), "--linear"])
    assert r.exit_code == 0, r.output
    text = said(r)
    assert (
        f"{a / 'mine.lp'} is written inside the session {a}, beside its own lights.lp, which "
        f"is left as captured (a session's files are never replaced); rti-rig fit {a} reads "
        f"lights.lp: give {a / 'mine.lp'} itself to use this one"
    ) in text, text
    assert own.read_bytes() == captured

    # the session's own lights.lp, already the journal's listing: left as it is
    r = wide.invoke(app, ["export-lp", str(a), "--out", str(own), "--force"])
    assert r.exit_code == 0, r.output
    assert f"{own} is already the listing of the journal: left as it is" in said(r), said(r)
    assert own.read_bytes() == captured and not (a / "recovered").exists()

    own.unlink()  # lost: export-lp writes it again, and says what it wrote
    # an export beside the lost lights.lp says the command that writes it again, pasteable
    # (the folder's name holds a space: it was printed unquoted)
    r = wide.invoke(app, ["export-lp", str(a), "--out", str(a / "other.lp")])
    assert r.exit_code == 0, r.output
    assert (
        f"rti-rig export-lp {shlex.quote(str(a))} --out {shlex.quote(str(own))} writes the "
        "session's own lights.lp again"
    ) in said(r), said(r)
    (a / "other.lp").unlink()
    r = wide.invoke(app, ["export-lp", str(a), "--out", str(own)])
    assert r.exit_code == 0, r.output
    assert (
        f"{own} is the session's own lights.lp, which was missing: written again from its journal"
    ) in said(r), said(r)
    assert own.read_bytes() == captured

    r = wide.invoke(app, ["export-lp", str(a), "--out", str(tmp_path / "outside.lp")])
    assert r.exit_code == 0, r.output
    assert "inside the session" not in said(r), said(r)


def test_an_export_into_its_own_session_says_which_lp_relight_cli_reads_there(
    tmp_path: Path,
) -> None:
    """relight-cli given a folder reads the first .lp there by name, case ignored (relight's
    ImageSet: QDir::entryList({"*.lp"})[0]). An export named before lights.lp (the guide's
    demo_linear.lp) became the .lp relight-cli read for the session without a word."""
    a = _session(tmp_path, "séance a", "6")
    wide = CliRunner(env={"COLUMNS": "400"})

    r = wide.invoke(app, ["export-lp", str(a), "--out", str(a / "mine.lp")])
    assert r.exit_code == 0, r.output
    assert f"relight-cli given {a} reads the first .lp there by name, still lights.lp" in said(r)

    r = wide.invoke(app, ["export-lp", str(a), "--out", str(a / "Demo_linear.lp"), "--linear"])
    assert r.exit_code == 0, r.output
    assert (
        f"relight-cli given {a} reads the first .lp there by name, now Demo_linear.lp, not "
        "lights.lp: move Demo_linear.lp out of the folder before giving the folder to relight-cli"
    ) in said(r), said(r)
    assert (a / "Demo_linear.lp").is_file() and (a / "lights.lp").is_file()


def test_an_export_outside_its_session_says_what_relight_cli_needs_moved(tmp_path: Path) -> None:
    """An export written elsewhere was always told to move the session's lights.lp out for
    relight-cli, also when its own name sorts first (the guide's demo_linear.lp): relight-cli
    reads that one first anyway, so the session lost its lights.lp for nothing."""
    a = _session(tmp_path, "séance a", "6")
    wide = CliRunner(env={"COLUMNS": "400"})
    lead = "relight-cli, which reads the first .lp of a folder by name (case ignored)"

    r = wide.invoke(app, ["export-lp", str(a), "--out", str(tmp_path / "Demo_linear.lp")])
    assert r.exit_code == 0, r.output
    assert f"{lead}, then reads Demo_linear.lp there: nothing else needs moving" in said(r)
    assert "lights.lp out" not in said(r), said(r)

    (a / "archive.lp").write_text("")  # another .lp before lights.lp and session.lp
    r = wide.invoke(app, ["export-lp", str(a), "--out", str(tmp_path / "session.lp")])
    assert r.exit_code == 0, r.output
    assert (
        f"for {lead}, move that folder's archive.lp and lights.lp out too (`rti-rig export-lp"
    ) in said(r), said(r)

    r = wide.invoke(app, ["export-lp", str(a), "--out", str(tmp_path / "lights.lp")])
    assert r.exit_code == 0, r.output
    assert "move that folder's archive.lp and lights.lp out too" in said(r)
    assert "lights.lp there would be replaced by the move" in said(r), said(r)
