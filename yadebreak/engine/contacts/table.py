"""The contacts of tracked bodies as rows of numbers, one per contact: the pair's body ids as YADE
orders them (a, b), YADE's geometry and physics objects, and the numbers of FIELDS, kept as one
block FIELDS x contacts (after a numpy read) or as one list per contact (after a read contact by
contact, until numpy needs the block). Saved with the scene in FIELDS' order."""
from __future__ import annotations

from functools import lru_cache
from itertools import chain
from operator import itemgetter

import numpy as np

from yadebreak import model
from yadebreak.engine.contacts.law import total_work

#: the columns of numbers kept per contact (J, m, N, s); saved with the scene in this order.
#: offset_a, offset_b: the contact's work already counted in an earlier event of body a (b);
#: share_a, share_b: Eq. 4's share of each body.
FIELDS = ("overlap", "force", "work", "offset_a", "offset_b", "share_a", "share_b",
          "shear_disp", "shear_force", "shear_work", "overlap_before", "time_before", "time_read")

(OVERLAP, FORCE, WORK, OFFSET_A, OFFSET_B, SHARE_A, SHARE_B, SHEAR_DISP, SHEAR_FORCE,
 SHEAR_WORK, OVERLAP_BEFORE, TIME_BEFORE, TIME_READ) = range(len(FIELDS))
#: the rows of the block with both sides' offsets and shares, a over b (as ContactTable.sides)
OFFSETS, SHARES = slice(OFFSET_A, OFFSET_B + 1), slice(SHARE_A, SHARE_B + 1)


def pair_codes(id1, id2):
    """One int64 per pair of body ids (< 2**31), in the order given."""
    return (np.asarray(id1, np.int64) << 32) | np.asarray(id2, np.int64)


def fresh_row(stiffness, bodies, a, b, now):
    """The numbers (FIELDS) of a contact between bodies a and b seen first at `now`: no work
    yet, Eq. 4's shares from the Hertz stiffness (Pa) of each body's YADE material id."""
    share_a, share_b = _shares(stiffness[bodies[a].material.id], stiffness[bodies[b].material.id])
    return [0.0, 0.0, 0.0, 0.0, 0.0, share_a, share_b, 0.0, 0.0, 0.0, 0.0, now, now]


@lru_cache(maxsize=None)
def _shares(ka, kb):
    """Eq. 4's shares of bodies of stiffness ka and kb (Pa): a scene has a few materials, and
    collisions make thousands of fresh rows."""
    return float(model.energy_partition(ka, kb)), float(model.energy_partition(kb, ka))


def _column(k):
    return property(lambda self: self.data[k], doc=f"{FIELDS[k]} of each contact (a view)")


