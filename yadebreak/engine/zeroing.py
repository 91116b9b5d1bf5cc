"""Zeroed artificial overlaps of fresh fragments (the paper's Section 2.4; see docs/model.md).

YADE's Hertz-Mindlin law has no reference overlap, so before each force evaluation (a PyRunner
ahead of the InteractionLoop) the stiffnesses of every zeroed pair are scaled,
kno = kno0 ((d - d0) / d)^1.5 and kso = kso0 ((d - d0) / d)^0.5, so that only overlap beyond the
artificial d0 produces force; d0 shrinks as the pair opens and the pair is dropped when it
separates. The engine sleeps when there are no zeroed pairs.

A pair inside its artificial overlap ("slack": no force) and opening needs no visit until its
overlap may have shrunk by `tolerance` of itself: it sleeps that many steps, judged from its
opening rate (at most MAX_SLEEP), and the work per step is bounded by the pairs awake. The only
error is where a pair that turns round while asleep closes again without force: it wakes with its
zero raised to the overlap it then has, so that it pushes from there on and never with an overlap
no force resisted (that would create energy); it pushes at most `tolerance` of its overlap later
than with a visit every step (tolerance 0), and never harder.

While every pair sleeps, the runner sleeps too, until the first pair is due: YADE does the
waiting, where a call of the runner would cost more than its visits (in a cascade's tail, tens
of thousands of steps with no pair awake: about 20 us a step).
"""
from __future__ import annotations

from yadebreak.adapter.yade_api import O, Vector3, utils, wrapper
from yadebreak.engine.parts import protocol

#: a slack pair sleeps at most this many steps
MAX_SLEEP = 50
_NO_FORCE = Vector3(0.0, 0.0, 0.0)


