"""Reading the stressing energy from YADE's interactions (Eqs. 14-16).

ContactReader keeps the real interactions that involve a tracked body as rows of numbers, one per
contact, and turns each read into the loading of each body: its counted energy Ek' (J), its most
energetic contact, and whether any of its contacts still worked. Two paths read alike
(tests/test_contact_paths.py):
- few contacts (laboratory scenes): YADE's list of real interactions, contact by contact on
  Python scalars;
- many (process scale): the rows kept, their overlaps and forces fetched from YADE (about 0.5 us
  per contact) and their work and sums in numpy; new contacts are looked for only around the
  tracked bodies whose count of real interactions (one C++ call for all the bodies) differs from
  their rows: no pass over every interaction in Python.
Two paths because each is the faster one somewhere. Measured per step of a whole run (CPU time,
a read every step, breakage out of reach, medians of 6 runs): 4 particles hitting a plate 60 us
per step contact by contact, 196 us with numpy; the default bed (44 contacts) 208 against 303 us;
a bed of 5 layers (203 contacts) 2095 against 1366 us. Per read alone: 4 contacts 9 against 64 us,
44 contacts 65 against 107 us, 203 contacts 308 against 281 us. The physics of a contact, its
normal work, shear work and peak (HertzMindlinWork) and what each body counts of it (total_work,
own_share), is one definition that both paths call, on floats or on arrays; calling it rather
than repeating it costs the scalar path 0.1-0.2 us per contact (7-17 % of a read).
Duck-typed on YADE's interaction container, geometry and physics objects; no yade import.
"""
from __future__ import annotations

import math
from itertools import chain

import numpy as np

from yadebreak import model

#: while the rows are at most this many a read goes contact by contact on Python scalars, beyond
#: with numpy: measured, the scalar path costs about 1.7 us per contact, the numpy one about
#: 0.7 us per contact plus 100 us per read (per step, see the module's docstring)
SMALL = 150

#: the columns of numbers kept per contact (J, m, N, s); saved with the scene in this order.
#: offset_a, offset_b: the contact's work already counted in an earlier event of body a (b);
#: share_a, share_b: Eq. 4's share of each body.
FIELDS = ("overlap", "force", "work", "offset_a", "offset_b", "share_a", "share_b",
          "shear_disp", "shear_force", "shear_work", "overlap_before", "time_before", "time_read")


(_OVERLAP, _FORCE, _WORK, _OFFSET_A, _OFFSET_B, _SHARE_A, _SHARE_B, _SHEAR_DISP, _SHEAR_FORCE,
 _SHEAR_WORK, _OVERLAP_BEFORE, _TIME_BEFORE, _TIME_READ) = range(len(FIELDS))


def pair_codes(id1, id2):
    """One int64 per pair of body ids (< 2**31), in the order given."""
    return (np.asarray(id1, np.int64) << 32) | np.asarray(id2, np.int64)


#: stored_share takes a body's rows at once from this many on
VECTOR_ROWS = 8


class _RowPairs:
    """The rows' pairs as (smaller id, larger id), made once per read when asked: as pair_codes
    and as tuples, and which of them are in a set of pairs."""

    def __init__(self, a, b):
        self.lo, self.hi = np.minimum(a, b), np.maximum(a, b)
        self._codes = self._tuples = None

    def among(self, pairs, within=None):
        """Which rows are pairs of the set `pairs`: each row looked up when the set is the larger
        (the zeroed pairs of many fragments), else a sorted search over the set's codes. With
        `within` (a mask of rows holding every row of the set), only those rows are looked up."""
        n = len(self.lo)
        if not pairs:
            return np.zeros(n, bool)
        if within is not None:
            rows = np.flatnonzero(within)
            tuples = self._tuple_list()
            found = np.zeros(n, bool)
            found[rows] = np.fromiter(map(pairs.__contains__, [tuples[k] for k in rows.tolist()]),
                                      bool, len(rows))
            return found
        if len(pairs) >= n:
            return np.fromiter(map(pairs.__contains__, self._tuple_list()), bool, n)
        if self._codes is None:
            self._codes = pair_codes(self.lo, self.hi)
        ab = np.fromiter(chain.from_iterable(pairs), np.int64, 2 * len(pairs))
        known = np.sort(pair_codes(ab[0::2], ab[1::2]))
        pos = np.minimum(np.searchsorted(known, self._codes), len(known) - 1)
        return known[pos] == self._codes

    def _tuple_list(self):
        if self._tuples is None:
            self._tuples = list(zip(self.lo.tolist(), self.hi.tolist()))
        return self._tuples


