"""When a part acts (in the spirit of HOOMD-blue's triggers): a trigger says, after each act,
the step at which its part is due next; the part's runner in YADE's loop then waits that long
with YADE's own iterPeriod (protocol.py), so that the steps between cost nothing. A part takes
a trigger, or an integer k for a Periodic one (every k steps). The engine's read schedules
(engine/reads.py) are triggers; so is the overlap zeroing (engine/zeroing.py)."""
from __future__ import annotations


class Trigger:
    """When a part acts next."""

    def next_step(self, now):
        """The step (>= now + 1) at which the part is due next, asked right after it acted at
        step `now` (and when it is woken)."""
        raise NotImplementedError


class Periodic(Trigger):
    """Every `steps` steps."""

    def __init__(self, steps):
        if isinstance(steps, bool) or not isinstance(steps, int) or steps < 1:
            raise ValueError(f"steps = {steps!r}: accepted an integer >= 1")
        self.steps = steps

    def next_step(self, now):
        return now + self.steps

    def __repr__(self):
        return f"Periodic({self.steps})"


def as_trigger(value):
    """A Trigger from a part's `trigger` argument: a Trigger, or an integer (Periodic)."""
    if isinstance(value, Trigger):
        return value
    if isinstance(value, int) and not isinstance(value, bool):
        return Periodic(value)
    raise TypeError(f"trigger = {value!r}: accepted a Trigger or an integer number of steps "
                    ">= 1")
