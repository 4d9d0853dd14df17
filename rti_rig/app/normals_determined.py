"""Whether a set of lights can determine a surface normal, judged once for plan, run and fit.

``rti-rig plan`` refused lights in one plane, but ``rti-rig run`` captured such a session
silently and ``rti-rig fit`` then refused its normals with advice only a Python caller could
follow. One judgement, the fit's own, and one refusal are shared so that all three agree on
which lights give no normals and say the same CLI way out.
"""

from __future__ import annotations

import numpy as np

from rti_rig.core.errors import RtiRigError

# NORMAL_NOISE, NORMAL_ERROR_LIMIT_DEG (why 15°: there) live with the other light minimums, so
# that the command line's help states them without loading numpy
from rti_rig.core.fit_minimums import NORMAL_ERROR_LIMIT_DEG, NORMAL_MIN_LIGHTS, NORMAL_NOISE

#: What ``rti-rig fit`` refuses of lights that give no normals, whatever their count (the start
#: of :func:`fit_without_normals_words`; ``fit_outlook.fit_without_normals`` goes on from it).
NO_NORMAL_MAPS = (
    "rti-rig fit would write no normal maps from them (--model ps, lambert and robust-ps refuse "
    "them"
)

#: The named models that write the relighting files of lights giving no normals, as they are
#: offered to a user (``--model auto`` besides them).
_RELIGHTING_BY_NAME = ("hsh2", "ptm")


def relighting_models(n: int) -> str:
    """The ``--model`` options that write fit.ptm and fit.rti of ``n`` lights that give no
    normals, those ``n`` is too few for named with what they need (``core.fit_minimums``).

    Why: 6-8 lights at one azimuth were told "hsh2 and ptm write the relighting files", and
    ``--model hsh2`` then refused them: it needs 9.
    """
    from rti_rig.core.fit_minimums import N_COEFFICIENTS

    fits = [f"--model {m}" for m in _RELIGHTING_BY_NAME if n >= N_COEFFICIENTS[m]]
    short = [m for m in _RELIGHTING_BY_NAME if n < N_COEFFICIENTS[m]]
    named = ", ".join(["--model auto", *fits[:-1]]) + f" or {fits[-1]}" if fits else ""
    named = named or "--model auto"
    needs = "; ".join(f"--model {m} needs {N_COEFFICIENTS[m]} lights" for m in short)
    return named + (f" ({needs}, these are {n})" if needs else "")


def fit_without_normals_words(n: int) -> str:
    """What ``rti-rig fit`` does with ``n`` lights that give no normals, as a CLI user can act
    on it: no normal maps, and the models that write the relighting files of ``n`` lights."""
    return NO_NORMAL_MAPS + (
        f"; {relighting_models(n)} write the relighting files fit.ptm and fit.rti only, "
        "ridge-regularised: along the direction the lights do not span, their relighting is a "
        "guess)"
    )


#: What the note of lights captured with ``--allow-no-normals`` says (kept in the manifest's
#: ``input_notes``): a manifest from before the flag was recorded shows it was given by this
#: note alone (:func:`~rti_rig.app.usecases.replay_advice.new_session_command` reads it).
CAPTURED_WITHOUT_NORMALS = "captured as asked (--allow-no-normals)"


def _layout(lights: np.ndarray) -> str:
    """How ``lights`` (N×3, judged ill-conditioned) fail to span the three directions.

    Read off the singular vectors of the Lambert matrix (the lights themselves: the
    hemisphere scaling of :func:`~rti_rig.reconstruct.solve.solve_matrix` is the same for its
    3 columns, so these are the vectors it judges): lights closer to one line than to one plane
    (``s2² <= s1·s3``) are bunched about the strongest direction; else they lie in the plane
    whose normal is the weakest. Why: every refusal had said "one plane through the object, or
    bunched at the zenith", leaving the user to guess which of the two to mend. Why ``<=``:
    lights all at one direction (four straight overhead) have ``s2 = s3 = 0`` exactly, and with
    ``<`` were said to "lie in one upright plane … at one azimuth (90° or 270°)", a plane
    picked at random among those through the one direction; singular values at rounding level
    (below ``1e-9 s1``: one direction read from an ``.lp``'s 6 decimals) count as 0 for it.
    """
    _, s, vt = np.linalg.svd(lights, full_matrices=False)
    s = np.where(s < s[0] * 1e-9, 0.0, s)
    if s[1] ** 2 <= s[0] * s[2]:
        strong = vt[0] * np.sign(vt[0][2] or 1.0)
        el = float(np.degrees(np.arcsin(np.clip(strong[2], -1.0, 1.0))))
        if el >= 80.0:
            return "they are bunched at the zenith"
        az = float(np.degrees(np.arctan2(strong[1], strong[0]))) % 360.0
        return f"they are bunched about one direction (azimuth {az:.0f}°, elevation {el:.0f}°)"
    normal = vt[2]
    if abs(normal[2]) > np.cos(np.radians(10.0)):
        return "they lie (nearly) in one plane through the object: the horizon"
    if abs(normal[2]) < np.sin(np.radians(10.0)):
        az = float(np.degrees(np.arctan2(normal[1], normal[0])) + 90.0) % 180.0
        return (
            "they lie (nearly) in one upright plane through the object: lights at one "
            f"azimuth ({az:.0f}° or {az + 180.0:.0f}°)"
        )
    return "they lie (nearly) in one tilted plane through the object"


#: At most this many lights are listed by direction in a refusal (more are counted only).
_LISTED = 6


