"""The use cases: what each ``rti-rig`` command does, as Python functions that need no typer.

Each takes a request object (a frozen dataclass of the command's options), checks it in one
place before anything moves or is written, does the work and returns what happened; the CLI
(:mod:`rti_rig.cli`) only parses, calls one of these and prints. Errors are
:class:`rti_rig.core.errors.RtiRigError` with a message that names the file, key or option.

- :mod:`.plan` — :func:`~.plan.plan_lights`, :func:`~.plan.draw_plan_figure`
- :mod:`.calibrate` — :func:`~.calibrate.calibrate_lights`
- :mod:`.probe` — :func:`~.probe.probe`
- :mod:`.adaptive` — the adaptive acquisition loop (``run --adaptive``)
"""
