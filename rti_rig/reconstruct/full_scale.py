"""The full scale of 16-bit images whose files do not say it: 10-, 12- or 14-bit camera data.

Why: a 16-bit TIFF or PNG says nothing of the range its values span, and every reader of an
acquisition (the fit, its QA, the exports) took 65535 as white. Machine-vision and scientific
cameras save 12-bit (or 10-, 14-bit) data in 16-bit files unscaled (white 4095) or shifted up
(white 65520). Read at 65535, an imported acquisition of such files had its clipped highlights
fitted as light (a 12-bit session with two thirds of some images clipped at 4095 was called
"good"), and one exposed to half of its 4095 was called "4.9 stops under-exposed", with the
advice to give it 29× the exposure. rti-rig's own sessions scale their camera's range to
65535 as they are shot (``drivers.cameras.image_io.to_linear_uint16``), so this reading is for
acquisitions from elsewhere (and for a replay of one, whose session keeps the codes as recorded
and states their white in its labels).

The reading, from a regular sample of every image's pixels:

* **clipped** — many pixels sit at exactly the brightest code, far more than at the code below
  it: a sensor (or its converter) clipped there, whatever the value (a 12-bit sensor less its
  black level clips below 4095). That code is full scale.
* **shifted** — every code is a multiple of 2^s (s ≥ 2): (16 − s)-bit data shifted up, whose
  full scale is 65536 − 2^s.
* **bits** — no code is above 2^k − 1, and some above 2^(k − 2), for k of 10 or 12: k-bit data
  stored unscaled. This reading cannot tell such data from a 16-bit acquisition under-exposed
  by 16 − k stops or more; the note says both, and ``rti-rig fit --white-level 65535`` takes the
  other reading. Not read: 14-bit data (a linear RAW converter's export of a dark object stays
  under a quarter of 65535, and the QA calls under-exposed only what is under 1/32 of it, which
  14-bit data so low is too), and a brightest code of 255 or less (a lens cap's noise: called
  black, as it is, not 10-bit data).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

#: The depths camera data stored unscaled in 16-bit files has (a sensor's ADC): the depths a
#: clip level is named by.
CAMERA_BITS = (10, 12, 14)
#: The depths read from the brightest code alone (no clip): see the module's docstring.
READ_BITS = (10, 12)
#: Pixels of one image sampled at the brightest code before it is read as a clip level.
PILE_MIN_PIXELS = 8
#: ...and how many times the count at the next code found below it they must be: a smooth
#: histogram's brightest code holds fewer pixels than the one below it, a clip holds every
#: brighter one. The next code *found*, not the next possible one: 8-bit data multiplied by
#: 257 has no value between its codes.
PILE_RATIO = 4.0
#: A shift is read only where the sample holds this many distinct codes (a flat sample of a
#: few codes could be multiples of 4 by chance).
SHIFT_MIN_CODES = 64
#: The most bits a shift may drop (8-bit data shifted up by 8 is still a reading).
MAX_SHIFT = 8


@dataclass(frozen=True)
class FullScale:
    """The code read as white (full scale) of an acquisition's 16-bit images, and why.

    ``how``: ``"clipped"``, ``"shifted"``, ``"bits"`` (read from the data), ``"given"``
    (``--white-level``), ``"labelled"`` (an rti-rig session's own TIFF labels say it: a
    replay of camera data kept as recorded) or ``"header"`` (TIFFs of 10, 12 or 14 bits a
    sample, as a replay reads them); ``bits``: the data's depth where read;
    ``brightest``: the brightest sampled code; ``clipped_image``/``clipped_share``: the image
    with most sampled pixels at ``level`` and their share (a clip reading)."""

    level: int
    how: str
    bits: int | None
    brightest: int
    clipped_image: str | None = None
    clipped_share: float = 0.0

    def as_dict(self) -> dict[str, object]:
        """fit.json's record of it."""
        return {
            "level": self.level,
            "how": self.how,
            "bits": self.bits,
            "brightest_sampled": self.brightest,
            "clipped_image": self.clipped_image,
            "clipped_share": round(self.clipped_share, 6),
        }

    def words(self, images: int, label: str, fit: str = "fit") -> str:
        """What the fit says of it (``label``: the acquisition's .lp as shown; ``fit``: what
        the user runs with ``--white-level``, "fit the session" where a replay says it)."""
        of = f"the {images} 16-bit images of {label}"
        other = f"if the camera's white level is another, {fit} with --white-level N"
        if self.how == "labelled":
            depth = f" ({self.bits}-bit camera data kept as recorded)" if self.bits else ""
            return (
                f"{of} are labelled with white level {self.level} by the session that wrote "
                f"them{depth}: fitted and judged with {self.level} as full scale (values there "
                f"read as clipped); {other}"
            )
        if self.how == "header":
            return (
                f"the {images} images of {label} store {self.bits} bits a sample, as their "
                f"files' headers say: fitted and judged with {self.level} as full scale "
                "(values there read as clipped); "
                f"{other}"
            )
        if self.how == "given":
            return (
                f"{of} were fitted and judged with {self.level} as full scale (--white-level): "
                "a value at or above it is read as clipped"
            )
        if self.how == "clipped":
            shifted = " shifted up" if self.bits and self.level != (1 << self.bits) - 1 else ""
            depth = f" ({self.bits}-bit data{shifted})" if self.bits else ""
            return (
                f"{of} are clipped at {self.level}, not at 65535{depth}: "
                f"{self.clipped_share:.1%} of {self.clipped_image}'s sampled pixels sit at "
                f"exactly {self.level}, the brightest value sampled in any image, far more "
                "than at the value found below it, as a sensor's clip leaves them; fitted "
                "and judged with "
                f"{self.level} as full scale (values there read as clipped); {other}"
            )
        if self.how == "shifted":
            return (
                f"{of} hold {self.bits}-bit data shifted up (every value a multiple of "
                f"{(65536 - self.level)}): fitted and judged with {self.level} as full scale; "
                f"{other}"
            )
        stops = np.log2(65535 / self.level)
        return (
            f"{of} hold no value above {self.level} (the brightest sampled: {self.brightest}): "
            f"read as {self.bits}-bit camera data stored unscaled, fitted and judged with "
            f"{self.level} as full scale. If they are 16-bit images (a RAW converter's), they "
            f"are {stops:.0f} stops or more under-exposed: {fit} with --white-level 65535 to "
            "judge them so"
        )