class ContactTable:
    """The rows of the last read."""

    overlap = _column(OVERLAP)
    force = _column(FORCE)
    work = _column(WORK)
    offset_a = _column(OFFSET_A)
    offset_b = _column(OFFSET_B)
    share_a = _column(SHARE_A)
    share_b = _column(SHARE_B)
    shear_disp = _column(SHEAR_DISP)
    shear_force = _column(SHEAR_FORCE)
    shear_work = _column(SHEAR_WORK)
    overlap_before = _column(OVERLAP_BEFORE)
    time_before = _column(TIME_BEFORE)
    time_read = _column(TIME_READ)

    def __init__(self):
        self.set(np.empty(0, np.int64), np.empty(0, np.int64), np.empty((len(FIELDS), 0)), [], [])

    def set(self, a, b, data, geoms, physs, rows=None, incomplete=False, by_body=None,
            index=None, kno=None):
        """The rows anew: ids a, b; numbers as a block `data` or as `rows` (lists); YADE's
        objects (None after a restore: `incomplete` until a read finds them); a scalar read
        also gives `by_body` (see rows_of) and `index` ((id1, id2) -> row); `kno`: the rows'
        kno kept so far (see kno_of; None: none kept)."""
        self.a, self.b = a, b
        self._data, self._rows = data, rows
        self.geoms, self.physs = geoms, physs
        self._kno = kno if kno is not None else np.full(len(a), np.nan)
        self.by_body = by_body
        self.index = index
        self._pairs = self._sides = self._per_body = None
        #: the rows the last numpy read left as they were (zeroed pairs asleep: slack, kno 0);
        #: None: every row was read
        self.resting = None
        self.incomplete = incomplete

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

    def row_lists(self):
        """The numbers as one list per contact (what a read contact by contact works on)."""
        return self._rows if self._rows is not None else self.data.T.tolist()

    @property
    def is_block(self):
        return self._rows is None

    def value(self, row, field):
        rows = self._rows
        return rows[row][field] if rows is not None else float(self._data[field, row])

    def set_value(self, row, field, value):
        if self._rows is not None:
            self._rows[row][field] = value
        else:
            self._data[field, row] = value

    def total(self, row, cs):
        """A row's counted work (J)."""
        return total_work(self.value(row, WORK), self.value(row, SHEAR_WORK), cs)

    def keep(self, rows):
        """Only the rows `rows` (indices, in order) stay."""
        kept = rows.tolist()
        self.set(self.a[rows], self.b[rows], self.data[:, rows], take(self.geoms, kept),
                 take(self.physs, kept), kno=self._kno[rows])

    def append(self, a, b, data, geoms, physs):
        """New rows (ids, numbers FIELDS x new, YADE's objects) after the present ones."""
        self.set(np.concatenate((self.a, a)), np.concatenate((self.b, b)),
                 np.concatenate((self.data, data), axis=1), self.geoms + geoms, self.physs + physs,
                 kno=np.concatenate((self._kno, np.full(len(a), np.nan))))

    def kno_of(self, rows, keep=False):
        """kno (N/m^1.5) of YADE's physics of the rows `rows` (an index array). A row's kno is
        taken from YADE once, when first asked with `keep`, then kept: the caller asks so only
        of pairs the zeroing does not scale, whose kno YADE's Ip2 set when it made the contact
        and leaves alone (zeroed pairs are a fresh fragment's from their first step, so a row
        kept is never zeroed later). A cloud's read would otherwise fetch hundreds a read."""
        kno = self._kno[rows]
        missing = np.isnan(kno).nonzero()[0]
        if len(missing):
            at = rows[missing]
            physs = self.physs
            kno[missing] = np.fromiter([physs[k].kno for k in at.tolist()], float, len(at))
            if keep:
                self._kno[at] = kno[missing]
        return kno

    def pairs(self):
        """The rows' RowPairs, kept until the rows change (most reads keep every row)."""
        if self._pairs is None:
            self._pairs = RowPairs(self.a, self.b)
        return self._pairs

    def sides(self):
        """The rows' body ids, a over b (2 x contacts), kept until the rows change."""
        if self._sides is None:
            self._sides = np.stack((self.a, self.b))
        return self._sides

    def places_of(self, bodies):
        """Of each side of each row (2 x contacts, a over b, as sides()), the place of its body
        in `bodies` (a non-empty list of ids), -1 for a body not in it."""
        ids_of = self.sides()
        slot = np.full(max(int(ids_of.max(initial=0)), max(bodies)) + 1, -1, np.int64)
        slot[bodies] = np.arange(len(bodies))
        return slot[ids_of]

    def sides_per_body(self, n):
        """How many rows each body id below n is a side of (n at least every id + 1), kept until
        the rows change."""
        if self._per_body is None or len(self._per_body) != n:
            self._per_body = np.bincount(self.sides().ravel(), minlength=n)
        return self._per_body

    def rows_of(self, body):
        """[(row, side: 0 for a, 1 for b)] of a body's contacts at the last read, in YADE's order
        (of the tracked bodies' sides, from the scalar read; of every side, from the numpy read:
        asked for tracked bodies only, they are the same)."""
        if isinstance(self.by_body, dict):
            return self.by_body.get(body, ())
        if self.by_body is None:
            sides = np.column_stack((self.a, self.b)).ravel()
            order = np.argsort(sides, kind="stable")
            self.by_body = (sides[order], order)
        sorted_ids, order = self.by_body
        lo, hi = np.searchsorted(sorted_ids, [body, body + 1])
        return [divmod(int(s), 2) for s in order[lo:hi]]

    def to_dict(self):
        return {"fields": list(FIELDS),
                "rows": [[a, b, *v] for a, b, v in zip(self.a.tolist(), self.b.tolist(),
                                                      self.data.T.tolist())]}

    def restore(self, data):
        """The rows of a saved scene, without YADE's objects until the next read finds them. A
        contact that had separated at its last read (overlap < 0) is left out: the law erases
        such an interaction, and the run this continues counted its next touch from zero;
        YADE's saved scene may still hold the interaction."""
        if data["fields"] != list(FIELDS):
            raise ValueError("saved contacts have other fields than this yadebreak's")
        rows = [r for r in data["rows"] if r[2] >= 0.0]
        values = np.array([r[2:] for r in rows], float).reshape(len(rows), len(FIELDS))
        self.set(np.array([r[0] for r in rows], np.int64),
                 np.array([r[1] for r in rows], np.int64), values.T.copy(),
                 [None] * len(rows), [None] * len(rows), incomplete=bool(rows))


def take(values, indices):
    """[values[k] for k in indices], in C (a cloud's table keeps thousands of rows)."""
    if len(indices) < 2:
        return [values[k] for k in indices]
    return list(itemgetter(*indices)(values))


class RowPairs:
    """The rows' pairs as (smaller id, larger id), made once per read when asked: as pair_codes
    and as tuples, and which of them are in a set of pairs."""

    def __init__(self, a, b):
        self.lo, self.hi = np.minimum(a, b), np.maximum(a, b)
        self._codes = self._tuples = self._rows = None

    def __len__(self):
        return len(self.lo)

    def among(self, pairs, within=None):
        """Which rows are pairs of the set `pairs`: each row looked up when the set is the larger
        (the zeroed pairs of many fragments), else a sorted search over the set's codes. With
        `within` (a mask of rows holding every row of the set), only those rows are looked up."""
        n = len(self.lo)
        if not pairs:
            return np.zeros(n, bool)
        if within is not None:
            rows = within.nonzero()[0]
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

    def rows_of(self, pairs):
        """[(row, pair)] of the pairs of `pairs` that are rows (each pair is one row at most): a
        look-up per pair, for the few pairs the zeroing changes between two reads."""
        if self._rows is None:
            self._rows = dict(zip(self._tuple_list(), range(len(self.lo))))
        get = self._rows.get
        return [(k, key) for key, k in zip(pairs, map(get, pairs)) if k is not None]

    def _tuple_list(self):
        if self._tuples is None:
            self._tuples = list(zip(self.lo.tolist(), self.hi.tolist()))
        return self._tuples
