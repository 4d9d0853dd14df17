"""Whether a set of lights can determine a surface normal, judged once for plan, run and fit.

``rti-rig plan`` refused lights in one plane, but ``rti-rig run`` captured such a session
silently and ``rti-rig fit`` then refused its normals with advice only a Python caller could
follow. One judgement, the fit's own, is shared so that all three agree on which lights give
no normals and say the same CLI way out.
"""

from __future__ import annotations

import numpy as np

#: What ``rti-rig fit`` does with lights that give no normals, as a CLI user can act on it.
FIT_WITHOUT_NORMALS = (
    "rti-rig fit would write no normal maps from them (--model auto, ps and lambert refuse "
    "them; --model hsh2 or --model ptm write the relighting files without normals)"
)


def undetermined_normals(lights: np.ndarray, what: str = "lights") -> str | None:
    """Why ``lights`` (N×3) cannot determine a surface normal, or None where they can.

    Judged as the fit judges Lambert's 3 terms (:func:`rti_rig.reconstruct.solve.solve_matrix`,
    the condition number over the hemisphere above its limit), so a plan or a capture refused
    here is one ``rti-rig fit`` would refuse normals for, and no other. ``what`` names them in
    the text ("planned lights", "lights of this session").
    """
    from rti_rig.core.rti_bases import design_matrix
    from rti_rig.reconstruct.solve import solve_matrix

    lights = np.asarray(lights, dtype=np.float64).reshape(-1, 3)
    if len(lights) < 3:  # too few is refused elsewhere, by count
        return None
    _, report = solve_matrix(design_matrix("lambert", lights), "lambert", warn=False)
    if not report.regularised:
        return None
    return (
        f"the {len(lights)} {what} cannot determine a surface normal: they lie (nearly) in one "
        f"plane through the object, or are bunched at the zenith (condition number "
        f"{report.condition_number:.3g} over the hemisphere, limit {report.cond_limit:g})"
    )
