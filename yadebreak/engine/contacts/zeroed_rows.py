"""Which rows of the contact table are zeroed pairs, and which of those sleep (slack, not read),
kept from read to read along the rows: a fragment cloud holds hundreds to thousands of zeroed
pairs, of which the zeroing changes a few between two reads, so looking every row up again
each read (about 0.1 us a row and set) would cost more than the read of the pairs awake."""
from __future__ import annotations

import numpy as np


class ZeroedRows:
    """Two masks over the rows of one RowPairs: `zeroed` (the pair's kno varies) and `asleep`
    (a zeroed pair the zeroing does not visit now: slack, kno 0, doing no work)."""

    def __init__(self):
        self.pairs = None                     # the RowPairs the masks describe
        self.zeroed = self.asleep = np.zeros(0, bool)

    def update(self, pairs, zeroed, asleep, changed):
        """The masks for the rows of `pairs`: the last ones with the pairs `changed` since
        looked up again when they describe the same rows and `changed` is known (a set of
        (smaller id, larger id)), else every row looked up. Returns (zeroed, asleep)."""
        if self.pairs is pairs and changed is not None:
            for k, key in pairs.rows_of(changed):
                self.zeroed[k] = key in zeroed
                self.asleep[k] = key in asleep
        else:
            n = len(pairs)
            self.zeroed = pairs.among(zeroed) if zeroed else np.zeros(n, bool)
            self.asleep = (pairs.among(asleep, within=self.zeroed) if asleep
                           else np.zeros(n, bool))
            self.pairs = pairs
        return self.zeroed, self.asleep

    def keep(self, rows):
        """The table kept only `rows` (indices); `pairs` is set once the rows are laid out."""
        self.zeroed, self.asleep = self.zeroed[rows], self.asleep[rows]

    def append(self, new, zeroed, asleep):
        """Rows of the pairs `new` ((smaller id, larger id) each) appended."""
        z = np.fromiter(map(zeroed.__contains__, new), bool, len(new))
        s = np.fromiter(map(asleep.__contains__, new), bool, len(new)) & z
        self.zeroed = np.concatenate((self.zeroed, z))
        self.asleep = np.concatenate((self.asleep, s))

    def forget(self):
        """The rows changed otherwise (a restore): look every row up at the next read."""
        self.pairs = None
