"""When the engine reads: the read schedules of read_period as triggers (parts/triggers.py) of
the engine's part: every k steps (EveryK), "auto" (RayleighReads) or "fast" (LoadingReads), and
what "fast" follows of the tracked bodies (SmallestBreakable, Reach)."""
from __future__ import annotations

import heapq

from yadebreak.model import placement
from yadebreak.adapter.yade_api import O, utils
from yadebreak.engine.parts.triggers import Trigger

#: read_period="fast" never waits longer than this many steps between reads.
FAST_MAX_PERIOD = 200
#: "fast" reads: the speed of every body is looked at every this many reads (a pass over all the
#: bodies in Python, about 1 us each: 1/64 of it per read)
SCAN_EVERY = 64


class SmallestBreakable:
    """(radius, id) of the smallest breakable body: a heap cleaned lazily of bodies that broke."""

    def __init__(self):
        self.heap = []

    def push(self, radius, bid):
        heapq.heappush(self.heap, (radius, bid))

    def rebuild(self, pairs):
        self.heap = list(pairs)
        heapq.heapify(self.heap)

    def get(self, still_breakable):
        heap = self.heap
        while heap and not still_breakable(heap[0][1]):
            heapq.heappop(heap)
        return heap[0] if heap else None


class Reach:
    """For "fast" reads: over every tracked body (breakable ones, and unbreakable fragments whose
    first stressing past their fracture energy sets their t10'), the least time in which a contact
    that begins between reads, closing at 1 m/s, brings one of them `tolerance` of its own present
    fracture energy (placement.hertz_onset_time; it scales as 1 / speed), and the least Hertz
    loading time at 1 m/s (~ speed^-1/5). Two heaps cleaned lazily: of bodies no longer tracked,
    and of onset times a damage made stale (`set_onsets`); built anew from the body table every
    SCAN_EVERY reads (`rebuild`), so that a fracture energy set by hand is followed too."""

    def __init__(self, tolerance):
        self.tolerance = tolerance
        self.onset = []                       # (time at 1 m/s, id)
        self.loading = []                     # (time at 1 m/s, id)
        self.current = {}                     # id -> its onset time now

    def add(self, bid, radius, fracture_energy, material):
        """A tracked body of `radius` (m) and `fracture_energy` (J/kg); `material` its YADE
        material (density, young, poisson)."""
        heapq.heappush(self.loading, (float(placement.hertz_loading_time(
            radius, material.density, material.young, material.poisson, 1.0)), bid))
        onset = float(placement.hertz_onset_time(radius, material.density, material.young,
                                                 material.poisson, 1.0,
                                                 self.tolerance * fracture_energy))
        self.set_onsets([bid], [onset])

    def set_onsets(self, ids, onsets):
        """The onset times (s, at 1 m/s) of the bodies `ids` are now `onsets` (lists): new
        bodies, or a damage lowered their fracture energies (stale times are cleaned lazily)."""
        current, heap = self.current, self.onset
        for bid, onset in zip(ids, onsets):
            current[bid] = onset
            heapq.heappush(heap, (onset, bid))

    def get(self, tracked):
        """(onset time, loading time) at 1 m/s (s) over the bodies in `tracked`, None if none."""
        onset, loading, current = self.onset, self.loading, self.current
        while onset and (onset[0][1] not in tracked or current.get(onset[0][1]) != onset[0][0]):
            t, bid = heapq.heappop(onset)
            if bid not in tracked:
                current.pop(bid, None)
        while loading and loading[0][1] not in tracked:
            heapq.heappop(loading)
        return (onset[0][0], loading[0][0]) if onset and loading else None

    def rebuild(self, ids, onset, loading):
        """Every tracked body's times at 1 m/s: `ids`, `onset`, `loading` (aligned lists)."""
        self.current = dict(zip(ids, onset))
        self.onset = list(zip(onset, ids))
        self.loading = list(zip(loading, ids))
        heapq.heapify(self.onset)
        heapq.heapify(self.loading)


class ReadSchedule(Trigger):
    """When the engine reads (its part's trigger): `period` steps after a read, set by the read
    (after_read). The three schedules of read_period are its subclasses (read_schedule makes
    the one the options ask for)."""

    mode = ""

    def __init__(self, options, period=1):
        self.options = options                # config.Reading
        self.period = period

    def after_read(self, limits):
        """A read happened; `limits` (a list or None) are the steps the loaded bodies allow
        ("fast")."""

    def next_step(self, now):
        return now + self.period

    def remedies(self):
        """What makes reads closer, best first, for the warning that a read came late: (option
        of attach(), advice with {} where the option's name goes)."""
        closer = [("time_step_fraction", "reduce {}")]
        if self.period == 1:
            return closer
        if self.mode == "every":
            return [("read_period", "reduce {}")] + closer
        own = "fast_fraction" if self.mode == "fast" else "read_fraction"
        return [(own, "reduce {}"), ("read_period", "read every step ({} 1)")] + closer

    def saw_speed(self, speed):
        """Fresh fragments move at up to `speed` (m/s): "fast" reads count it."""

    def to_list(self):
        """What the schedule saves besides its period (the scene's state)."""
        return [None, 0]

    def restore(self, saved):
        pass


