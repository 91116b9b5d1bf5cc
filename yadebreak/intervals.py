"""Ranges of accepted numbers, one home for the check and its wording: the scripts' options
(scriptargs) and attach()'s options (coupling.config) both check their values with it. Model
layer: no YADE."""
from __future__ import annotations

import math
from dataclasses import dataclass


@dataclass(frozen=True)
class Interval:
    """Finite numbers from lo to hi, each end open (excluded) or closed; infinite ends are open
    by nature. `v in Interval(0, 1, lo_open=True)` tests 0 < v <= 1; str() words it ("in (0, 1]",
    "> 0", "any number")."""
    lo: float = -math.inf
    hi: float = math.inf
    lo_open: bool = False
    hi_open: bool = False

    def __contains__(self, v):
        return (math.isfinite(v) and (v > self.lo if self.lo_open else v >= self.lo)
                and (v < self.hi if self.hi_open else v <= self.hi))

    def __str__(self):
        if self.lo == -math.inf and self.hi == math.inf:
            return "any number"
        if self.hi == math.inf:
            return f"{'>' if self.lo_open else '>='} {self.lo:g}"
        if self.lo == -math.inf:
            return f"{'<' if self.hi_open else '<='} {self.hi:g}"
        return (f"in {'(' if self.lo_open else '['}{self.lo:g}, {self.hi:g}"
                f"{')' if self.hi_open else ']'}")
