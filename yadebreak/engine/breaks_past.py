"""The warnings that a body broke well past its fracture energy, so that its t10' is high: a read
that came late ("jump": closer reads would catch the crossing), or a contact's first count
("emin": none would). Each once per run (the controller's warn_once)."""
from __future__ import annotations

from yadebreak.adapter.yade_api import O


class BreaksPast:
    """What the judge tells of a body that broke past its fracture energy (judging.Judge's
    warn_jump and warn_emin), as one warning per cause with the figures and the remedy."""

    def __init__(self, state, criteria, schedule, reader, warn_once):
        self.state, self.criteria, self.schedule = state, criteria, schedule
        self.reader, self.warn_once = reader, warn_once

    def _breakage(self, bid, ek):
        table = self.state.table
        crit = self.criteria[table.label_of(bid)]
        return crit, crit.breakage(table, bid, ek)

    def jump(self, bid, rise, scale, ek):
        """A body broke (or an unbreakable fragment was stressed past its fracture energy) after
        its energy rose by `rise` (J/kg) between two reads, more than LATE_JUMP of its fracture
        energy `scale`: its t10' is that of the read, where reading at the crossing gives the
        criterion's t10' at its threshold (Eq. 8 at Ek'/(m E) = 1; Eq. 9.4 at e_cum = its
        threshold). The message says both."""
        crit, (ratio, t10, _) = self._breakage(bid, ek)
        low = crit.t10_at_threshold(self.state.table, bid, scale)
        self.warn_once("jump", (
            f"specific energy rose by {100 * rise / scale:.0f} % of the fracture energy between "
            f"two reads at body {bid} (read every {self.schedule.period} step(s) of {O.dt:.3g} s): "
            f"its t10' is {t10:.2f} % (at {ratio:.2f} times its fracture energy) where a read at "
            f"the crossing gives {low:.2f} %"),
            remedies=self.schedule.remedies(), purpose="for an accurate t10'")

    def emin(self, bid, rise, scale, ek, start):
        """A body broke on its strongest contact's first counted energy: its count rose by `rise`
        (J/kg), `start` of it the least that contact's first count gives (its share of emin), so
        no closer read could have caught the crossing of its fracture energy `scale`."""
        _, (ratio, t10, _) = self._breakage(bid, ek)
        mass = self.state.table.columns["mass"][bid]
        self.warn_once("emin", (
            f"body {bid} ({mass:.3g} kg) broke at {ratio:.2f} times its fracture energy "
            f"({scale:.3g} J/kg) on a contact's first counted energy: a contact counts from "
            f"emin = {self.reader.emin:g} J on (the paper's Emin), {start:.3g} J/kg of this "
            f"body's share, so its t10' is {t10:.2f} % however often it is read"),
            remedies=[("emin", "lower {}")], purpose="to count smaller contacts of fine fragments")