class ZeroedOverlap:
    """One pair's artificial overlap (m), its stiffnesses before scaling, its overlap (m) at the
    step of its last visit (-1: not visited yet), and the YADE objects a visit reads (None: not
    found yet)."""

    __slots__ = ("artificial", "kno0", "kso0", "seen_overlap", "seen_iter", "objects")

    def __init__(self, artificial, kno0, kso0):
        self.artificial, self.kno0, self.kso0 = artificial, kno0, kso0
        self.seen_overlap, self.seen_iter = 0.0, -1
        self.objects = None

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
        self.awake = {}                          # pairs visited at every step -> their
        #                                          ZeroedOverlap (a visit looks nothing up)
        self.asleep = set()                      # slack pairs not visited until they wake
        self._wake_at = {}                       # step -> pairs that wake then
        self._loaded_depth = {}                  # wall, facet pair -> overlap (m) when saved
        self._changes = set()                    # pairs zeroed, dropped, asleep or woken
        #                                          since take_changes() (None: not kept)

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
        self._changed(key)
        self.pairs[key] = zero
        self.awake[key] = zero
        for i in key:
            self.by_body.setdefault(i, set()).add(key)

    def drop_body(self, body_id):
        for key in list(self.by_body.get(body_id, ())):
            self._drop(key)

    def _drop(self, key):
        self._changed(key)
        self.pairs.pop(key, None)
        self.awake.pop(key, None)
        self.asleep.discard(key)                 # its entry in _wake_at is skipped when due
        for i in key:
            pairs = self.by_body.get(i)
            if pairs is not None:
                pairs.discard(key)
                if not pairs:
                    del self.by_body[i]

    def take_changes(self):
        """The pairs that were zeroed, dropped, fell asleep or woke since the last call (None:
        not known, after forget_changes)."""
        changes, self._changes = self._changes, set()
        return changes

    def forget_changes(self):
        """Stop keeping the changes until the next take_changes (no one asks meanwhile)."""
        self._changes = None

    def _changed(self, key):
        if self._changes is not None:
            self._changes.add(key)

    def artificial(self, id_a, id_b):
        """The zeroed overlap (m) of a pair, 0 if none."""
        z = self.pairs.get((min(id_a, id_b), max(id_a, id_b)))
        return z.artificial if z else 0.0

    def wake(self):
        """Pairs were zeroed: visit every step from the next on."""
        if self.pairs:
            protocol.wake(self.engine_label)

    def next_step(self, now):
        """The step of the next visit (the zeroing part's trigger, asked after a visit at `now`
        and when woken): the next step while a pair is awake; with every pair asleep, when the
        first wakes (entries of pairs dropped meanwhile may make it earlier: a visit that finds
        nothing to do)."""
        if not self.awake and self._wake_at:
            return now + max(1, min(self._wake_at) - now)
        return now + 1

    def apply(self):
        """Before the InteractionLoop: scale kno, kso of every zeroed pair awake (sphere pairs
        and spheres on walls from this step's positions, facets from the last step's overlap)."""
        if not self.pairs:
            protocol.sleep(self.engine_label)
            return
        now = O.iter
        woken = self._wake(now)
        tolerance = self.tolerance
        done, sleep = [], []
        for key, z in self.awake.items():
            c = z.objects
            if c is None:
                c = z.objects = self._objects(key)
                if c is None:
                    done.append(key)
                    continue
            state_a, state_b, radius_sum, phys, geom, through = c
            if geom is None:
                d = radius_sum - (state_a.pos - state_b.pos).norm()
            elif geom.__class__ is tuple:        # a sphere on a wall: (axis, sense)
                axis, sense = geom
                gap = state_a.pos[axis] - state_b.pos[axis]
                d = radius_sum - (abs(gap) if sense == 0 else sense * gap)
            else:
                d = geom.penetrationDepth
                if d != d:                       # NaN: O.load does not keep it (see to_list)
                    d = self._loaded_depth.get(key, z.seen_overlap)
            if d <= 0.0:
                done.append(key)
                continue
            if woken and key in woken and d > z.artificial:
                z.artificial = d                 # closed while asleep: pushes from here on
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
                if d < through:
                    phys.kso = z.kso0 * ratio ** 0.5
                else:
                    # the contact point lies past the smaller sphere's centre (a fine fragment
                    # inside a larger sibling): the law's shear lever would be negative and
                    # pump spin into it, so the pair pushes without friction
                    phys.kso = 0.0
                    phys.shearForce = _NO_FORCE
            z.seen_overlap, z.seen_iter = d, now
        self._loaded_depth.clear()
        for key in done:
            self._drop(key)
        for key, when in sleep:
            self._changed(key)
            del self.awake[key]
            self.asleep.add(key)
            self._wake_at.setdefault(when, []).append(key)

    def _wake(self, now):
        """The pairs due now are awake again (pairs dropped while asleep are gone); returns them
        (None if none)."""
        woken = None
        for when in [w for w in self._wake_at if w <= now]:
            for key in self._wake_at.pop(when):
                if key in self.asleep:
                    self._changed(key)
                    self.asleep.discard(key)
                    self.awake[key] = self.pairs[key]
                    woken = woken or set()
                    woken.add(key)
        return woken

    def _objects(self, key):
        ba, bb = O.bodies[key[0]], O.bodies[key[1]]
        if ba is None or bb is None or not O.interactions.has(key[0], key[1]):
            return None
        inter = O.interactions[key[0], key[1]]
        if not inter.isReal:
            return None
        spheres = isinstance(ba.shape, wrapper.Sphere) and isinstance(bb.shape, wrapper.Sphere)
        if spheres:
            c = (ba.state, bb.state, ba.shape.radius + bb.shape.radius, inter.phys, None,
                 2.0 * min(ba.shape.radius, bb.shape.radius))
        elif isinstance(bb.shape, wrapper.Wall) or isinstance(ba.shape, wrapper.Wall):
            # this step's overlap from the positions, as Ig2_Wall_Sphere_ScGeom will find it
            # (the law's last overlap lags a step: a pair opening would push for one step more)
            sphere, wall = (ba, bb) if isinstance(bb.shape, wrapper.Wall) else (bb, ba)
            c = (sphere.state, wall.state, sphere.shape.radius, inter.phys,
                 (wall.shape.axis, wall.shape.sense), 2.0 * sphere.shape.radius)
        else:                                    # facets: the law's last overlap
            sphere = ba if isinstance(ba.shape, wrapper.Sphere) else bb
            c = (ba.state, bb.state, 0.0, inter.phys, inter.geom, 2.0 * sphere.shape.radius)
        return c

    def to_list(self):
        """Every pair with its last visit and, if asleep, the step it wakes at (-1: awake): a
        restored scene goes on exactly as the saved one would have."""
        wake_at = {key: when for when, keys in self._wake_at.items() for key in keys
                   if key in self.asleep}
        return [[a, b, *z.saved(), z.seen_overlap, z.seen_iter, wake_at.get((a, b), -1),
                 self._depth((a, b))] for (a, b), z in self.pairs.items()]

    def _depth(self, key):
        """The overlap (m) of a wall or facet pair as YADE last computed it (None for spheres,
        whose overlap comes from their positions): O.save does not keep ScGeom.penetrationDepth,
        which apply() reads before the InteractionLoop has computed it again."""
        if any(O.bodies[i] is None for i in key) or not O.interactions.has(*key):
            return None                        # (has() aborts YADE for an erased body)
        inter = O.interactions[key]
        geom = inter.geom
        if geom is None or all(isinstance(O.bodies[i].shape, wrapper.Sphere) for i in key):
            return None
        return geom.penetrationDepth

    def restore(self, rows):
        for a, b, *values in rows:
            self._register((a, b), ZeroedOverlap(*values[:3]))
            if len(values) > 3:                  # (saved before the visits were: all awake)
                z = self.pairs[(a, b)]
                z.seen_overlap, z.seen_iter, wake = values[3], int(values[4]), int(values[5])
                if len(values) > 6 and values[6] is not None:
                    self._loaded_depth[(a, b)] = values[6]
                if wake >= 0:
                    del self.awake[(a, b)]
                    self.asleep.add((a, b))
                    self._wake_at.setdefault(wake, []).append((a, b))
