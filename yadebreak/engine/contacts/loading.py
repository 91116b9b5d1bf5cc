"""What a read tells the judge: each tracked body's counted energy, its strongest contact, and
whether any of its contacts still worked."""
from __future__ import annotations

from itertools import repeat
from typing import NamedTuple

import numpy as np

from yadebreak.engine.contacts.table import SHARE_A, SHARE_B


class Strongest(NamedTuple):
    """A body's most energetic contact at a read."""
    share: float          # the body's share of the contact's counted work (J)
    normal: object        # the contact normal (YADE's Vector3, or a 3-sequence), from a to b
    sign: float           # +1.0 if the body is the contact's a, -1.0 if b: sign * normal points
    #                       from the body to its partner
    other: int            # the partner's body id (-1: none)


def _places(ids, bodies):
    """Where each of `bodies` (int64) is in the sorted, non-empty `ids`, and whether it is
    there."""
    at = np.minimum(np.searchsorted(ids, bodies), len(ids) - 1)
    return at, ids[at] == bodies


class StrongestContacts:
    """body -> its Strongest contact at a read; the normal is fetched from YADE only for the
    bodies asked for. A numpy read gives them as arrays (`ranked`: ids in order, shares, rows,
    signs, partners), looked up body by body only when asked (a breakage): most reads ask only
    for the partners of the bodies whose event grew, all at once (partners)."""

    def __init__(self, found=None, geoms=None, ranked=None):
        self._found = found if found is not None or ranked is not None else {}
        self._ranked = ranked         # (ids, share, row, sign, other) arrays, ids sorted
        self._geoms = geoms
        self._made = {}

    def __setitem__(self, body, value):
        self._made[body] = value

    def _by_body(self):
        """body -> (share, row, sign, other)."""
        if self._found is None:
            self._found = dict(zip(self._ranked[0].tolist(),
                                   zip(*(column.tolist() for column in self._ranked[1:]))))
        return self._found

    def partner(self, body):
        """The partner's id of a body's strongest contact (-1: none), without YADE's normal."""
        made = self._made.get(body)
        if made is not None:
            return made.other
        found = self._by_body().get(body)
        return -1 if found is None else found[3]

    def partners(self, bodies):
        """partner() of each of `bodies` (an int64 array), as a list."""
        if self._ranked is None or self._made:
            return [self.partner(b) for b in bodies.tolist()]
        ids, other = self._ranked[0], self._ranked[4]
        if not len(ids):
            return [-1] * len(bodies)
        at, found = _places(ids, bodies)
        return np.where(found, other[at], -1).tolist()

    def row(self, body):
        """(row, share column) of a body's strongest contact in the read's table (the column of
        the body's share, Eq. 4), None if the read did not rank it."""
        found = self._by_body().get(body)
        if found is None:
            return None
        return found[1], (SHARE_A if found[2] > 0.0 else SHARE_B)

    def get(self, body, default=None):
        made = self._made.get(body)
        if made is None:
            found = self._by_body().get(body)
            if found is None:
                return default
            share, row, sign, other = found
            made = self._made[body] = Strongest(share, self._geoms[row].normal, sign, other)
        return made


class Loading:
    """The bodies' loading found by one read. A numpy read gives the energies as arrays (`ids`
    sorted, `sums`), made a dict only when asked (`energy`)."""

    __slots__ = ("_energy", "ids", "sums", "strongest", "grew")

    def __init__(self, energy=None, strongest=None, grew=None, ids=None, sums=None):
        self._energy = energy if energy is not None or ids is not None else {}
        self.ids, self.sums = ids, sums
        self.strongest = strongest if strongest is not None else StrongestContacts()
        self.grew = grew if grew is not None else set()     # tracked bodies with a contact that
        #                                                       worked since the last read

    @property
    def energy(self):
        """body -> Ek' (J) counted now."""
        if self._energy is None:
            self._energy = dict(zip(self.ids.tolist(), self.sums.tolist()))
        return self._energy

    def energies(self, bodies):
        """Ek' (J) of each of `bodies` (an int64 array; 0.0 for a body without counted
        energy)."""
        if self.ids is None:
            n = len(bodies)
            return np.fromiter(map(self._energy.get, bodies.tolist(), repeat(0.0, n)), float, n)
        if not len(self.ids):
            return np.zeros(len(bodies))
        at, found = _places(self.ids, bodies)
        return np.where(found, self.sums[at], 0.0)
