"""Rocky's breakage for large deformations (option overlap_factor): "the value of the ratio of the
overlap to the minimum fragment size will be monitored for every contact ... Whenever that ratio
exceeds the value of the Breakage Overlap Factor ... If the related particle or fragment is large
enough so that its breakage is possible, it will be broken at once ... if breakage is not
possible ..., it will be removed from the simulation" (removed: "if its volume is smaller than 3
times the volume of the smallest fragment allowed"). The minimum fragment size is dmin; a body
removed goes to the fines ledger with its mass and momentum. What it costs: one numpy comparison
over the contacts read, only when the option is set."""
from __future__ import annotations

import numpy as np

from yadebreak.adapter.yade_api import O
from yadebreak.engine.contacts.table import OVERLAP
from yadebreak.engine.state import BROKEN

#: a body smaller than this many times dmin^3 is removed, not broken (Rocky's)
REMOVE_BELOW = 3.0


class LargeOverlaps:
    """Which tracked bodies have a contact whose overlap passed factor x dmin at a read."""

    def __init__(self, factor):
        self.factor = factor

    def find(self, table, tracked, dmin, already=()):
        """The tracked bodies (ids, sorted) past the limit at this read, less `already`."""
        if not len(table):
            return []
        rows = np.flatnonzero(table.data[OVERLAP] > self.factor * dmin)
        if not len(rows):
            return []
        found = set(table.a[rows].tolist()) | set(table.b[rows].tolist())
        return sorted((found & tracked) - set(already))

    @staticmethod
    def removed(volume, dmin):
        """The body is too small to break: it leaves the scene."""
        return volume < REMOVE_BELOW * dmin ** 3

    def due(self, ctl, loading, broken):
        """The breakable bodies of controller `ctl` with a contact past the limit at this read,
        less those `broken` already: each breaks now at its present energy (returned as
        judge() returns breakages), or leaves for the ledger if too small to break."""
        dmin, table = ctl.dmin(), ctl.state.table
        due = []
        for bid in self.find(ctl.reader.table, ctl.state.tracked, dmin, [b for b, _, _ in broken]):
            if table.kind_of(bid) != "breakable":
                continue
            volume = float(table.columns["mass"][bid]) / O.bodies[bid].material.density
            removed = self.removed(volume, dmin)
            ctl.record_event("large_overlap", bid, action="removed" if removed else "broken")
            if removed:
                to_ledger(ctl, bid)
            else:
                due.append((bid, loading.energy.get(bid, 0.0), loading.strongest.get(bid)))
        return due


def to_ledger(ctl, bid):
    """Body `bid` of controller `ctl` leaves the scene for the fines ledger, with its mass and
    momentum."""
    state, c = ctl.state, ctl.state.table.columns
    mass = float(c["mass"][bid])
    state.ledger.add(mass, 2.0 * float(c["radius"][bid]), 0.0, state.table.label_of(bid),
                     mass * np.array(O.bodies[bid].state.vel))
    state.tracked.discard(bid)
    state.open_events.discard(bid)
    c["kind"][bid] = BROKEN
    O.bodies.erase(bid)
    ctl.zeroing.drop_body(bid)
    ctl.reader.erased(bid)
