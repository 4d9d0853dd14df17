"""The application layer: rig configs, the composition root and the use cases.

The only layer (with the CLI above it) that sees every other one: it reads a rig config, builds
the real or simulated devices (``compose``) and offers the use cases the CLI calls
(``rti_rig.app.usecases``), which work without typer.
"""
