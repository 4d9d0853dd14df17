"""The exposures two ranges share, and whether they share any: one judgement for the config
check and the metering.

Why one place: ``[camera]``'s exposure range (``min_exposure_s`` … ``max_exposure_s``) and the
camera's own (``[camera.device]``'s, or what the connected camera says it takes) are compared
when the rig config loads (:mod:`rti_rig.app.config`, before any port is opened) and again when
``run --auto-exposure`` chooses where its metering starts
(:func:`rti_rig.runtime.exposure_policy.metering_start`). Each had its own comparison, with its
own tolerance and its own way of choosing the end to blame, so the two could disagree on a
config at the edge. Each caller keeps its own words; which ends bound the shared range, and
whether it is empty, are decided here.

Each end is a :data:`Bound`: the exposure in seconds and the phrase naming the key that sets it
(``"[camera] min_exposure_s = 0.001 s"``), so the end that is to blame is said by its key.
"""

from __future__ import annotations

from dataclasses import dataclass

#: one end of an exposure range: seconds, and the phrase naming the key that sets it
Bound = tuple[float, str]

#: Relative tolerance of the comparisons: an exposure said in a config (``1e-3``) and the same
#: one computed (``0.1 * 0.01``) differ in their last bits, which is no gap between ranges.
REL_TOL = 1e-9


def longer_than(exposure_s: float, bound: Bound) -> bool:
    """Whether ``exposure_s`` lies above ``bound`` by more than rounding (:data:`REL_TOL`)."""
    return exposure_s > bound[0] * (1 + REL_TOL)


@dataclass(frozen=True)
class SharedRange:
    """The exposures every range given allows: the highest of their shortest ends
    (``floor``) and the lowest of their longest (``cap``), each the very :data:`Bound` object
    a caller gave (so a caller can tell which range sets it by identity); None where no range
    gives that end."""

    floor: Bound | None
    cap: Bound | None

    @property
    def empty(self) -> bool:
        """No exposure lies in every range: the floor is above the cap."""
        floor, cap = self.floor, self.cap
        return floor is not None and cap is not None and longer_than(floor[0], cap)


def shared_range(*ranges: tuple[Bound | None, Bound | None]) -> SharedRange:
    """The range ``ranges`` (each ``(shortest, longest)``, either end None when not known)
    share. On a tie the end of the range given first is kept."""
    floor: Bound | None = None
    cap: Bound | None = None
    for low, high in ranges:
        if low is not None and (floor is None or low[0] > floor[0]):
            floor = low
        if high is not None and (cap is None or high[0] < cap[0]):
            cap = high
    return SharedRange(floor, cap)