class EveryK(ReadSchedule):
    """A read every k steps (read_period an integer; 1: every step)."""

    mode = "every"


class RayleighReads(ReadSchedule):
    """read_period "auto": k dt <= read_fraction of the Rayleigh time of the smallest breakable
    body. `smallest`: () -> (radius, id) or None."""

    mode = "auto"

    def __init__(self, options, smallest):
        super().__init__(options)
        self.smallest = smallest
        self._key = None

    def after_read(self, limits):
        smallest = self.smallest()
        key = (smallest, O.dt)
        if key == self._key:                   # nothing changed: keep k (no numpy per step)
            return
        self._key = key
        k = 1
        if smallest is not None:
            radius, bid = smallest
            mat = O.bodies[bid].material
            tr = float(placement.rayleigh_time(radius, mat.density, mat.young, mat.poisson))
            k = max(1, int(self.options.read_fraction * tr / O.dt))
        self.period = k


class LoadingReads(ReadSchedule):
    """read_period "fast": as often as the loading requires (after_read). `reach`: (rebuild) ->
    Reach.get's (onset, loading) or None."""

    mode = "fast"

    def __init__(self, options, reach):
        super().__init__(options)
        self.reach = reach
        self.scanned = None                   # largest speed at the last scan (m/s)
        self.reads_since_scan = 0

    def after_read(self, limits):
        """k, the smallest of
        - what every loaded body allows (steps_allowed), so that no body's energy passes its
          fracture energy by more than fast_tolerance of it between reads;
        - the time in which a contact that begins between reads, closing at twice the largest
          speed in the scene (the most energetic body's at every read, every body's every
          SCAN_EVERY reads, fresh fragments' when they appear), brings any tracked body (Reach:
          breakable ones and unbreakable fragments alike) fast_tolerance of its own fracture
          energy: the Hertz onset bound (placement.hertz_onset_time), the most a fresh contact can
          bring in that time; it grows as time^2.5, so a read late by a factor 4.4 (or a partner
          4.4 times faster than the bound) still keeps the rise below judging.LATE_JUMP (the
          warning's 80 %) at the default fast_tolerance (2 %);
        - fast_fraction of the shortest Hertz loading time of a tracked body at that closing
          speed, so that an impact that begins between reads is read several times while it
          loads;
        - FAST_MAX_PERIOD steps."""
        self.reads_since_scan += 1
        scan = self.reads_since_scan >= SCAN_EVERY or self.scanned is None
        reach = self.reach(scan)
        if scan:
            self.reads_since_scan = 0
        if reach is None:
            k = FAST_MAX_PERIOD
        else:
            if scan:
                self.scanned = largest_speed()
            closing = max(2.0 * max(self.scanned, most_energetic_speed()), 1e-6)
            onset_1, loading_1 = reach
            wait = min(self.options.fast_fraction * loading_1 * closing ** -0.2,
                       onset_1 / closing)
            k = min(FAST_MAX_PERIOD, int(wait / O.dt))
        if limits:
            k = min(k, int(min(limits)))
        self.period = max(1, k)

    def saw_speed(self, speed):
        if self.scanned is not None:
            self.scanned = max(self.scanned, speed)

    def to_list(self):
        return [self.scanned, self.reads_since_scan]

    def restore(self, saved):
        self.scanned, self.reads_since_scan = saved


def read_schedule(options, smallest, reach, every_step=False):
    """The read schedule (a trigger) that `options` (config.Reading) ask for: its read_period, an
    integer k or "every_step" (EveryK), "auto" (RayleighReads) or "fast" (LoadingReads; `reach`
    as it takes). `every_step`: every step whatever the option (a contact law that reads every
    step: contacts/laws.py)."""
    period = options.read_period
    if every_step:
        return EveryK(options)
    if period == "auto":
        return RayleighReads(options, smallest)
    if period == "fast":
        return LoadingReads(options, reach)
    return EveryK(options, period if isinstance(period, int) else 1)


def most_energetic_speed():
    """Speed (m/s) of the dynamic body with the most kinetic energy (YADE finds it in C++), 0 at
    rest."""
    _, top = utils.kineticEnergy(True)
    return O.bodies[top].state.vel.norm() if top >= 0 else 0.0


def largest_speed():
    """The largest speed (m/s) of a dynamic body: a pass over every body in Python (about 1 us
    each), made every SCAN_EVERY reads only."""
    return max((b.state.vel.norm() for b in O.bodies if b is not None and b.dynamic), default=0.0)
