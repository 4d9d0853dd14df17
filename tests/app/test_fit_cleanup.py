"""A fit that fails half-way leaves no open file and nothing half-written that looks like an
output: the .ptm/.rti writers' ``.part`` files and the float maps are removed, whether it
failed before the bands (reading the images again) or between two bands (Ctrl-C)."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

from rti_rig.app.usecases import fit as fit_usecase
from rti_rig.app.usecases.fit import FitRequest, local_bands, run_fit
from rti_rig.reconstruct.stack import ImageStack

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from fit_sessions import make_session


@pytest.fixture(scope="module")
def session(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return make_session(tmp_path_factory.mktemp("cleanup") / "s", size=(48, 64))[0]


def _left(out: Path) -> list[str]:
    return sorted(p.name for p in out.iterdir()) if out.exists() else []


def test_a_read_error_before_the_bands_leaves_no_partial_output(
    session: Path, tmp_path: Path, monkeypatch
) -> None:
    def unreadable(self, *args, **kwargs):  # type: ignore[no-untyped-def]
        raise OSError("disk went away")

    monkeypatch.setattr(ImageStack, "reference_level", unreadable)
    out = tmp_path / "out"
    with pytest.raises(OSError, match="disk went away"):
        run_fit(FitRequest(session, out, model="ps", qa=False))
    left = _left(out)
    assert not [n for n in left if n.endswith(".part") or n.endswith(".npy")], left


def test_an_interrupt_between_bands_removes_the_maps_and_part_files(
    session: Path, tmp_path: Path, monkeypatch
) -> None:
    monkeypatch.setattr(fit_usecase, "BAND_BUDGET_BYTES", 1)  # one row per band: several bands

    def interrupted(stack, plan, tiles):  # type: ignore[no-untyped-def]
        for i, item in enumerate(local_bands(stack, plan, tiles)):
            if i == 2:
                raise KeyboardInterrupt
            yield item

    out = tmp_path / "out"
    with pytest.raises(KeyboardInterrupt):
        run_fit(FitRequest(session, out, model="ps", qa=False), bands=interrupted)
    left = _left(out)
    assert not [n for n in left if n.endswith(".part") or n.endswith(".npy")], left
    # the same folder can be used again, and the fit then completes
    for name in left:
        (out / name).unlink()
    result = run_fit(FitRequest(session, out, model="ps", qa=False))
    assert (out / "normals.npy").exists() and (out / "fit.ptm").exists(), result.files
