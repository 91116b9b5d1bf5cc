"""ContactReader: the one interface to the contacts of tracked bodies. Each read turns YADE's
real interactions into the loading of each body (Eqs. 14-16): its counted energy Ek' (J), its
most energetic contact, and whether any of its contacts still worked.

Two read paths give the same numbers (tests/test_contact_paths.py), because each is the faster
one somewhere: contact by contact on Python scalars over YADE's list of real interactions
(each.py) for a few contacts, numpy over the rows kept (arrays.py) for many. Measured per step
of a whole run (CPU time, a read every step, breakage out of reach, medians of 6 runs): 4
particles hitting a plate 60 us per step contact by contact, 196 us with numpy; the default bed
(44 contacts) 208 against 303 us; a bed of 5 layers (203 contacts) 2095 against 1366 us. Per read
alone: 4 contacts 9 against 64 us, 44 contacts 65 against 107 us, 203 contacts 308 against 281
us. Both call the physics of a contact (law.py) on floats or on arrays. Which read a scene
takes, and what a row holds, is its contact law's (laws.py): Hertz-Mindlin (hertz.py) chooses
between the two paths; polyhedra on YADE's volumetric law take a read of their own
(volumetric.py): the work of the force over the approach of the bodies' material points.
Duck-typed on YADE's interaction container, geometry and physics objects; no yade import.
"""
from __future__ import annotations

import numpy as np

from yadebreak.engine.contacts.arrays import ArrayRead
from yadebreak.engine.contacts.hertz import HertzMindlin
from yadebreak.engine.contacts.law import HertzMindlinWork, total_work
from yadebreak.engine.contacts.table import (OFFSET_A, OFFSET_B, OFFSETS, OVERLAP, SHARE_A,
                                             SHARE_B, SHARES, SHEAR_WORK, WORK, ContactTable)

#: while the rows are at most this many a read goes contact by contact on Python scalars, beyond
#: with numpy: measured, the scalar path costs about 1.7 us per contact, the numpy one about
#: 0.7 us per contact plus 100 us per read (per step, see the module's docstring)
SMALL = 150


