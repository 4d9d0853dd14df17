"""What a user is told about the lights after a session or check ended early.

Never "lights are off" unless that was established: a dome reports the outcome of its last
all-off (acknowledged, sent to a firmware that never acknowledges, sent but unconfirmed, not
sent), an arm that its lamp-off was requested.
"""

from __future__ import annotations

from rti_rig.runtime.dome_policy import lights_state_sentence
from rti_rig.runtime.lighting import DomeLighting


def lights_state(rig, teardown_failed: bool = False) -> str:  # type: ignore[no-untyped-def]
    """One sentence on the lights of ``rig`` after its teardown (``teardown_failed``: the
    teardown's failures were printed just before, and the sentence points at them)."""
    lighting = rig.lighting
    if getattr(rig.loaded.config, "backend", None) == "replay":
        return "a replayed acquisition has no lights to switch off"
    own = getattr(lighting, "lights_state", None)
    if callable(own):  # a lighting that knows best what it can say (a camera-triggered dome)
        return str(own())
    if isinstance(lighting, DomeLighting):
        source = lighting.source
        if hasattr(source, "off_report"):
            return lights_state_sentence(source)
        return "lights were switched off"  # a simulated dome: its state is the simulation's
    carrier = getattr(lighting, "carrier", None)
    if getattr(carrier, "ever_connected", True) is False:
        if getattr(carrier, "commanded", True) is False:
            # never reached: no move, torque or lamp was commanded, nor could a stop be
            return "nothing was commanded: the arm could not be connected"
        # its connect failed after writing to a servo (goal = where it was, then torque on)
        return (
            "the arm's connection failed part-way, after settings were written to its servos: "
            "a servo may be holding its position under torque; switch the arm's power off "
            "before touching it"
        )
    return "lamp off and stop were requested" + (
        " (see the teardown problems above)" if teardown_failed else ""
    )
