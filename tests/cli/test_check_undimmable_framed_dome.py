"""`rti-rig check` on a framed-profile dome configured with ``send_level = false`` walks each
LED fully on (the only level its light frames can ask for) and says so; a dome that dims is
walked at the check's intensity, said likewise.

Found by a review: the walk asked every LED for intensity 0.2, which the driver refuses on a
link without levels ("the framed profile is configured without intensity"), so the check of
a working dome failed all 48 LEDs. The dome is the shipped dry run (``emulated_dome.toml``,
its emulated board speaking the framed profile from docs/protocols/led-dome.md)."""

from __future__ import annotations

from pathlib import Path

from conftest import CONFIGS, shipped_variant
from typer.testing import CliRunner

from rti_rig.cli import app

LP = ('lp_file = "example_dome_48.lp"', f'lp_file = "{CONFIGS / "example_dome_48.lp"}"')
FRAMED = (
    'profile = "default"\n',
    'profile = "framed"\n',
)
NO_LEVEL = (
    "reconnect_attempts = 3\n",
    "reconnect_attempts = 3\n\n[dome.serial.framed]\nsend_level = false\n",
)


def _check(config: Path) -> tuple[int, str]:
    r = CliRunner().invoke(app, ["check", str(config)], terminal_width=400)
    return r.exit_code, " ".join(r.output.split())


def test_a_framed_dome_without_levels_is_walked_fully_on(tmp_path: Path) -> None:
    code, text = _check(shipped_variant(tmp_path, "emulated_dome.toml", (LP, FRAMED, NO_LEVEL)))
    assert code == 0, text
    assert "LEDs stepped: 48, passed: 48, failed: 0" in text, text
    assert (
        "each LED lit fully on (intensity 1, not the check's 0.2): the framed profile with "
        "send_level = false sends no level in its light frames"
    ) in text, text
    assert "without intensity" not in text and text.endswith("RESULT: PASS"), text


def test_a_dome_that_dims_is_walked_at_the_checks_intensity() -> None:
    code, text = _check(CONFIGS / "emulated_dome.toml")
    assert code == 0, text
    assert "each LED lit at intensity 0.2 " in text and "fully on" not in text, text
