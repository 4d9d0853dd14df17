"""`fit --model` refuses an unknown name listing exactly the names --help offers, each of which
the fit accepts: it had answered "known: lambert, hsh1, ptm, hsh2, hsh3, ps, ps-robust (or
robust-ps)", without ``auto`` (the default) and naming robust PS otherwise than --help."""

from __future__ import annotations

import re
from pathlib import Path

from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.reconstruct.registry import MODEL_NAMES, model_spec

runner = CliRunner()


def names_in(text: str) -> set[str]:
    """The model names of a listing ("auto (evidence-based choice), ps, robust-ps (or
    ps-robust), …"), the names in parentheses after "or" included."""
    text = re.sub(r"\(evidence-based choice\)", "", text)
    return set(re.findall(r"[a-z][a-z0-9]*(?:-[a-z]+)?", text.replace("or ", ""))) - {""}


def test_an_unknown_model_is_refused_with_the_names_help_offers(tmp_path: Path) -> None:
    r = runner.invoke(app, ["fit", str(tmp_path), "--out", str(tmp_path / "o"), "--model", "foo"])
    assert r.exit_code == 2 and "Traceback" not in r.output, r.output
    said = " ".join(r.output.split())
    assert "--model 'foo' is not known; choose " in said, said
    refused = names_in(said.split("choose ", 1)[1])
    shown = runner.invoke(app, ["fit", "--help"]).output.replace("│", " ")  # rich's box
    help_text = " ".join(shown.split())
    offered = re.search(r"--model <str> (.*?)\. \[default: auto\]", help_text)
    assert offered is not None, help_text
    assert refused == names_in(offered.group(1))
    assert {"auto", "robust-ps", "ps-robust"} <= refused
    # each name listed is one the fit takes, and every registry name is listed
    for name in refused - {"auto"}:
        model_spec(name)
    assert set(MODEL_NAMES) <= refused
    assert not (tmp_path / "o").exists()
