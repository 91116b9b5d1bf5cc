"""What a read tells the judge: each tracked body's counted energy, its strongest contact, and
whether any of its contacts still worked."""
from __future__ import annotations

from typing import NamedTuple

from yadebreak.engine.contacts.table import SHARE_A, SHARE_B


class Strongest(NamedTuple):
    """A body's most energetic contact at a read."""
    share: float          # the body's share of the contact's counted work (J)
    normal: object        # the contact normal (YADE's Vector3, or a 3-sequence), from a to b
    sign: float           # +1.0 if the body is the contact's a, -1.0 if b: sign * normal points
    #                       from the body to its partner
    other: int            # the partner's body id (-1: none)


class StrongestContacts:
    """body -> its Strongest contact at a read; the normal is fetched from YADE only for the
    bodies asked for."""

    def __init__(self, found=None, geoms=None):
        self._found = found or {}     # body -> (share, row, sign, other)
        self._geoms = geoms
        self._made = {}

    def __setitem__(self, body, value):
        self._made[body] = value

    def partner(self, body):
        """The partner's id of a body's strongest contact (-1: none), without YADE's normal."""
        made = self._made.get(body)
        if made is not None:
            return made.other
        found = self._found.get(body)
        return -1 if found is None else found[3]

    def row(self, body):
        """(row, share column) of a body's strongest contact in the read's table (the column of
        the body's share, Eq. 4), None if the read did not rank it."""
        found = self._found.get(body)
        if found is None:
            return None
        return found[1], (SHARE_A if found[2] > 0.0 else SHARE_B)

    def get(self, body, default=None):
        made = self._made.get(body)
        if made is None:
            found = self._found.get(body)
            if found is None:
                return default
            share, row, sign, other = found
            made = self._made[body] = Strongest(share, self._geoms[row].normal, sign, other)
        return made


class Loading:
    """The bodies' loading found by one read."""

    __slots__ = ("energy", "strongest", "grew")

    def __init__(self, energy=None, strongest=None, grew=None):
        self.energy = energy if energy is not None else {}   # body -> Ek' (J) counted now
        self.strongest = strongest if strongest is not None else StrongestContacts()
        self.grew = grew if grew is not None else set()     # tracked bodies with a contact that
        #                                                       worked since the last read