def predicted_normal_error_deg(lights: np.ndarray, noise: float = NORMAL_NOISE) -> float:
    """Standard deviation of a Lambertian normal's angle, in degrees, at image noise ``noise``
    (a fraction of the albedo), for the worst-oriented surface lit by all of ``lights`` (N×3).

    The least-squares fit ``g = (LᵀL)⁻¹Lᵀ I`` of ``g = albedo·n`` has covariance
    ``noise²·(LᵀL)⁻¹``; only its part across ``n`` turns the normal, so the angle's variance is
    ``noise²·(trace C − nᵀCn)``, largest where ``n`` is ``C``'s least-variance axis:
    ``noise²·(1/s₂² + 1/s₃²)`` with ``s`` the singular values of ``L`` (first order, without
    shadows, which only make it worse). Why this and not the condition number: the condition
    number is a ratio, blind to how small the weakest direction is against the noise; 3 lights
    at condition 95 passed while their normals were about 40° off at 1 % noise.
    """
    lights = np.asarray(lights, dtype=np.float64).reshape(-1, 3)
    norms = np.linalg.norm(lights, axis=1, keepdims=True)
    unit = lights / np.where(norms > 0.0, norms, 1.0)
    s = np.linalg.svd(unit, compute_uv=False)
    if len(s) < 3 or s[2] <= s[0] * 1e-12:
        return float("inf")
    return float(np.degrees(noise * np.sqrt(1.0 / s[1] ** 2 + 1.0 / s[2] ** 2)))


def _listed(lights: np.ndarray) -> str:
    """The lights' directions as azimuth/elevation, where few enough to read."""
    if len(lights) > _LISTED:
        return ""
    unit = lights / np.linalg.norm(lights, axis=1, keepdims=True).clip(1e-12)
    az = np.degrees(np.arctan2(unit[:, 1], unit[:, 0])) % 360.0
    el = np.degrees(np.arcsin(np.clip(unit[:, 2], -1.0, 1.0)))
    return " at azimuth/elevation " + ", ".join(
        f"{a:.0f}°/{e:.0f}°" for a, e in zip(az, el, strict=True)
    )


def undetermined_normals(lights: np.ndarray, what: str = "lights") -> str | None:
    """Why ``lights`` (N×3) cannot determine a surface normal, or None where they can.

    Two tests, both needed: the fit's own conditioning of Lambert's 3 terms
    (:func:`rti_rig.reconstruct.solve.solve_matrix`, the condition number over the hemisphere
    above its limit, where it would regularise or refuse), and the predicted normal error at
    :data:`NORMAL_NOISE` above :data:`NORMAL_ERROR_LIMIT_DEG`
    (:func:`predicted_normal_error_deg`), which judges what the normals are worth. So a plan or
    a capture refused here is one ``rti-rig fit`` would refuse normals for, and no other.
    ``what`` names them in the text ("planned lights", "lights of this session").
    """
    from rti_rig.core.rti_bases import design_matrix
    from rti_rig.reconstruct.solve import condition_words, solve_matrix

    lights = np.asarray(lights, dtype=np.float64).reshape(-1, 3)
    if len(lights) < NORMAL_MIN_LIGHTS:  # too few is refused elsewhere, by count
        return None
    _, report = solve_matrix(design_matrix("lambert", lights), "lambert", warn=False)
    error = predicted_normal_error_deg(lights)
    conditioned = condition_words(
        report.condition_number, report.cond_limit, "the three components of a normal"
    )
    if not report.regularised and error <= NORMAL_ERROR_LIMIT_DEG:
        return None
    shown = f"{error:.3g}°" if np.isfinite(error) else "unbounded"
    return (
        f"the {len(lights)} {what}{_listed(lights)} cannot determine a surface normal: "
        f"{_layout(lights)} (predicted normal error {shown} at {NORMAL_NOISE:.0%} image "
        f"noise, limit {NORMAL_ERROR_LIMIT_DEG:g}°; "
        f"{conditioned})"
    )


def band_advice(min_elevation_deg: float, max_elevation_deg: float) -> str:
    """The way out of lights a rig's elevation band leaves undetermined: another rig, and
    widening the band only where one was given (:func:`~rti_rig.planner.uniform.band_text`).

    Why: a rig whose rings sit at 89.2° and 89.6° had been told to widen the 0..90° band it
    already had.
    """
    from rti_rig.planner.uniform import band_text

    advice = "use a rig with lights at several elevations and azimuths"
    band = band_text(min_elevation_deg, max_elevation_deg)
    if band:
        advice += f", or widen --min-elevation-deg / --max-elevation-deg (lights{band} were asked)"
    return advice


def refuse_undetermined(lights: np.ndarray, what: str, advice: str, nothing_done: str) -> None:
    """Refuse, before anything is written, lit or moved, lights that cannot determine a normal.

    ``what`` names the lights, ``advice`` is the way out ("use a rig ..."), ``nothing_done``
    what was left undone ("nothing was written"). One refusal for ``rti-rig plan`` and ``rti-rig
    run``: each had its own copy of it, and each worked out "was a band given" itself.
    """
    from rti_rig.app.usecases.fit_outlook import fit_without_normals

    reason = undetermined_normals(lights, what)
    if reason is not None:
        # what the fit makes of this many: below a PTM's 6 --model auto writes fit.rti alone or
        # nothing, where "--model auto ... write the relighting files" had been offered
        raise RtiRigError(
            f"{reason}; {fit_without_normals(len(lights))}. "
            f"{advice[0].upper()}{advice[1:]}; {nothing_done}"
        )
