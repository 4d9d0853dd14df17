"""The `rti-rig` command line: one module per command, each a thin layer over a use case.

A command parses its options into a request, calls one function of
:mod:`rti_rig.app.usecases` and prints what comes back; the shared application object, consoles
and helpers are in :mod:`rti_rig.cli.app`. Importing this package registers every command, in
the order ``--help`` lists them.
"""

import importlib

from rti_rig.cli.app import app, main, reflow_command_help

#: The command modules, in the order of ``rti-rig --help``.
COMMAND_MODULES = ("session", "plan", "check", "calibrate", "fit", "bench")

for _module in COMMAND_MODULES:
    importlib.import_module(f"rti_rig.cli.{_module}")

from rti_rig.cli.bench import bench_app  # noqa: E402  (registered by the loop above)

for _app in (app, bench_app):
    reflow_command_help(_app)

__all__ = ["COMMAND_MODULES", "app", "main"]
