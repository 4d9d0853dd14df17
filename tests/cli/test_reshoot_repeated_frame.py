"""A frame delivered twice is in the command the verdict offers to reshoot in place.

Found through a watched-folder camera that delivered one picture under two lights: the verdict
said "reshoot: image_001 (…), image_002 …, image_005 (the same picture as image_001 …
reshoot it)" and offered ``rti-rig run --resume S --reshoot image_001,image_002,image_003``,
without image_005. The simulated camera delivers no stale frame, so the verdict's report is
given here; the session and the command's run are real.
"""

from __future__ import annotations

import shlex
from pathlib import Path
from types import SimpleNamespace

from typer.testing import CliRunner

from rti_rig.app.usecases.fit import reshoot_in_place
from rti_rig.cli import app
from rti_rig.reconstruct.qa_repeated import repeated_problem

REPO = Path(__file__).resolve().parents[2]
runner = CliRunner()


def _image(name: str, *problems: str) -> SimpleNamespace:
    return SimpleNamespace(name=name, problems=problems)


def test_a_repeated_frame_is_reshot_in_place_with_the_others(tmp_path: Path) -> None:
    session = tmp_path / "s"
    config = str(REPO / "rig_configs" / "simulated_dome.toml")
    r = runner.invoke(app, ["run", config, "--out", str(session), "--lights", "8"])
    assert r.exit_code == 0, r.output
    report = SimpleNamespace(
        lights_likely_wrong=False,
        lost_unfitted=(),
        reshoot=[
            _image("image_002", "misfired or dim light: 30% of the brightness …"),
            _image("image_005", repeated_problem("image_001")),
            _image("image_007", "saturated: 40% of its pixels clipped"),  # shot the same again
        ],
    )
    said = reshoot_in_place(session, report)
    assert said is not None
    assert said.startswith(
        "to reshoot image_002, image_005 in place, once what made the light wrong is mended"
    ), said
    assert "what made the camera deliver an earlier frame is mended" in said, said
    command = said.split(": rti-rig ", 1)[1]
    assert command.endswith("--reshoot image_002,image_005"), command
    r = runner.invoke(app, shlex.split(command))  # as printed
    assert r.exit_code == 0, r.output

    # a repeated frame alone: the camera named, not an LED
    report.reshoot = [_image("image_005", repeated_problem("image_001"))]
    said = reshoot_in_place(session, report) or ""
    assert "camera deliver an earlier frame" in said and "LED" not in said, said
