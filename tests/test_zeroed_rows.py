"""ZeroedRows keeps, from read to read, which rows of the contact table are zeroed pairs and
which of those sleep, looking up only the pairs the zeroing changed: after any sequence of
changes, rows dropped and rows appended, its masks are those a lookup of every row gives."""
import numpy as np

from yadebreak.engine.contacts.table import RowPairs
from yadebreak.engine.contacts.zeroed_rows import ZeroedRows


def _full(a, b, zeroed, asleep):
    fresh = ZeroedRows()
    return fresh.update(RowPairs(a, b), zeroed, asleep, None)


def _random_rows(rng, n, bodies=60):
    """n rows of distinct pairs (YADE keeps one interaction per pair), either id first."""
    pairs = {}
    while len(pairs) < n:
        i, j = rng.choice(bodies, 2, replace=False).tolist()
        pairs.setdefault((min(i, j), max(i, j)), (i, j))
    a, b = np.array(sorted(pairs.values()), np.int64).T
    return a, b


def test_the_masks_follow_the_zeroing_and_the_rows_as_a_full_lookup_would():
    rng = np.random.default_rng(7)
    a, b = _random_rows(rng, 200)
    keys = [(min(i, j), max(i, j)) for i, j in zip(a.tolist(), b.tolist())]
    zeroed = set(keys[k] for k in rng.choice(200, 120, replace=False).tolist()) | {(900, 901)}
    asleep = set(k for k in zeroed if rng.random() < 0.6)
    rows = ZeroedRows()
    pairs = RowPairs(a, b)
    rows.update(pairs, zeroed, asleep, None)
    looked_up = 0
    for round_ in range(60):
        changed = set()
        for key in rng.choice(len(keys), 15).tolist():       # sleep, wake, zero, drop
            key = keys[key]
            what = rng.integers(4)
            if what == 0 and key in zeroed:
                asleep.add(key)
            elif what == 1:
                asleep.discard(key)
            elif what == 2:
                zeroed.add(key)
            else:
                zeroed.discard(key)
                asleep.discard(key)
            changed.add(key)
        if round_ % 5 == 4:                                  # rows dropped, then appended
            keep = np.sort(rng.choice(len(a), len(a) - 10, replace=False))
            rows.keep(keep)
            a, b = a[keep], b[keep]
            new_a, new_b = _random_rows(rng, 5, bodies=40)
            new_a, new_b = new_a + 100, new_b + 100           # pairs the rows did not hold
            rows.append([(min(i, j), max(i, j)) for i, j in zip(new_a.tolist(), new_b.tolist())],
                        zeroed, asleep)
            a, b = np.concatenate((a, new_a)), np.concatenate((b, new_b))
            pairs = rows.pairs = RowPairs(a, b)
            keys = [(min(i, j), max(i, j)) for i, j in zip(a.tolist(), b.tolist())]
        got = rows.update(pairs, zeroed, asleep, changed)
        want = _full(a, b, zeroed, asleep)
        assert np.array_equal(got[0], want[0]) and np.array_equal(got[1], want[1])
        assert rows.pairs is pairs                          # it followed, did not look all up
        looked_up += int(want[0].sum())
    assert looked_up > 1000 and 0 < int(got[1].sum()) < int(got[0].sum())


def test_unknown_changes_or_other_rows_are_looked_up_in_full():
    rng = np.random.default_rng(3)
    a, b = _random_rows(rng, 50)
    keys = {(min(i, j), max(i, j)) for i, j in zip(a.tolist(), b.tolist())}
    zeroed, asleep = set(list(keys)[:30]), set(list(keys)[:10])
    rows = ZeroedRows()
    rows.update(RowPairs(a, b), zeroed, asleep, set())       # first: a full lookup
    zeroed -= set(list(keys)[:5])
    asleep -= set(list(keys)[:5])
    for pairs, changed in ((RowPairs(a, b), set()), (rows.pairs, None)):
        got = rows.update(pairs, zeroed, asleep, changed)
        want = _full(a, b, zeroed, asleep)
        assert np.array_equal(got[0], want[0]) and np.array_equal(got[1], want[1])
    rows.forget()
    assert rows.pairs is None