def full_scale_of(values: NDArray[np.uint16], names: Sequence[str]) -> FullScale | None:
    """The full scale read from ``values`` (N images × P sampled pixels × C channels, the
    images' own codes), or None where it is 65535 or nothing says otherwise."""
    v = np.asarray(values)
    if v.dtype != np.uint16 or v.size == 0:
        return None
    brightest = int(v.max())
    if brightest in (0, 65535):
        return None
    ored = int(np.bitwise_or.reduce(v.reshape(-1)))
    shift = min((ored & -ored).bit_length() - 1, MAX_SHIFT)
    n = v.shape[0]
    # a pixel is at the top when any channel is (a red object under a warm light)
    per_image = v.reshape(n, -1, v.shape[-1] if v.ndim == 3 else 1)
    at_top = (per_image == brightest).any(axis=-1).sum(axis=1)
    lower = v[v < brightest]
    below = int((lower == lower.max()).sum()) if lower.size else 0
    top_values = int((v == brightest).sum())
    worst = int(np.argmax(at_top))
    if at_top[worst] >= PILE_MIN_PIXELS and top_values >= PILE_RATIO * max(below, 1):
        return FullScale(
            brightest,
            "clipped",
            bits_of(brightest, shift),
            brightest,
            str(names[worst]),
            float(at_top[worst] / per_image.shape[1]),
        )
    for bits in READ_BITS:
        if (1 << (bits - 2)) <= brightest <= (1 << bits) - 1:
            return FullScale((1 << bits) - 1, "bits", bits, brightest)
    # shifted up into 16 bits (10-bit data shifted by 2 in a 12-bit container is read above)
    if shift >= 2 and brightest > (1 << 12) - 1 and np.unique(v).size >= SHIFT_MIN_CODES:
        return FullScale(65536 - (1 << shift), "shifted", 16 - shift, brightest)
    return None


def bits_of(level: int, shift: int = 0) -> int | None:
    """The depth a clip level shows where it is a depth's top code, unscaled or shifted up."""
    if shift >= 2 and level == 65536 - (1 << shift):
        return 16 - shift
    return next((b for b in CAMERA_BITS if level == (1 << b) - 1), None)
