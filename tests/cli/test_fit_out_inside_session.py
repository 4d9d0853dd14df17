"""`rti-rig fit SESSION --out SESSION/fitout` is refused as `run --out SESSION/sub` is: it had
written the fit among the session's images and exited 0."""

from __future__ import annotations

from pathlib import Path

from typer.testing import CliRunner

from rti_rig.cli import app

ACQ = Path(__file__).resolve().parents[1] / "data" / "neuralrti_replay"
runner = CliRunner()
ADVICE = "give an --out outside it, so that each session stays a folder of its own"


def test_a_fit_or_a_batch_into_a_session_folder_is_refused_as_run_refuses_one(
    tmp_path: Path,
) -> None:
    session = tmp_path / "demo"
    r = runner.invoke(app, ["run", str(ACQ / "dirs.lp"), "--out", str(session), "--no-verdict"])
    assert r.exit_code == 0, r.output
    r = runner.invoke(app, ["run", str(ACQ / "dirs.lp"), "--out", str(session / "sub")])
    assert r.exit_code == 2 and ADVICE in " ".join(r.output.split()), r.output  # run's words
    for sources in ([session], [session, ACQ / "dirs.lp"]):  # one session, and a batch
        args = ["fit", *map(str, sources), "--out", str(session / "fitout"), "--no-qa"]
        r = runner.invoke(app, [*args, "--model", "ps"])
        said = " ".join(r.output.split())
        assert r.exit_code == 2, said
        assert f"--out {session / 'fitout'} is inside {session}, a session folder" in said, said
        assert ADVICE in said and "Traceback" not in said
        assert not (session / "fitout").exists()


def test_every_caller_of_a_batch_gets_the_refusal_before_anything_is_done(tmp_path: Path) -> None:
    """The batch use cases refuse a root inside a session themselves (only the command line
    had, so another caller made the batch folder inside the session and had each session's fit
    refused there); with a scheduler, before the cluster is reached."""
    import pytest

    from rti_rig.app.usecases.fit import FitRequest
    from rti_rig.app.usecases.fit_batch import run_batch
    from rti_rig.app.usecases.fit_dask import run_batch_dask
    from rti_rig.core.errors import RtiRigError

    session = tmp_path / "demo"
    r = runner.invoke(app, ["run", str(ACQ / "dirs.lp"), "--out", str(session), "--no-verdict"])
    assert r.exit_code == 0, r.output
    root = session / "fitout"
    sources = [session, ACQ / "dirs.lp"]
    template = FitRequest(session, root, model="ps", qa=False)
    unreachable = "tcp://127.0.0.1:9"  # never contacted: the refusal comes first
    for run in (
        lambda: run_batch(sources, root, template),
        lambda: run_batch_dask(sources, root, template),
        lambda: run_batch_dask(sources, root, template, unreachable),
    ):
        with pytest.raises(RtiRigError, match="a session folder") as refused:
            run()
        assert f"--out {root} is inside {session}" in str(refused.value)
        assert ADVICE in str(refused.value)
        assert not root.exists()
