"""A read with numpy over the rows kept (process scale): their overlaps and forces fetched from
YADE (about 0.5 us per contact), their work and sums in numpy; new contacts are looked for only
around the tracked bodies whose count of real interactions (one C++ call for all the bodies)
differs from their rows: no pass over every interaction in Python. It gives the numbers the read
contact by contact (each.py) gives (tests/test_contact_paths.py). Rows are found with
mask.nonzero()[0]: np.flatnonzero's dispatch layers cost more than the search over a cloud's
table, a dozen times a read."""
from __future__ import annotations

import numpy as np

from yadebreak.engine.contacts.law import HertzMindlinWork, own_share, total_work
from yadebreak.engine.contacts.loading import Loading, StrongestContacts
from yadebreak.engine.contacts.table import (OFFSETS, OVERLAP, OVERLAP_BEFORE, FORCE, SHARES,
                                             SHEAR_DISP, SHEAR_FORCE, TIME_BEFORE, TIME_READ,
                                             fresh_row, take)
from yadebreak.engine.contacts.zeroed_rows import ZeroedRows

_law = HertzMindlinWork


class ArrayRead:
    """The numpy read of one reader (its table, cs, emin, inherited and erased bodies)."""

    def __init__(self, reader):
        self.reader = reader
        self.table = reader.table
        self.zeroed_rows = ZeroedRows()

    def __call__(self, interactions, bodies, tracked, zeroed, now, interval, asleep, counts,
                 zeroing_changes=None):
        """One read; see ContactReader.read."""
        reader, table = self.reader, self.table
        mask = tracked.mask(len(bodies))                # tracked, by body id
        flags = None                                    # which rows are zeroed, asleep
        if not zeroed:
            self.zeroed_rows.forget()          # the changes told meanwhile are not followed
        else:
            flags = self.zeroed_rows
            if table.incomplete:
                flags.forget()
            else:
                flags.update(table.pairs(), zeroed, asleep, zeroing_changes)
        incomplete = table.incomplete          # rows restored from a save, found now
        fresh, restored, delta = self._screen(interactions, bodies, mask, counts, now, flags,
                                              zeroed, asleep)
        pairs = table.pairs() if (reader.inherited or asleep or zeroed) else None
        in_zeroed = None
        update = None                          # every row
        if flags is not None:
            in_zeroed, resting = flags.update(pairs, zeroed, asleep, set())
            if asleep:
                idle = resting                 # (not made of masks that select no row)
                if fresh is not None:
                    idle = idle & ~fresh
                if incomplete:
                    idle = idle & ~restored
                update = ~idle
        force, us, fs = self._forces(update)
        if reader.inherited and fresh is not None:
            self._start_here(fresh & pairs.among(reader.inherited), delta, force, us, fs)
        hertz = ~in_zeroed if zeroed else None
        worked = self._work(delta, force, update, hertz, now, interval)
        if us is not None:
            self._shear_work(us, fs, update)
        table.by_body = None
        table.resting = None if update is None else ~update
        return self._loading(mask[table.sides()], worked)

    def _forces(self, update):
        """The normal force (N) of each row, and with cs > 0 its shear displacement (m) and
        force (N), from YADE for the rows `update` (None: every row). The others are slack
        zeroed pairs asleep: they keep their numbers from their last read, which nothing uses
        (they are not updated), and reading them from YADE would cost a microsecond each; the
        fragment clouds of a cascade are mostly such pairs."""
        table = self.table
        physs = table.physs if update is None else take(table.physs,
                                                        update.nonzero()[0].tolist())
        m = len(physs)

        def kept(got, stored):                 # the rows read, the others as they were
            if update is None:
                return got
            out = stored.copy()
            out[update] = got
            return out
        force = kept(np.fromiter([p.normalForce.norm() for p in physs], float, m), table.force)
        if self.reader.cs <= 0.0:
            return force, None, None
        us = kept(np.fromiter([p.usTotal.norm() for p in physs], float, m), table.shear_disp)
        fs = kept(np.fromiter([p.shearForce.norm() for p in physs], float, m), table.shear_force)
        return force, us, fs

    def _find_restored(self, interactions, bodies):
        """Rows restored from a save get YADE's objects; rows whose interaction is gone go.
        Returns which of the rows kept were restored."""
        table = self.table
        restored = np.zeros(len(table), bool)
        found = []
        for k, g in enumerate(table.geoms):
            if g is None:
                pair = (int(table.a[k]), int(table.b[k]))
                if bodies[pair[0]] is None or bodies[pair[1]] is None:
                    continue                   # erased since (YADE's has() would abort)
                inter = interactions[pair] if interactions.has(*pair) else None
                if inter is None or not inter.isReal:
                    continue
                table.geoms[k], table.physs[k] = inter.geom, inter.phys
                restored[k] = True
            found.append(k)
        table.keep(np.array(found, np.int64))
        table.incomplete = False
        return restored[found]

    def _screen(self, interactions, bodies, mask, counts, now, flags, zeroed, asleep):
        """The rows laid out as the contacts of tracked bodies now, without a pass over every
        interaction: a row whose overlap is negative was erased by the law at its last step (its
        geometry is YADE's last, kept alive by the row) and goes; rows with no tracked body go;
        then a tracked body whose count of real interactions (YADE's, in C++) differs from its
        rows has them taken from YADE (withBody): new ones become fresh rows, missing ones go.
        The rows of zeroed pairs asleep (`flags`, a ZeroedRows, or None) are not read: they are
        slack, and nothing uses their overlap; one the law erased since is found missing by its
        bodies' count. `flags` follows the rows (of the pairs `zeroed`, `asleep`).
        Returns masks of the fresh rows (None: none) and of rows restored from a save, and the
        overlaps (the last read's for the rows asleep)."""
        table, erased = self.table, self.reader.erased_bodies
        restored = (self._find_restored(interactions, bodies) if table.incomplete
                    else np.zeros(len(table), bool))
        geoms = table.geoms
        if flags is not None and flags.pairs is None:
            flags = None                       # rows restored: looked up once the read is done
        resting = None if flags is None or not asleep else flags.asleep
        if resting is None:
            delta = np.fromiter([g.penetrationDepth for g in geoms], float, len(table))
        else:
            delta = table.overlap.copy()
            read = (~resting).nonzero()[0]
            delta[read] = np.fromiter([g.penetrationDepth for g in take(geoms, read.tolist())],
                                      float, len(read))
        keep = (delta >= 0.0) & (mask[table.a] | mask[table.b])
        if erased:
            gone = np.zeros(len(mask), bool)
            gone[np.fromiter(erased, np.int64, len(erased))] = True
            keep &= ~(gone[table.a] | gone[table.b])
        if not keep.all():
            rows = keep.nonzero()[0]
            table.keep(rows)
            delta, restored = delta[rows], restored[rows]
            if flags is not None:
                flags.keep(rows)
        have = table.sides_per_body(len(mask))
        changed = (mask & (have != counts())).nonzero()[0]
        fresh = None
        if len(changed):
            kept, new, new_geoms = self._rescan(interactions, bodies, changed, now)
            if kept is not None:
                delta, restored = delta[kept], restored[kept]
                if flags is not None:
                    flags.keep(kept)
            if new:
                added = np.fromiter([g.penetrationDepth for g in new_geoms], float, len(new))
                none = np.zeros(len(new), bool)
                fresh = np.concatenate((np.zeros(len(delta), bool), ~none))
                delta = np.concatenate((delta, added))
                restored = np.concatenate((restored, none))
                if flags is not None:
                    flags.append([(a, b) if a < b else (b, a) for a, b in new], zeroed, asleep)
        if flags is not None:
            flags.pairs = table.pairs()
        return fresh, restored, delta

    def _rescan(self, interactions, bodies, changed, now):
        """Rows of the bodies `changed` from YADE's own lists: rows not in them go, interactions
        not in the rows are appended as fresh rows. Returns the indices of the rows kept (None:
        all), the new rows' pairs (id1, id2) and their geometries."""
        table = self.table
        current = {}
        for bid in changed.tolist():
            for inter in interactions.withBody(bid):
                current[(inter.id1, inter.id2)] = inter
        is_changed = np.zeros(len(bodies), bool)
        is_changed[changed] = True
        touched = is_changed[table.a] | is_changed[table.b]
        keys = list(zip(table.a[touched].tolist(), table.b[touched].tolist()))
        known = set(keys)
        stale = [k for k, key in zip(touched.nonzero()[0].tolist(), keys) if key not in current]
        kept = None
        if stale:
            keep = np.ones(len(table), bool)
            keep[stale] = False
            kept = keep.nonzero()[0]
            table.keep(kept)
        new = [(key, inter) for key, inter in current.items() if key not in known]
        if not new:
            return kept, [], []
        pairs = [key for key, _ in new]
        geoms = [inter.geom for _, inter in new]
        stiffness = self.reader.stiffness
        data = np.array([fresh_row(stiffness, bodies, ia, ib, now) for ia, ib in pairs], float).T
        ab = np.array(pairs, np.int64).T
        table.append(ab[0], ab[1], data, geoms, [inter.phys for _, inter in new])
        return kept, pairs, geoms

    def _start_here(self, rows, delta, force, us, fs):
        """The fresh `rows` of inherited pairs count work from the present state on, not from
        first touch: a contact that a fresh fragment inherited overlapping (with a neighbour or
        a sibling) did no work on it yet; counted from zero, its whole overlap, artificial part
        included, would count as if the fragment had just been loaded through it."""
        table = self.table
        table.overlap[rows] = table.overlap_before[rows] = delta[rows]
        table.force[rows] = force[rows]
        if us is not None:
            table.shear_disp[rows] = us[rows]
            table.shear_force[rows] = fs[rows]

    def _work(self, delta, force, update, hertz, now, interval):
        """Add each updated contact's normal work since the last read; returns the rows that
        worked."""
        table = self.table
        d0 = table.overlap
        everyone = update is None
        grows = delta > d0 if everyone else update & (delta > d0)
        worked = grows
        rows = grows.nonzero()[0]
        if len(rows):
            table.work[rows] += self._loading_work(rows, d0, delta, force, hertz, interval)
        peaked = _law.peaked(d0, delta, table.overlap_before, table.time_before, table.time_read)
        if not everyone:
            peaked &= update
        for k in peaked.nonzero()[0].tolist():           # sparse reads only: a few per impact
            if hertz is not None and not hertz[k]:
                continue                                 # zeroed pairs: the peak is d0, no work
            work = _law.past_peak(float(d0[k]), float(table.force[k]), table.physs[k].kno,
                                  float(table.overlap_before[k]), float(table.time_before[k]),
                                  float(table.time_read[k]), now, float(delta[k]))
            if work is not None:
                table.work[k] += work
                worked = worked.copy() if worked is grows else worked
                worked[k] = True
        where = True if everyone else update
        data = table.data
        np.copyto(data[OVERLAP_BEFORE], d0, where=where)      # d0 is still the last overlap
        np.copyto(data[TIME_BEFORE], data[TIME_READ], where=where)
        np.copyto(data[TIME_READ], now, where=where)
        np.copyto(data[OVERLAP], delta, where=where)
        np.copyto(data[FORCE], force, where=where)
        return worked

    def _loading_work(self, rows, d0, delta, force, hertz, interval):
        """Normal work (J) of the `rows` whose overlap grew: Hertz rows by the law, zeroed pairs
        (hertz False) by the trapezoid on their total force."""
        table = self.table
        f0 = table.force[rows]
        first_touch = _law.first_touch_factor(interval)
        if hertz is None:
            kno = table.kno_of(rows, keep=True)
            return _law.loading(d0[rows], f0, kno, delta[rows], force[rows], first_touch)
        work = np.empty(len(rows))
        h = hertz[rows]
        hr, tr = rows[h], rows[~h]
        kno = table.kno_of(hr, keep=True)
        work[h] = _law.loading(d0[hr], f0[h], kno, delta[hr], force[hr], first_touch)
        work[~h] = _law.trapezoid(d0[tr], f0[~h], delta[tr], force[tr])
        return work

    def _shear_work(self, us, fs, update):
        table = self.table
        rows = us > table.shear_disp
        if update is not None:
            rows &= update
        table.shear_work[rows] += _law.trapezoid(table.shear_disp[rows], table.shear_force[rows],
                                                 us[rows], fs[rows])
        where = True if update is None else update
        np.copyto(table.data[SHEAR_DISP], us, where=where)
        np.copyto(table.data[SHEAR_FORCE], fs, where=where)

    def _loading(self, in_sides, worked):
        """Each tracked body's Ek': the sum, over its contacts whose own work holds at least
        emin, of its share of that work; its strongest such contact; whether one worked.
        `in_sides`: whether each side of each contact (a over b) is a tracked body's."""
        table, reader = self.table, self.reader
        total = total_work(table.work, table.shear_work, reader.cs)
        data, ids_of = table.data, table.sides()
        counted, share = own_share(total, data[OFFSETS], data[SHARES], reader.emin)
        counted &= in_sides
        grew = set(ids_of[in_sides & worked].tolist())
        # the counted sides contact by contact, a before b (nonzero takes the transpose in its
        # logical order): sums in the order a loop over the contacts makes them
        row, side = counted.T.nonzero()
        if not len(row):
            return Loading(grew=grew)
        owner, values = ids_of[side, row], share[side, row]
        # strongest: the first side of each body with the largest share (a loop's strict >);
        # lexsort is stable: among equal shares the first side comes first
        best = np.lexsort((-values, owner))
        ranked = owner[best]
        head = np.empty(len(best), bool)
        head[0] = True
        head[1:] = ranked[1:] != ranked[:-1]
        heads = best[head]
        ids = ranked[head]                               # the bodies, in id order
        # each body's sum over its sides in their order (bincount adds in the order given)
        sums = np.bincount(owner, weights=values)[ids]
        heads = heads[values[heads] > 0.0]
        # (ids, share, row, sign, partner) as arrays: a cloud has hundreds of bodies, and most
        # reads ask only for the partners of some
        row, side = row[heads], side[heads]
        ranked = (owner[heads], values[heads], row, 1.0 - 2.0 * side, ids_of[::-1][side, row])
        return Loading(strongest=StrongestContacts(geoms=table.geoms, ranked=ranked), grew=grew,
                       ids=ids, sums=sums)