class HertzMindlinWork:
    """Eqs. 15-16 for YADE's Law2_ScGeom_MindlinPhys_Mindlin: the normal work while the overlap
    grows, with F = kno delta^1.5 + dashpot.

    The Hertz part is exact between two reads, 0.4 kno (d1^2.5 - d0^2.5); the dashpot part
    (total force minus kno d^1.5) by the trapezoidal rule, except from first touch, where
    Mindlin's dashpot grows like delta^(1/4) at a nearly constant rate: over k steps its work is
    (0.8 - 0.3 / k^2) F d (the trapezoid's 0.5 over one step, which is what YADE's leapfrog makes
    of it, 0.8 over many). Pairs whose kno varies (zeroed artificial overlaps) take the trapezoid
    on their total force.

    Each formula is written once, with operators that numpy arrays and Python floats share (the
    same operations in the same order: the same numbers to the last bit on either), and both
    read paths of ContactReader call it."""

    @staticmethod
    def first_touch_factor(interval):
        return 0.8 - 0.3 / interval ** 2

    @staticmethod
    def trapezoid(d0, f0, delta, force):
        """Work (J) of a force going from f0 to `force` (N) as the displacement goes d0 -> delta
        (m): the dashpot of zeroed pairs, and the shear work (Eq. 16)."""
        return 0.5 * (f0 + force) * (delta - d0)

    @staticmethod
    def from_overlap(d0, f0, kno, delta, force, sqrt):
        """Work (J) from overlap d0 > 0 (force f0) up to delta (> d0): the Hertz part exact, the
        dashpot part (force minus kno d^1.5) by the trapezoid. `sqrt`: math.sqrt on floats,
        np.sqrt on arrays."""
        el0 = kno * d0 * sqrt(d0)
        el1 = kno * delta * sqrt(delta)
        return 0.4 * (el1 * delta - el0 * d0) + 0.5 * (f0 - el0 + force - el1) * (delta - d0)

    @staticmethod
    def from_first_touch(kno, delta, force, first_touch, sqrt):
        """Work (J) from first touch up to delta: the Hertz part exact, the dashpot's
        first_touch F d (see first_touch_factor)."""
        el1 = kno * delta * sqrt(delta)
        return 0.4 * el1 * delta + first_touch * (force - el1) * delta

    @classmethod
    def loading(cls, d0, f0, kno, delta, force, first_touch):
        """Work (J) of a Hertz contact from overlap d0 (force f0) up to delta (> d0), over
        arrays of contacts (ContactReader._read_each calls from_overlap and from_first_touch on
        floats itself: a call less per contact)."""
        touching = d0 > 0.0
        if touching.all():                      # the usual case: one formula, no np.where
            return cls.from_overlap(d0, f0, kno, delta, force, np.sqrt)
        d0c = np.maximum(d0, 0.0)               # equal to d0 where the formula is taken
        return np.where(touching, cls.from_overlap(d0c, f0, kno, delta, force, np.sqrt),
                        cls.from_first_touch(kno, delta, force, first_touch, np.sqrt))

    @staticmethod
    def peaked(d0, delta, overlap_before, time_before, time_read):
        """The overlap fell since the last read (d0 at time_read) after rising from the read
        before (overlap_before at time_before): it peaked in between (floats or arrays)."""
        return (delta < d0) & (overlap_before < d0) & (time_read > time_before)

    @classmethod
    def past_peak(cls, d0, f0, kno, overlap_before, time_before, time_read, now, delta):
        """Work (J) of a contact that peaked between two reads (peaked()), up to the peak of
        the parabola through its last three overlaps (model.parabolic_peak); None when that
        peak is not above d0. Floats: a few contacts per impact, at sparse reads only."""
        peak = model.parabolic_peak(time_before, overlap_before, time_read, d0, now, delta)
        return cls.to_peak(d0, f0, kno, peak) if peak > d0 else None

    @staticmethod
    def to_peak(d0, f0, kno, peak):
        """Work (J) of a Hertz contact from d0 up to `peak` (> d0), where the overlap peaked
        between two reads (sparse reads; the peak from model.parabolic_peak)."""
        el0 = kno * d0 * math.sqrt(d0)
        return 0.4 * kno * (peak ** 2.5 - d0 ** 2.5) + 0.5 * (f0 - el0) * (peak - d0)

    @staticmethod
    def stored(kno, delta):
        """Elastic energy (J) held in a Hertz contact: 0.4 kno delta^2.5."""
        return 0.4 * kno * delta ** 2.5