class ContactReader:
    """The contacts of tracked bodies (`table`, one row per contact), read when the schedule
    says, and what the engine tells them between reads (erased bodies, inherited pairs)."""

    def __init__(self, stiffness_by_material_id, cs, emin, law=None):
        self.stiffness = stiffness_by_material_id     # YADE material id -> the stiffness of
        #                                               Eq. 4's shares (Pa; the law's own kn
        #                                               where law.young_is_stiffness)
        self.contact_law = law if law is not None else HertzMindlin()   # laws.py
        self.last_time = None                         # O.time at the last read
        self.cs = cs
        self.emin = emin
        self.law = HertzMindlinWork()
        self.table = ContactTable()
        self.inherited = set()                        # (smaller id, larger id): see inherit()
        self.erased_bodies = set()                    # bodies gone since the last read
        self.small = SMALL                            # see SMALL (tests set it to choose a path)
        self.arrays = ArrayRead(self)                 # the numpy read (Hertz-Mindlin's)

    def __len__(self):
        return len(self.table)

    def read(self, interactions, bodies, tracked, zeroed, now, interval, asleep=(), counts=None,
             zeroing_changes=None):
        """One read of the real interactions; contacts that ceased drop out. `tracked`: the
        bodies read (a state.TrackedBodies, which also gives them as a mask). `zeroed` holds the
        pairs whose kno varies, `asleep` those of them that carry no force and are not updated
        now (they do no work), all keyed (smaller id, larger id); `interval` is the steps since
        the last read; `counts()` gives the real interactions of each body id as an array
        (adapter.yade_api.interaction_counts, one pass in C++): with it, a read of many contacts
        looks for new ones only around the bodies whose count changed; `zeroing_changes`, the
        pairs that entered or left `zeroed` or `asleep` since the last read (None: unknown),
        spares it looking every row up in them again."""
        loading = self.contact_law.read(self, interactions, bodies, tracked, zeroed, now,
                                        interval, asleep, counts, zeroing_changes)
        self.inherited.clear()                 # read now or gone
        self.erased_bodies.clear()
        self.last_time = now
        return loading

    # -- one body's contacts -------------------------------------------------------------------
    def stored_share(self, body):
        """Elastic energy (J) a body holds now in its counted contacts: its share (Eq. 4) of
        what each holds, as its law says (Hertz: with kno as the law uses it, scaled for zeroed
        pairs)."""
        table = self.table
        if table.is_block:
            return self.stored_shares([body])[0]
        total = 0.0
        rows, physs, cs, emin = table.row_lists(), table.physs, self.cs, self.emin
        held = self.contact_law.held
        for k, side in table.rows_of(body):
            row = rows[k]
            if total_work(row[WORK], row[SHEAR_WORK], cs) - row[OFFSET_B if side else OFFSET_A] \
                    >= emin:
                energy = held(table, k, physs)
                if energy > 0.0:
                    total += row[SHARE_B if side else SHARE_A] * energy
        return total

    def stored_shares(self, bodies):
        """stored_share of each of `bodies` (a list). On the numpy block, at once: a fragment
        cloud's open events ask every read whether their bodies unloaded. Each body's sum is
        taken in the order of its rows, as the loop over a body's rows takes it."""
        table = self.table
        if not table.is_block:
            return [self.stored_share(b) for b in bodies]
        d = table.data
        overlap, work = d[OVERLAP], total_work(d[WORK], d[SHEAR_WORK], self.cs)
        pressed = overlap > 0.0
        if table.resting is not None:
            pressed &= ~table.resting   # asleep zeroed pairs: slack, kno 0, nothing held
        asked = table.places_of(bodies)
        counted = (asked >= 0) & pressed & (work - d[OFFSETS] >= self.emin)
        # the counted sides of the asked bodies (a few), each contact's a before its b (as
        # arrays.py takes them): in the order of each body's rows
        row, side = counted.T.nonzero()
        places = asked[side, row].tolist()
        shares = d[SHARES][side, row].tolist()
        totals = [0.0] * len(bodies)
        stored = self.law.stored
        for place, share, kno, overlap_now in zip(places, shares, table.kno_of(row).tolist(),
                                                  overlap[row].tolist()):
            totals[place] += share * stored(kno, overlap_now)
        return totals

    @property
    def pair_checks(self):
        """YADE's silenced warnings the law counts (volumetric.PairChecks), None if it counts
        none."""
        return self.contact_law.pair_checks

    def restart(self, body):
        """Count a body's energy from now on: its offsets become its contacts' present work."""
        table = self.table
        for row, side in table.rows_of(body):
            table.set_value(row, OFFSET_B if side else OFFSET_A, table.total(row, self.cs))

    def restart_all(self, bodies):
        """restart() of each of `bodies` (a list). On the numpy block, at once: the events a read
        closes in a collisional cloud restart hundreds of bodies' rows."""
        table = self.table
        if not table.is_block or len(bodies) < 2:
            for body in bodies:
                self.restart(body)
            return
        d = table.data
        np.copyto(d[OFFSETS], total_work(d[WORK], d[SHEAR_WORK], self.cs),
                  where=table.places_of(bodies) >= 0)

    def erased(self, body):
        """`body` left the scene (a parent replaced): its rows go at the next read (YADE erased
        its interactions; the rows' objects would keep their last numbers)."""
        self.erased_bodies.add(body)

    def inherit(self, pairs, zeroed=False):
        """Pairs (ids) that fresh fragments inherit overlapping: their rows, made at the next
        read, count work from that state on (arrays.ArrayRead._start_here); `zeroed`: the
        replacement's zero_overlaps, which the contact law applies where the zeroing does not
        (laws.py: inherited)."""
        pairs = list(pairs)
        self.inherited.update((a, b) if a < b else (b, a) for a, b in pairs)
        self.contact_law.inherited(pairs, zeroed)

    def bodies_in_contact(self):
        return set(np.concatenate((self.table.a, self.table.b)).tolist())

    # -- saved with the scene ------------------------------------------------------------------
    def to_dict(self):
        return {**self.table.to_dict(), **self.contact_law.to_dict(),
                "inherited": sorted(self.inherited),
                "last_time": self.last_time}

    def restore(self, data):
        self.table.restore(data)
        self.inherited = {tuple(pair) for pair in data.get("inherited", ())}
        self.contact_law.restore(data)
        self.last_time = data.get("last_time")
