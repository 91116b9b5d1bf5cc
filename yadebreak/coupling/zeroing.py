"""Zeroed artificial overlaps of fresh fragments (the paper's Section 2.4; see docs/model.md).

YADE's Hertz-Mindlin law has no reference overlap, so before each force evaluation (a PyRunner
ahead of the InteractionLoop) the stiffnesses of every zeroed pair are scaled,
kno = kno0 ((d - d0) / d)^1.5 and kso = kso0 ((d - d0) / d)^0.5, so that only overlap beyond the
artificial d0 produces force; d0 shrinks as the pair opens and the pair is dropped when it
separates. The engine sleeps when there are no zeroed pairs.

A pair inside its artificial overlap ("slack": no force) and opening needs no visit until its
overlap may have shrunk by `tolerance` of itself: it sleeps that many steps, judged from its
opening rate (at most MAX_SLEEP), and the work per step is bounded by the pairs awake. The only
error is where a pair that turns round while asleep starts to push again: at most `tolerance` of
its overlap later than with a visit every step (tolerance 0).
"""
from __future__ import annotations

from ._yade import O, find_engine, utils, wrapper

#: a slack pair sleeps at most this many steps
MAX_SLEEP = 50


class ZeroedOverlap:
    """One pair's artificial overlap (m), its stiffnesses before scaling, and its overlap (m) at
    the step of its last visit (-1: not visited yet)."""

    __slots__ = ("artificial", "kno0", "kso0", "seen_overlap", "seen_iter")

    def __init__(self, artificial, kno0, kso0):
        self.artificial, self.kno0, self.kso0 = artificial, kno0, kso0
        self.seen_overlap, self.seen_iter = 0.0, -1

    def saved(self):
        return [self.artificial, self.kno0, self.kso0]


class OverlapZeroing:
    """The zeroed pairs of a scene, indexed by pair and by body."""

    def __init__(self, local_damping, engine_label, tolerance=0.0):
        self.local_damping = local_damping       # share of an artificial overlap released as force
        self.engine_label = engine_label
        self.tolerance = tolerance               # see the module's docstring
        self.pairs = {}                          # (id_a, id_b), id_a < id_b -> ZeroedOverlap
        self.by_body = {}                        # body -> its zeroed pairs
        self.awake = set()                       # pairs visited at every step
        self.asleep = set()                      # slack pairs not visited until they wake
        self._wake_at = {}                       # step -> pairs that wake then
        self._cache = {}                         # pair -> YADE objects read every step

    def __bool__(self):
        return bool(self.pairs)

    def __contains__(self, key):
        return key in self.pairs

    def items(self):
        return self.pairs.items()

    def zero_pair(self, id_a, id_b, artificial, created):
        """Register an artificial overlap (m) of a new pair (its interaction made now unless
        `created`); (1 - local_damping) of it is zeroed, the rest is released as real force."""
        inter = O.interactions[id_a, id_b] if created else utils.createInteraction(id_a, id_b)
        ph = inter.phys
        self._register((min(id_a, id_b), max(id_a, id_b)),
                       ZeroedOverlap((1.0 - self.local_damping) * artificial, ph.kno, ph.kso))

    def _register(self, key, zero):
        self.pairs[key] = zero
        self.awake.add(key)
        for i in key:
            self.by_body.setdefault(i, set()).add(key)

    def drop_body(self, body_id):
        for key in list(self.by_body.get(body_id, ())):
            self._drop(key)

    def _drop(self, key):
        self.pairs.pop(key, None)
        self._cache.pop(key, None)
        self.awake.discard(key)
        self.asleep.discard(key)                 # its entry in _wake_at is skipped when due
        for i in key:
            pairs = self.by_body.get(i)
            if pairs is not None:
                pairs.discard(key)
                if not pairs:
                    del self.by_body[i]

    def artificial(self, id_a, id_b):
        """The zeroed overlap (m) of a pair, 0 if none."""
        z = self.pairs.get((min(id_a, id_b), max(id_a, id_b)))
        return z.artificial if z else 0.0

    def wake(self):
        if self.pairs:
            find_engine(self.engine_label).dead = False

    def apply(self):
        """Before the InteractionLoop: scale kno, kso of every zeroed pair awake (sphere pairs
        from this step's positions, walls and facets from the last step's overlap)."""
        if not self.pairs:
            find_engine(self.engine_label).dead = True
            return
        now = O.iter
        self._wake(now)
        cache, pairs, tolerance = self._cache, self.pairs, self.tolerance
        done, sleep = [], []
        for key in self.awake:
            z = pairs[key]
            c = cache.get(key)
            if c is None:
                c = self._objects(key)
                if c is None:
                    done.append(key)
                    continue
            state_a, state_b, radius_sum, phys, geom = c
            if geom is None:
                d = radius_sum - (state_a.pos - state_b.pos).norm()
            else:
                d = geom.penetrationDepth
            if d <= 0.0:
                done.append(key)
                continue
            if d <= z.artificial:
                if tolerance and z.seen_iter >= 0 and d < z.seen_overlap:
                    # opening with no force: asleep until it may have closed `tolerance` of d
                    steps = int(tolerance * d * (now - z.seen_iter) / (z.seen_overlap - d))
                    if steps > 1:
                        sleep.append((key, now + min(steps, MAX_SLEEP)))
                z.artificial = d
                if z.kno0 != 0.0 and phys.kno != 0.0:
                    phys.kno = 0.0
                    phys.kso = 0.0
            else:
                ratio = (d - z.artificial) / d
                phys.kno = z.kno0 * ratio ** 1.5
                phys.kso = z.kso0 * ratio ** 0.5
            z.seen_overlap, z.seen_iter = d, now
        for key in done:
            self._drop(key)
        for key, when in sleep:
            self.awake.discard(key)
            self.asleep.add(key)
            self._wake_at.setdefault(when, []).append(key)

    def _wake(self, now):
        """The pairs due now are awake again (pairs dropped while asleep are gone)."""
        for when in [w for w in self._wake_at if w <= now]:
            for key in self._wake_at.pop(when):
                if key in self.asleep:
                    self.asleep.discard(key)
                    self.awake.add(key)

    def _objects(self, key):
        ba, bb = O.bodies[key[0]], O.bodies[key[1]]
        if ba is None or bb is None or not O.interactions.has(key[0], key[1]):
            return None
        inter = O.interactions[key[0], key[1]]
        if not inter.isReal:
            return None
        spheres = isinstance(ba.shape, wrapper.Sphere) and isinstance(bb.shape, wrapper.Sphere)
        c = (ba.state, bb.state, (ba.shape.radius + bb.shape.radius) if spheres else 0.0,
             inter.phys, None if spheres else inter.geom)
        self._cache[key] = c
        return c

    def to_list(self):
        return [[a, b, *z.saved()] for (a, b), z in self.pairs.items()]

    def restore(self, rows):
        for a, b, *values in rows:
            self._register((a, b), ZeroedOverlap(*values))