def total_work(work, shear_work, cs):
    """A contact's counted work (J): normal work plus cs times its shear work (floats or
    arrays)."""
    return work + cs * shear_work if cs > 0.0 else work


def own_share(total, offset, share, emin):
    """One body's side of a contact: whether the work done since its offset (J) counts (at least
    emin), and its share (Eq. 4) of that work (J); floats or arrays."""
    own = total - offset
    return own >= emin, share * own


class StrongestContacts:
    """body -> (share of energy (J), contact normal, sign, the other body) of its most energetic
    contact at a read; the normal is fetched from YADE only for the bodies asked for."""

    def __init__(self, found=None, geoms=None):
        self._found = found or {}     # body -> (share, row, sign, other)
        self._geoms = geoms
        self._made = {}

    def __setitem__(self, body, value):
        self._made[body] = value

    def get(self, body, default=None):
        made = self._made.get(body)
        if made is None:
            found = self._found.get(body)
            if found is None:
                return default
            share, row, sign, other = found
            made = self._made[body] = (share, self._geoms[row].normal, sign, other)
        return made


class Loading:
    """The bodies' loading found by one read."""

    __slots__ = ("energy", "strongest", "grew")

    def __init__(self, energy=None, strongest=None, grew=None):
        self.energy = energy if energy is not None else {}   # body -> Ek' (J) counted now
        self.strongest = strongest if strongest is not None else StrongestContacts()
        self.grew = grew if grew is not None else set()     # tracked bodies with a contact that
        #                                                       worked since the last read


