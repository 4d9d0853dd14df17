"""The use cases: what each ``rti-rig`` command does, as Python functions that need no typer.

Each takes a request object (a frozen dataclass of the command's options), checks it in one
place before anything moves or is written, does the work and returns what happened; the CLI
(:mod:`rti_rig.cli`) only parses, calls one of these and prints. Errors are
:class:`rti_rig.core.errors.RtiRigError` with a message that names the file, key or option.

- :mod:`.session` — open a new, resumed or preview session and run it (below)
- :mod:`.plan` — :func:`~.plan.plan_lights`, :func:`~.plan.draw_plan_figure`
- :mod:`.calibrate` — :func:`~.calibrate.calibrate_lights`
- :mod:`.probe` — :func:`~.probe.probe`
- :mod:`.fit` — :func:`~.fit.run_fit`: normals, albedo, PTM/HSH and the QA verdict of a session
- :mod:`.adaptive` — the adaptive acquisition loop (``run --adaptive``)

Messages meant for the user along the way go to an optional ``on_note`` callback.

Sessions (:mod:`rti_rig.app.usecases.session`)::

    from rti_rig.app.usecases.session import (
        NewSessionRequest, ResumeRequest, PreviewRequest,
        open_new_session, open_resumed_session, open_preview_session, run_opened_session,
    )
    from rti_rig.runtime.controller import CancelToken

    opened = open_new_session(NewSessionRequest(Path("rig.toml"), Path("out"), lights=24))
    result = run_opened_session(opened, CancelToken(), on_event=print)

``open_*`` check everything they can before anything moves (counts, caps, the folder, the
rig's config against the session's), open the rig and check the schedule on it, meter the
exposure if asked, and return an :class:`~rti_rig.app.usecases.session.OpenedSession`.
``run_opened_session`` runs it (closing the rig whatever happens) and returns the controller's
:class:`~rti_rig.runtime.controller.SessionResult`. Failures are :class:`RtiRigError` subclasses
with a message for the user.
"""
