"""A refit never replaces a current fit another attempt put in place while it ran.

Why: a batch on a Dask cluster whose scheduler is lost leaves its workers fitting the sessions
they had begun, and the user reruns at once. When such a session had an outgrown earlier fit,
both attempts refit it in partial folders of their own, and the one finishing second set the
first one's finished fit aside and put its own in its place: a finished output replaced.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from conftest import SMALL_DOME, said, write_config
from typer.testing import CliRunner

from rti_rig.app.usecases import fit_batch
from rti_rig.cli import app

runner = CliRunner()


def move_a_light(session: Path) -> None:
    """Move the third light of the session's lights.lp a little (a recalibrated dome): its
    earlier fit is outgrown."""
    head, *rows = (session / "lights.lp").read_text(encoding="utf-8").splitlines()
    name, x, y, _ = rows[2].split()
    x2, y2 = float(x) * 0.98, float(y) * 0.98
    rows[2] = f"{name} {x2:.6f} {y2:.6f} {(1.0 - x2 * x2 - y2 * y2) ** 0.5:.6f}"
    (session / "lights.lp").write_text("\n".join([head, *rows]) + "\n", encoding="utf-8")


def test_a_refit_finished_meanwhile_by_another_attempt_is_kept(tmp_path: Path, monkeypatch) -> None:
    cfg = write_config(tmp_path, SMALL_DOME)
    s, t, fb = tmp_path / "S", tmp_path / "T", tmp_path / "FB"
    for session in (s, t):
        r = runner.invoke(app, ["run", str(cfg), "--out", str(session), "--lights", "6"])
        assert r.exit_code == 0, r.output
    args = ["fit", str(s), str(t), "--out", str(fb), "--model", "ps", "--no-qa"]
    r = runner.invoke(app, args)
    assert r.exit_code == 0 and said(r).count(": done") == 2, r.output
    move_a_light(s)

    real = fit_batch.run_fit
    late: list[Any] = []

    def late_attempt_finishes_first(request: Any, bands: Any = None) -> Any:
        """This rerun's fit, once the late attempt (a worker of the lost batch) has put its
        refit of the same session in place."""
        monkeypatch.setattr(fit_batch, "run_fit", real)  # the late attempt runs the real fit
        item = fit_batch.fit_one(s, fb, request)
        late.append((item, (fb / "S").stat().st_ino))
        return real(request, bands)

    monkeypatch.setattr(fit_batch, "run_fit", late_attempt_finishes_first)
    r = runner.invoke(app, args)
    assert r.exit_code == 0, r.output
    ((item, placed),) = late
    assert item.outcome is fit_batch.Outcome.REFITTED, item
    assert (fb / "S").stat().st_ino == placed  # the late attempt's finished fit stands
    assert f"{s}: done{fit_batch.DONE_ELSEWHERE}" in said(r), r.output
    assert sorted(p.name for p in fb.iterdir()) == [
        "S",
        "T",
    ]  # nothing partial or set aside
