"""`rti-rig check` on the shipped simulated dome says what it is: a simulation, with no firmware
to identify and no command to time, its walk timed on the simulation's clock.

Found by a front-door audit: the check said "simulated dome: unknown firmware, 48 LEDs" (as if
a board had answered and not been identified), "LEDs stepped: 48 … in 3.36 s" for a command
that ended in under 2 s of wall time (the simulation's clock, unnamed, where the arm's check
names it), and "light command round trip: median 0.00 ms (wall clock)" of commands no link
carried, a figure the check offers as a measured light_switch_s."""

from __future__ import annotations

from conftest import CONFIGS
from typer.testing import CliRunner

from rti_rig.cli import app

runner = CliRunner()


def test_check_of_the_simulated_dome_names_no_firmware_and_times_no_link() -> None:
    r = runner.invoke(app, ["check", str(CONFIGS / "simulated_dome.toml")])
    assert r.exit_code == 0, r.output
    said = " ".join(r.output.split())
    assert "simulated dome: no firmware (a simulation), 48 LEDs" in said, said
    assert "unknown firmware" not in said and "round trip" not in said, said
    assert "LEDs stepped: 48, passed: 48, failed: 0 in " in said, said
    assert " s on the rig's clock" in said and said.endswith("RESULT: PASS"), said
