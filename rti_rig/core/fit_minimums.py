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
