"""The `rti-rig` console entry point, kept apart from the command line it starts.

Why a module of its own: a console script imports its target before calling it, and
:mod:`rti_rig.cli` pulls in typer, rich and numpy — a few tenths of a second in which a Ctrl-C
would otherwise print Python's KeyboardInterrupt traceback. Nothing has been opened or moved
then, so the honest message is that nothing was done. This module imports nothing at load time.
"""

import sys

#: The exit status of a command stopped by Ctrl-C (128 + SIGINT), as the shell reports it.
INTERRUPTED_EXIT = 130


def main() -> None:
    """Import the command line and run it; a Ctrl-C during the import ends quietly."""
    try:
        from rti_rig.cli import main as run_cli
    except KeyboardInterrupt:
        sys.stderr.write("rti-rig: stopped while starting (Ctrl-C); nothing was done\n")
        raise SystemExit(INTERRUPTED_EXIT) from None
    run_cli()
