"""A virtual clock that runs scripted actions as time passes: a file appearing in a watched
folder at t = 2 s, a rename at 3 s. Shared by the folder-watch camera's tests."""

from __future__ import annotations

from collections.abc import Callable

from rti_rig.core.clock import VirtualClock


class ScriptedClock(VirtualClock):
    """Virtual time; runs ``actions[t]`` once virtual time reaches ``t`` (a file appearing...)."""

    def __init__(self, actions: dict[float, Callable[[], object]]) -> None:
        super().__init__()
        self.actions = sorted(actions.items())

    def sleep(self, seconds: float) -> None:
        super().sleep(seconds)
        while self.actions and self.actions[0][0] <= self.now():
            self.actions.pop(0)[1]()
