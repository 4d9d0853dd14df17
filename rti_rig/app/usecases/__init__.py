"""Use cases: what a command does, as plain Python (no typer, no printing).

Each use case takes a request dataclass and returns a result; the CLI (or a script, a notebook,
a GUI) parses its input into the request, calls the use case and presents what comes back.
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
