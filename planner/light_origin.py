"""Where the plan's preview light came from, as a fact code can compare.

Why a type: the origin had been display text (``"given"``, ``"estimated (Zheng-Chellappa)"``,
``"assumed (zenith)"``) that the planner and the app compared with ``== "given"`` and the app
then overwrote with a sentence; a change of wording would have changed what the plan did. The
words are the app's (:func:`rti_rig.app.usecases.plan.preview_light_said`), said once.
"""

from __future__ import annotations

from enum import Enum


class LightOrigin(Enum):
    """How the preview's light direction was had."""

    #: typed by the user (``--preview-light AZ,EL``)
    GIVEN = "given"
    #: read from a record of the shot (the session's manifest, an ``.lp``)
    RECORDED = "recorded"
    #: estimated from the image's shading (Zheng & Chellappa)
    ESTIMATED = "estimated"
    #: no direction could be estimated from the image: the zenith was assumed
    ZENITH_ASSUMED = "zenith assumed"

    @property
    def known(self) -> bool:
        """The light that fired is known (given or recorded), not guessed from the image: only
        then can the plan say the preview was shot outside its band."""
        return self in (LightOrigin.GIVEN, LightOrigin.RECORDED)
