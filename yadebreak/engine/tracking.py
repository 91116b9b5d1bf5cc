"""Which bodies the engine reads: the tracked set (breakable bodies, and unbreakable fragments
until their first stressing past their fracture energy), with the two quantities the read
schedule asks of it: the smallest breakable body ("auto" reads) and the reach of a fresh contact
("fast" reads)."""
from __future__ import annotations

import numpy as np

from yadebreak.model import placement
from yadebreak.adapter.yade_api import O
from yadebreak.engine.state import BREAKABLE, UNBREAKABLE
from yadebreak.engine.reads import Reach, SmallestBreakable


class Tracking:
    """The tracked bodies of an engine's state; `fast_tolerance` is None unless reads are
    "fast" (then the reach is kept)."""

    def __init__(self, state, fast_tolerance=None):
        self.state = state
        self.smallest = SmallestBreakable()
        self.reach = Reach(fast_tolerance) if fast_tolerance is not None else None
        table = state.table
        if state.tracked:                     # a restored state: its tracked bodies
            self.smallest.rebuild((float(table.columns["radius"][i]), i) for i in state.tracked
                                  if table.columns["kind"][i] == BREAKABLE)
        if self.reach is not None:
            self._rebuild_reach()

    def adopt(self, ids):
        """Track new bodies (in the body table): breakable and unbreakable ones are read;
        breakable ones may set the read schedule."""
        c = self.state.table.columns
        kind, radius = c["kind"], c["radius"]
        for i in ids:
            k = kind[i]
            if k == BREAKABLE or k == UNBREAKABLE:
                self.state.tracked.add(i)
                if self.reach is not None:
                    self.reach.add(i, float(radius[i]), float(c["fracture_energy"][i]),
                                   O.bodies[i].material)
            if k == BREAKABLE:
                self.smallest.push(float(radius[i]), i)

    def weakened(self, ids):
        """A damage lowered the fracture energy of the bodies `ids` (a list): "fast" reads
        follow them (a collisional cloud weakens dozens a read: their times in numpy)."""
        if self.reach is None:
            return
        tracked = self.state.tracked
        ids = np.array([i for i in ids if i in tracked], np.int64)
        if len(ids):
            self.reach.set_onsets(ids.tolist(), self._times(ids, loading=False)[0].tolist())

    def smallest_breakable(self):
        """(radius, id) of the smallest breakable body still tracked, None if none."""
        return self.smallest.get(self._still_breakable)

    def reach_now(self, rebuild):
        """Reach.get over the tracked bodies, built anew first if `rebuild`."""
        if rebuild:
            self._rebuild_reach()
        return self.reach.get(self.state.tracked)

    def _still_breakable(self, i):
        return i in self.state.tracked and self.state.table.columns["kind"][i] == BREAKABLE

    def _rebuild_reach(self):
        """The reach of every tracked body from the body table."""
        ids = np.array(sorted(self.state.tracked), np.int64)
        onset, loading = self._times(ids)
        self.reach.rebuild(ids.tolist(), onset.tolist(), loading.tolist())

    def _times(self, ids, loading=True):
        """The onset times at 1 m/s of the bodies `ids` (an array) at their present fracture
        energies (Reach), and with `loading` their Hertz loading times (else None): numpy on
        each material's bodies."""
        c = self.state.table.columns
        onset = np.empty(len(ids))
        times = np.empty(len(ids)) if loading else None
        materials = c["material"][ids]
        for m in np.unique(materials).tolist():
            rows = (materials == m).nonzero()[0]
            mat = O.bodies[int(ids[rows[0]])].material
            radius = c["radius"][ids[rows]]
            onset[rows] = placement.hertz_onset_time(
                radius, mat.density, mat.young, mat.poisson, 1.0,
                self.reach.tolerance * c["fracture_energy"][ids[rows]])
            if loading:
                times[rows] = placement.hertz_loading_time(radius, mat.density, mat.young,
                                                           mat.poisson, 1.0)
        return onset, times