class ContactReader:
    """The contacts of tracked bodies, read every time the schedule says: one row per contact
    (in the order YADE listed them after a scalar read; kept, then new ones, after a numpy read).
    Each field of FIELDS is an array (a row of one block, so that a new layout gathers all of
    them at once)."""

    def __init__(self, stiffness_by_material_id, cs, emin):
        self.stiffness = stiffness_by_material_id     # YADE material id -> Hertz stiffness (Pa)
        self.cs = cs
        self.emin = emin
        self.law = HertzMindlinWork()
        self.inherited = set()                        # (smaller id, larger id): see inherit()
        self._erased = set()                          # bodies gone since the last read
        self.small = SMALL                            # see SMALL (tests set it to choose a path)
        self._set_rows(np.empty(0, np.int64), np.empty(0, np.int64),
                       np.empty((len(FIELDS), 0)), [], [])

    def _set_rows(self, a, b, data, geoms, physs, rows=None, incomplete=False):
        self.a, self.b = a, b                         # body ids as YADE orders the pair
        # the numbers: a block FIELDS x contacts, or (after a scalar read, until numpy is needed)
        # one list per contact
        self._data, self._rows = data, rows
        self.geoms, self.physs = geoms, physs          # YADE's objects (None after a restore)
        self._by_body = None                           # see _rows_of
        self._index = None                             # (id1, id2) -> row, from a scalar read
        self._pairs = None                             # see _row_pairs
        self._incomplete = incomplete          # rows without YADE's objects yet (a restore)

    def __len__(self):
        return len(self.a)

    @property
    def data(self):
        """The numbers of every contact, FIELDS x contacts (each field also as an attribute)."""
        if self._data is None:
            self._data = (np.array(self._rows, float).T.copy() if self._rows
                          else np.empty((len(FIELDS), 0)))
            self._rows = None
        return self._data

    def _value(self, row, field):
        rows = self._rows
        return rows[row][field] if rows is not None else float(self._data[field, row])

    def _set_value(self, row, field, value):
        if self._rows is not None:
            self._rows[row][field] = value
        else:
            self._data[field, row] = value

    # -- the read ----------------------------------------------------------------------------
    def read(self, interactions, bodies, tracked, zeroed, now, interval, asleep=(), counts=None):
        """One read of the real interactions; contacts that ceased drop out. `zeroed` holds the
        pairs whose kno varies, `asleep` those of them that carry no force and are not updated
        now (they do no work), all keyed (smaller id, larger id); `interval` is the steps since
        the last read; `counts()` gives the real interactions of each body id (YADE's
        numIntrsOfEachBody, in C++): with it, a read of many contacts looks for new ones only
        around the bodies whose count changed (_screen)."""
        if counts is None or len(self) <= self.small:
            real = interactions.all(True)
            return self._read_each(real, [i.id1 for i in real], [i.id2 for i in real], bodies,
                                   tracked, zeroed, now, interval, asleep)
        mask = np.zeros(len(bodies), bool)              # tracked, by body id
        if tracked:
            mask[np.fromiter(tracked, np.int64, len(tracked))] = True
        fresh, restored, delta = self._screen(interactions, bodies, mask, counts, now)
        pairs = self._row_pairs() if (self.inherited or asleep or zeroed) else None
        in_zeroed = pairs.among(zeroed) if zeroed else None
        update = None                          # every row
        if asleep:                             # pairs asleep are zeroed pairs: look there only
            update = ~(pairs.among(asleep, within=in_zeroed) & ~fresh & ~restored)
        force, us, fs = self._forces(update)
        if self.inherited and fresh.any():
            self._start_here(fresh & pairs.among(self.inherited), delta, force, us, fs)
        self.inherited.clear()                 # read now or gone
        self._erased.clear()
        hertz = ~in_zeroed if zeroed else None
        worked = self._work(delta, force, update, hertz, now, interval)
        if us is not None:
            self._shear_work(us, fs, update)
        self._by_body = None
        return self._loading(mask[self.a], mask[self.b], worked)

    def _row_pairs(self):
        """The rows' _RowPairs, kept until the rows change (most reads keep every row)."""
        if self._pairs is None:
            self._pairs = _RowPairs(self.a, self.b)
        return self._pairs

    def _forces(self, update):
        """The normal force (N) of each row, and with cs > 0 its shear displacement (m) and
        force (N), from YADE for the rows `update` (None: every row). The others are slack
        zeroed pairs asleep: they keep their numbers from their last read, which nothing uses
        (they are not updated), and reading them from YADE would cost a microsecond each; the
        fragment clouds of a cascade are mostly such pairs."""
        physs = self.physs if update is None else [self.physs[k]
                                                   for k in np.flatnonzero(update).tolist()]
        m = len(physs)

        def kept(got, stored):                 # the rows read, the others as they were
            if update is None:
                return got
            out = stored.copy()
            out[update] = got
            return out
        force = kept(np.fromiter([p.normalForce.norm() for p in physs], float, m), self.force)
        if self.cs <= 0.0:
            return force, None, None
        us = kept(np.fromiter([p.usTotal.norm() for p in physs], float, m), self.shear_disp)
        fs = kept(np.fromiter([p.shearForce.norm() for p in physs], float, m), self.shear_force)
        return force, us, fs

    def _screen(self, interactions, bodies, mask, counts, now):
        """The rows laid out as the contacts of tracked bodies now, without a pass over every
        interaction: a row whose overlap is negative was erased by the law at its last step (its
        geometry is YADE's last, kept alive by the row) and goes; rows with no tracked body go;
        then a tracked body whose count of real interactions (YADE's, in C++) differs from its
        rows has them taken from YADE (withBody): new ones become fresh rows, missing ones go.
        Returns masks of the fresh rows and of rows restored from a save, and the overlaps."""
        restored = np.zeros(len(self), bool)
        if self._incomplete:                   # restored from a save: find YADE's objects
            found = []
            for k, g in enumerate(self.geoms):
                if g is None:
                    pair = (int(self.a[k]), int(self.b[k]))
                    if bodies[pair[0]] is None or bodies[pair[1]] is None:
                        continue                   # erased since (YADE's has() would abort)
                    inter = interactions[pair] if interactions.has(*pair) else None
                    if inter is None or not inter.isReal:
                        continue
                    self.geoms[k], self.physs[k] = inter.geom, inter.phys
                    restored[k] = True
                found.append(k)
            self._keep_rows(np.array(found, np.int64))
            restored = restored[found]
            self._incomplete = False
        delta = np.fromiter([g.penetrationDepth for g in self.geoms], float, len(self))
        keep = (delta >= 0.0) & (mask[self.a] | mask[self.b])
        if self._erased:
            gone = np.zeros(len(mask), bool)
            gone[np.fromiter(self._erased, np.int64, len(self._erased))] = True
            keep &= ~(gone[self.a] | gone[self.b])
        if not keep.all():
            rows = np.flatnonzero(keep)
            self._keep_rows(rows)
            delta, restored = delta[rows], restored[rows]
        have = np.bincount(np.concatenate((self.a, self.b)), minlength=len(mask))
        changed = np.flatnonzero(mask & (have != np.asarray(counts(), np.int64)))
        fresh = np.zeros(len(self), bool)
        if len(changed):
            kept, new = self._rescan(interactions, bodies, changed, now)
            if kept is not None:
                delta, restored = delta[kept], restored[kept]
            if new:
                added = np.fromiter([inter.geom.penetrationDepth for inter in new], float,
                                    len(new))
                fresh = np.concatenate((np.zeros(len(delta), bool), np.ones(len(new), bool)))
                delta = np.concatenate((delta, added))
                restored = np.concatenate((restored, np.zeros(len(new), bool)))
        return fresh, restored, delta

    def _rescan(self, interactions, bodies, changed, now):
        """Rows of the bodies `changed` from YADE's own lists: rows not in them go, interactions
        not in the rows are appended as fresh rows. Returns the indices of the rows kept (None:
        all) and the new interactions."""
        current = {}
        for bid in changed.tolist():
            for inter in interactions.withBody(bid):
                current[(inter.id1, inter.id2)] = inter
        is_changed = np.zeros(len(bodies), bool)
        is_changed[changed] = True
        touched = is_changed[self.a] | is_changed[self.b]
        keys = list(zip(self.a[touched].tolist(), self.b[touched].tolist()))
        known = set(keys)
        stale = [k for k, key in zip(np.flatnonzero(touched).tolist(), keys) if key not in current]
        kept = None
        if stale:
            keep = np.ones(len(self), bool)
            keep[stale] = False
            kept = np.flatnonzero(keep)
            self._keep_rows(kept)
        new = [inter for key, inter in current.items() if key not in known]
        if new:
            a = np.array([i.id1 for i in new], np.int64)
            b = np.array([i.id2 for i in new], np.int64)
            data = np.array([self._fresh_row(bodies, ia, ib, now)
                             for ia, ib in zip(a.tolist(), b.tolist())], float).T
            self._set_rows(np.concatenate((self.a, a)), np.concatenate((self.b, b)),
                           np.concatenate((self.data, data), axis=1),
                           self.geoms + [i.geom for i in new], self.physs + [i.phys for i in new])
        return kept, new

    def _fresh_row(self, bodies, a, b, now):
        """The numbers (FIELDS) of a contact between bodies a and b seen first at `now`: no
        work yet, Eq. 4's shares."""
        ka = self.stiffness[bodies[a].material.id]
        kb = self.stiffness[bodies[b].material.id]
        return [0.0, 0.0, 0.0, 0.0, 0.0, float(model.energy_partition(ka, kb)),
                float(model.energy_partition(kb, ka)), 0.0, 0.0, 0.0, 0.0, now, now]

    def _keep_rows(self, rows):
        """Only the rows `rows` (indices, in order) stay."""
        self._set_rows(self.a[rows], self.b[rows], self.data[:, rows],
                       [self.geoms[k] for k in rows.tolist()],
                       [self.physs[k] for k in rows.tolist()])

    def _read_each(self, real, id1, id2, bodies, tracked, zeroed, now, interval, asleep):
        """The same read contact by contact on Python scalars: for a few contacts (laboratory
        scenes), where numpy's cost per call outweighs its cost per contact."""
        cs, emin = self.cs, self.emin
        # the columns as local names: this loop runs for every contact at every read
        OV, F, W, OA, OB, SA, SB, SD, SF, SW, OVB, TB, TR = range(len(FIELDS))
        law = self.law
        first_touch = law.first_touch_factor(interval)
        from_overlap, from_first_touch, sqrt = law.from_overlap, law.from_first_touch, math.sqrt
        peaked, trapezoid, total_of, share_of = law.peaked, law.trapezoid, total_work, own_share
        inherited = self.inherited
        index = self._index
        if index is None:             # the last read was numpy's
            index = dict(zip(zip(self.a.tolist(), self.b.tolist()), range(len(self.a))))
        new_index = {}
        old_rows = self._rows if self._rows is not None else self.data.T.tolist()
        old_geoms, old_physs = self.geoms, self.physs
        a_list, b_list, rows, geoms, physs = [], [], [], [], []
        energy, found, grew, by_body = {}, {}, set(), {}
        for inter, a, b in zip(real, id1, id2):
            in_a = a in tracked
            in_b = b in tracked
            if not (in_a or in_b):
                continue
            pair = (a, b) if a < b else (b, a)
            j = index.get((a, b))
            update, delta = True, None
            if j is not None:
                geom = old_geoms[j]
                if geom is None:                              # restored from a save
                    row, geom, phys = old_rows[j], inter.geom, inter.phys
                else:
                    delta = geom.penetrationDepth
                    if delta < 0.0:       # the law erased it after the last read, YADE made it anew
                        j, delta = None, None
                    else:
                        row, phys = old_rows[j], old_physs[j]
                        update = not (asleep and pair in asleep)   # a slack zeroed pair: no work
            if j is None:
                geom, phys = inter.geom, inter.phys
                row = self._fresh_row(bodies, a, b, now)
                if inherited and pair in inherited:          # see _start_here
                    row[OV] = row[OVB] = geom.penetrationDepth
                    row[F] = phys.normalForce.norm()
                    if cs > 0.0:
                        row[SD] = phys.usTotal.norm()
                        row[SF] = phys.shearForce.norm()
            if update:
                if delta is None:
                    delta = geom.penetrationDepth
                force = phys.normalForce.norm()
                d0 = row[OV]
                work = None
                if delta > d0:
                    if zeroed and pair in zeroed:
                        work = trapezoid(d0, row[F], delta, force)
                    elif d0 > 0.0:
                        work = from_overlap(d0, row[F], phys.kno, delta, force, sqrt)
                    else:
                        work = from_first_touch(phys.kno, delta, force, first_touch, sqrt)
                elif (peaked(d0, delta, row[OVB], row[TB], row[TR])
                      and not (zeroed and pair in zeroed)):
                    work = law.past_peak(d0, row[F], phys.kno, row[OVB], row[TB], row[TR], now,
                                         delta)
                if work is not None:
                    row[W] += work
                    if in_a:
                        grew.add(a)
                    if in_b:
                        grew.add(b)
                row[OVB] = d0
                row[TB] = row[TR]
                row[TR] = now
                row[OV] = delta
                row[F] = force
                if cs > 0.0:
                    us = phys.usTotal.norm()
                    fs = phys.shearForce.norm()
                    if us > row[SD]:
                        row[SW] += trapezoid(row[SD], row[SF], us, fs)
                    row[SD] = us
                    row[SF] = fs
            k = len(rows)
            new_index[(a, b)] = k
            rows.append(row)
            a_list.append(a)
            b_list.append(b)
            geoms.append(geom)
            physs.append(phys)
            total = total_of(row[W], row[SW], cs)
            if in_a:
                by_body.setdefault(a, []).append((k, 0))
                counted, share = share_of(total, row[OA], row[SA], emin)
                if counted:
                    energy[a] = energy.get(a, 0.0) + share
                    if share > found.get(a, (0.0,))[0]:
                        found[a] = (share, k, 1.0, b)
            if in_b:
                by_body.setdefault(b, []).append((k, 1))
                counted, share = share_of(total, row[OB], row[SB], emin)
                if counted:
                    energy[b] = energy.get(b, 0.0) + share
                    if share > found.get(b, (0.0,))[0]:
                        found[b] = (share, k, -1.0, a)
        self._set_rows(np.array(a_list, np.int64), np.array(b_list, np.int64), None, geoms,
                       physs, rows=rows)
        self._by_body, self._index = by_body, new_index
        inherited.clear()                 # read now or gone
        self._erased.clear()
        return Loading(energy, StrongestContacts(found, geoms), grew)

    def _start_here(self, rows, delta, force, us, fs):
        """The fresh `rows` of inherited pairs count work from the present state on, not from
        first touch: a contact that a fresh fragment inherited overlapping (with a neighbour or
        a sibling) did no work on it yet; counted from zero, its whole overlap, artificial part
        included, would count as if the fragment had just been loaded through it."""
        self.overlap[rows] = self.overlap_before[rows] = delta[rows]
        self.force[rows] = force[rows]
        if us is not None:
            self.shear_disp[rows] = us[rows]
            self.shear_force[rows] = fs[rows]

    def _work(self, delta, force, update, hertz, now, interval):
        """Add each updated contact's normal work since the last read; returns the rows that
        worked."""
        d0 = self.overlap
        everyone = update is None
        grows = delta > d0 if everyone else update & (delta > d0)
        worked = grows
        rows = np.flatnonzero(grows)
        if len(rows):
            f0 = self.force[rows]
            if hertz is None:
                kno = np.fromiter([self.physs[k].kno for k in rows.tolist()], float, len(rows))
                work = self.law.loading(d0[rows], f0, kno, delta[rows], force[rows],
                                        self.law.first_touch_factor(interval))
            else:
                work = np.empty(len(rows))
                h = hertz[rows]
                hr, tr = rows[h], rows[~h]
                kno = np.fromiter([self.physs[k].kno for k in hr.tolist()], float, len(hr))
                work[h] = self.law.loading(d0[hr], f0[h], kno, delta[hr], force[hr],
                                           self.law.first_touch_factor(interval))
                work[~h] = self.law.trapezoid(d0[tr], f0[~h], delta[tr], force[tr])
            self.work[rows] += work
        peaked = self.law.peaked(d0, delta, self.overlap_before, self.time_before,
                                 self.time_read)
        if not everyone:
            peaked &= update
        for k in np.flatnonzero(peaked).tolist():        # sparse reads only: a few per impact
            if hertz is not None and not hertz[k]:
                continue                                 # zeroed pairs: the peak is d0, no work
            work = self.law.past_peak(float(d0[k]), float(self.force[k]), self.physs[k].kno,
                                      float(self.overlap_before[k]), float(self.time_before[k]),
                                      float(self.time_read[k]), now, float(delta[k]))
            if work is not None:
                self.work[k] += work
                worked = worked.copy() if worked is grows else worked
                worked[k] = True
        where = True if everyone else update
        data = self.data
        np.copyto(data[_OVERLAP_BEFORE], d0, where=where)      # d0 is still the last overlap
        np.copyto(data[_TIME_BEFORE], data[_TIME_READ], where=where)
        np.copyto(data[_TIME_READ], now, where=where)
        np.copyto(data[_OVERLAP], delta, where=where)
        np.copyto(data[_FORCE], force, where=where)
        return worked

    def _shear_work(self, us, fs, update):
        rows = us > self.shear_disp
        if update is not None:
            rows &= update
        self.shear_work[rows] += self.law.trapezoid(self.shear_disp[rows], self.shear_force[rows],
                                                    us[rows], fs[rows])
        where = True if update is None else update
        np.copyto(self.data[_SHEAR_DISP], us, where=where)
        np.copyto(self.data[_SHEAR_FORCE], fs, where=where)

    def _loading(self, in_a, in_b, worked):
        """Each tracked body's Ek': the sum, over its contacts whose own work holds at least
        emin, of its share of that work; its strongest such contact; whether one worked."""
        total = total_work(self.work, self.shear_work, self.cs)
        # the two sides of each contact in YADE's order, a before b: sums in the order a loop over
        # the contacts makes them
        n = len(total)
        body, counted, share = np.empty(2 * n, np.int64), np.empty(2 * n, bool), np.empty(2 * n)
        body[0::2], body[1::2] = self.a, self.b
        counted[0::2], share[0::2] = own_share(total, self.offset_a, self.share_a, self.emin)
        counted[1::2], share[1::2] = own_share(total, self.offset_b, self.share_b, self.emin)
        counted[0::2] &= in_a
        counted[1::2] &= in_b
        grew = set(self.a[in_a & worked].tolist())
        grew.update(self.b[in_b & worked].tolist())
        sides = np.flatnonzero(counted)
        if not len(sides):
            return Loading(grew=grew)
        ids, group = np.unique(body[sides], return_inverse=True)
        values = share[sides]
        sums = np.bincount(group, weights=values, minlength=len(ids))
        # strongest: the first side of each body with the largest share (a loop's strict >)
        best = np.lexsort((sides, -values, group))
        head = np.empty(len(best), bool)
        head[0] = True
        head[1:] = group[best][1:] != group[best][:-1]
        heads = best[head]
        found = {}
        for g, s, value in zip(group[heads].tolist(), sides[heads].tolist(),
                               values[heads].tolist()):
            if value > 0.0:
                row, side = divmod(s, 2)
                found[int(ids[g])] = (value, row, -1.0 if side else 1.0,
                                      int(self.a[row] if side else self.b[row]))
        return Loading(dict(zip(ids.tolist(), sums.tolist())),
                       StrongestContacts(found, self.geoms), grew)

    # -- one body's contacts -------------------------------------------------------------------
    def _rows_of(self, body):
        """[(row, side: 0 for a, 1 for b)] of a body's contacts at the last read, in YADE's order
        (of the tracked bodies' sides, from the scalar read; of every side, from the numpy read:
        asked for tracked bodies only, they are the same)."""
        if isinstance(self._by_body, dict):
            return self._by_body.get(body, ())
        if self._by_body is None:
            sides = np.column_stack((self.a, self.b)).ravel()
            order = np.argsort(sides, kind="stable")
            self._by_body = (sides[order], order)
        sorted_ids, order = self._by_body
        lo, hi = np.searchsorted(sorted_ids, [body, body + 1])
        return [divmod(int(s), 2) for s in order[lo:hi]]

    def _total(self, row):
        return total_work(self._value(row, _WORK), self._value(row, _SHEAR_WORK), self.cs)

    def stored_share(self, body):
        """Elastic energy (J) a body holds now in its counted contacts: its share of the Hertz
        energy, with kno as the law uses it (scaled for zeroed pairs)."""
        total = 0.0
        value = self._value
        sides = self._rows_of(body)
        # a body of many contacts (a fragment in its cloud): which count, at once from the numpy
        # block; below VECTOR_ROWS the loop is the cheaper (numpy's cost per call)
        if self._rows is None and len(sides) >= VECTOR_ROWS:
            rows = np.fromiter((r for r, _ in sides), np.int64, len(sides))
            b = np.fromiter((s for _, s in sides), bool, len(sides))
            d = self._data
            overlap = d[_OVERLAP, rows]
            counted = ((total_work(d[_WORK, rows], d[_SHEAR_WORK, rows], self.cs)
                        - np.where(b, d[_OFFSET_B, rows], d[_OFFSET_A, rows]) >= self.emin)
                       & (overlap > 0.0))
            share = np.where(b, d[_SHARE_B, rows], d[_SHARE_A, rows])
            for k in np.flatnonzero(counted).tolist():   # the sum in the rows' order, as below
                total += float(share[k]) * self.law.stored(self.physs[int(rows[k])].kno,
                                                           float(overlap[k]))
            return total
        for row, side in sides:
            offset = value(row, _OFFSET_B if side else _OFFSET_A)
            overlap = value(row, _OVERLAP)
            if self._total(row) - offset >= self.emin and overlap > 0.0:
                share = value(row, _SHARE_B if side else _SHARE_A)
                total += share * self.law.stored(self.physs[row].kno, overlap)
        return total

    def restart(self, body):
        """Count a body's energy from now on: its offsets become its contacts' present work."""
        for row, side in self._rows_of(body):
            self._set_value(row, _OFFSET_B if side else _OFFSET_A, self._total(row))

    def erased(self, body):
        """`body` left the scene (a parent replaced): its rows go at the next read (YADE erased
        its interactions; the rows' objects would keep their last numbers)."""
        self._erased.add(body)

    def inherit(self, pairs):
        """Pairs (ids) that fresh fragments inherit overlapping: their rows, made at the next
        read, count work from that state on (see _start_here)."""
        self.inherited.update((a, b) if a < b else (b, a) for a, b in pairs)

    def bodies_in_contact(self):
        return set(np.concatenate((self.a, self.b)).tolist())

    # -- saved with the scene ------------------------------------------------------------------
    def to_dict(self):
        return {"fields": list(FIELDS),
                "rows": [[a, b, *v] for a, b, v in zip(self.a.tolist(), self.b.tolist(),
                                                      self.data.T.tolist())],
                "inherited": sorted(self.inherited)}

    def restore(self, data):
        if data["fields"] != list(FIELDS):
            raise ValueError("saved contacts have other fields than this yadebreak's")
        # a contact that had separated at its last read (overlap < 0) is left out: the law erases
        # such an interaction, and the run this continues counted its next touch from zero;
        # YADE's saved scene may still hold the interaction
        rows = [r for r in data["rows"] if r[2] >= 0.0]
        values = np.array([r[2:] for r in rows], float).reshape(len(rows), len(FIELDS))
        self._set_rows(np.array([r[0] for r in rows], np.int64),
                       np.array([r[1] for r in rows], np.int64), values.T.copy(),
                       [None] * len(rows), [None] * len(rows),
                       incomplete=bool(rows))
        self.inherited = {tuple(pair) for pair in data.get("inherited", ())}


def _column(k):
    return property(lambda self: self.data[k], doc=f"{FIELDS[k]} of each contact (a view)")


for _k, _name in enumerate(FIELDS):
    setattr(ContactReader, _name, _column(_k))
