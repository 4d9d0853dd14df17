"""`rti-rig check` and `rti-rig probe`: a rig's self-test, and which dome firmware answers."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from rti_rig.cli.app import app, fail, out
from rti_rig.core.errors import RtiRigError


@app.command()
def check(
    rig_config: Annotated[Path, typer.Argument(help="Rig config TOML to check.")],
    intensity: Annotated[
        float, typer.Option("--intensity", help="LED drive level for the walk, in (0, 1].")
    ] = 0.2,
) -> None:
    """Self-test the rig's lights: a dome lights each LED in turn and reports what answered; an
    arm visits poses spanning its band (checking where it really got to), flashes the lamp at
    each and parks."""
    from rti_rig.app.usecases.check import CheckRequest, check_rig

    try:
        report = check_rig(CheckRequest(rig_config, intensity))
    except RtiRigError as exc:
        raise fail(exc) from None
    for line in report.lines():
        out.print(line, highlight=False)
    if not report.ok:
        raise typer.Exit(code=1)


@app.command()
def probe(
    port: Annotated[str, typer.Argument(help="Serial port of the dome, e.g. /dev/ttyACM0.")],
) -> None:
    """Identify which known dome firmware answers on PORT (least intrusive probes first; none
    lights an LED, and a dome that boots lit is switched off, or you are told it could not be)
    and print the rig-config lines to use."""
    from rti_rig.app.usecases.probe import ProbeRequest
    from rti_rig.app.usecases.probe import probe as run_probe

    result = run_probe(ProbeRequest(port))
    for line in result.lines():
        out.print(line, highlight=False, markup=False)
    if result.profile is None:
        raise typer.Exit(code=1)
