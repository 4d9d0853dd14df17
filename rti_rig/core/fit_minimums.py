"""How many lights each thing `rti-rig fit` makes needs: the one source of those numbers.

Why a module of its own, in the core and without numpy: the fit's gates, its advice before a
session (``app.usecases.fit_outlook``), the adaptive session's note, the planner's refusal and
the command line's help all name these numbers. Written out in each they drifted apart (a
literal 6 in three places, "3 lights for a normal" in six); derived here from the models'
coefficient counts they cannot. The command line reads it for its help without loading numpy.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

#: Coefficient count of each linear model name (``core.rti_bases.design_matrix`` builds them).
N_COEFFICIENTS = {"lambert": 3, "hsh1": 4, "ptm": 6, "hsh2": 9, "hsh3": 16}

#: Lights a surface normal needs: Lambert's albedo × normal is 3 unknowns per pixel. Fewer
#: determine no normal, whatever their placement.
NORMAL_MIN_LIGHTS = N_COEFFICIENTS["lambert"]

#: ``rti-rig plan``'s ``--lights`` when none is given, and the count a hint's command suggests
#: where the rig does not limit it (``core.rig_geometry.hint_light_count``): one number, which
#: had been a literal 12 in the plan command, its use case and four hints.
PLAN_DEFAULT_LIGHTS = 12

#: Image noise, as a fraction of the brightness of a surface facing the light (its albedo), at
#: which a light set's normals are judged: 1 %, an 8-bit JPEG's quantisation and shot noise.
NORMAL_NOISE = 0.01
#: Largest predicted normal error (standard deviation in degrees, at :data:`NORMAL_NOISE`, for
#: the worst-placed surface) of lights that can determine a normal. Why 15°: measured
#: (docs/reconstruction.md, "Which lights determine a normal"), every plan of 3 to 12 lights on
#: the shipped configs and on the recorded .lp files, with and without an elevation band, gives
#: 0.4-9.5°; the condition-number limit alone had passed 3-light sets at condition 80-100 whose
#: normals were 22-38° off (first order) at 1 % noise.
NORMAL_ERROR_LIMIT_DEG = 15.0


def fewest_held_out(models: Iterable[str]) -> int:
    """The fewest lights the model choice can fit one of ``models`` from *and* check it on a
    light left out: the simplest one's coefficients plus one (every fold holds out at least
    one). ``reconstruct.model_select.fewest_images`` is this rule."""
    return min(N_COEFFICIENTS[m] for m in models) + 1


@dataclass(frozen=True)
class FitMinimums:
    """The fewest lights of each thing `rti-rig fit` makes.

    ``normal``: a normal map (``--model ps``; also the QA verdict's and a plan's minimum);
    ``auto``: the default ``--model auto`` (its simplest model, checked on a light held out);
    ``ptm``: fit.ptm (a PTM's coefficients); ``rti``: fit.rti in the order the fit chooses (an
    order-1 HSH once its held-out error can be measured, ``app.usecases.fit_rti_order``).
    """

    normal: int
    auto: int
    ptm: int
    rti: int

    @property
    def rti_file(self) -> int:
        """Lights for both relighting files (fit.ptm and fit.rti)."""
        return max(self.ptm, self.rti)

    @staticmethod
    def hsh(order: int) -> int:
        """Lights an HSH of ``order`` is fitted from: its ``(order + 1)²`` coefficients."""
        return N_COEFFICIENTS[f"hsh{order}"]


#: The figures of this build: read them here, never restate them.
FIT_MINIMUMS = FitMinimums(
    normal=NORMAL_MIN_LIGHTS,
    auto=fewest_held_out(N_COEFFICIENTS),
    ptm=N_COEFFICIENTS["ptm"],
    rti=fewest_held_out(("hsh1",)),
)

#: The models whose fit is the normal map (photometric stereo): on lights that cannot determine
#: a normal there is nothing to write, and ``--model auto`` leaves them out of its choice.
PHOTOMETRIC_STEREO = ("ps", "lambert", "ps-robust")


def auto_models(normals_determined: bool) -> tuple[str, ...]:
    """The models ``rti-rig fit --model auto`` chooses among: every relighting model, less
    photometric stereo (Lambert) on lights that cannot determine a normal. The fit's choice
    (``app.usecases.fit.auto_candidates``) and the outlook before a session both read this."""
    return tuple(m for m in N_COEFFICIENTS if normals_determined or m not in PHOTOMETRIC_STEREO)


@dataclass(frozen=True)
class AutoFit:
    """What ``rti-rig fit`` with its default ``--model auto`` makes of ``n`` lights.

    Why one object: the run's note before a session and the fit's own refusal had each worked
    it out, and disagreed: on 4 raking lights (one azimuth) the note promised a normal map while
    the fit, with photometric stereo left out, needed 5 lights for its simplest model and made
    nothing. Every figure is derived from :func:`auto_models` and :data:`FIT_MINIMUMS`.
    """

    n: int
    normals_determined: bool

    @property
    def least(self) -> int:
        """The fewest lights auto fits from on such lights (its simplest model, checked on one
        left out)."""
        return fewest_held_out(auto_models(self.normals_determined))

    @property
    def simplest(self) -> str:
        """Auto's simplest candidate model on such lights."""
        return min(auto_models(self.normals_determined), key=N_COEFFICIENTS.__getitem__)

    @property
    def fits(self) -> bool:
        """Whether auto fits anything at all (else it refuses the session)."""
        return self.n >= self.least

    @property
    def normal_map(self) -> bool:
        """Whether normal maps are written."""
        return self.fits and self.normals_determined

    @property
    def ptm(self) -> bool:
        """Whether fit.ptm is written."""
        return self.fits and self.n >= FIT_MINIMUMS.ptm

    @property
    def rti(self) -> bool:
        """Whether fit.rti is written (an HSH order chosen on held-out lights)."""
        return self.fits and self.n >= FIT_MINIMUMS.rti
