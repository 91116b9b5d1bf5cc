"""When to read, and the time step: the read schedule (every k steps, "auto" or "fast"), the time
step that follows the finest sphere, and the damping of fresh fragments."""
from __future__ import annotations

import heapq
import math

from yadebreak.model import placement
from yadebreak.options.table import AttachError
from yadebreak.adapter.yade_api import O, utils, wrapper
from yadebreak.engine.parts import protocol

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
    and of onset times a damage made stale (`update`); built anew from the body table every
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
        self.update(bid, radius, fracture_energy, material)

    def update(self, bid, radius, fracture_energy, material):
        """The body's fracture energy changed (a damage): its onset time with it."""
        onset = float(placement.hertz_onset_time(radius, material.density, material.young,
                                                 material.poisson, 1.0,
                                                 self.tolerance * fracture_energy))
        self.current[bid] = onset
        heapq.heappush(self.onset, (onset, bid))

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


class ReadSchedule:
    """How many steps to the next read: a fixed k, "auto" (k dt <= read_fraction of the Rayleigh
    time of the smallest breakable body) or "fast" (as often as the loading requires). The
    period is the engine part's (protocol.set_period). `every_step`: read every step whatever
    the option says (polyhedra on the volumetric law: contacts/volumetric.py)."""

    def __init__(self, options, engine_label, smallest, reach=None, every_step=False):
        self.options = options                # config.Reading
        self.mode = ("every" if every_step or options.read_period not in ("auto", "fast")
                     else options.read_period)
        self.period = (options.read_period if isinstance(options.read_period, int)
                       and not every_step and self.mode == "every" else 1)   # "every_step": 1
        self.engine_label = engine_label
        self.smallest = smallest              # () -> (radius, id) or None
        self.reach = reach                    # (rebuild) -> Reach.get's (onset, loading) or None
        self.scanned = None                   # "fast": largest speed at the last scan (m/s)
        self.reads_since_scan = 0
        self._auto_key = None

    def after_read(self, limits):
        """Set the period after a read; `limits` (a list or None) are the steps the loaded
        bodies allow ("fast")."""
        if self.mode == "auto":
            self._auto()
        elif self.mode == "fast":
            self._fast(limits)

    def _auto(self):
        smallest = self.smallest()
        key = (smallest, O.dt)
        if key == self._auto_key:              # nothing changed: keep k (no numpy per step)
            return
        self._auto_key = key
        k = 1
        if smallest is not None:
            radius, bid = smallest
            mat = O.bodies[bid].material
            tr = float(placement.rayleigh_time(radius, mat.density, mat.young, mat.poisson))
            k = max(1, int(self.options.read_fraction * tr / O.dt))
        self.set_period(k)

    def _fast(self, limits):
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
        reach = self.reach(scan) if self.reach is not None else None
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
        self.set_period(max(1, k))

    def set_period(self, k):
        if k != self.period:
            self.period = k
            protocol.set_period(self.engine_label, k)

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
        """Fresh fragments move at up to `speed` (m/s): the next reads count it."""
        if self.scanned is not None:
            self.scanned = max(self.scanned, speed)

    def to_list(self):
        return [self.scanned, self.reads_since_scan]

    def restore(self, saved):
        self.scanned, self.reads_since_scan = saved


def most_energetic_speed():
    """Speed (m/s) of the dynamic body with the most kinetic energy (YADE finds it in C++), 0 at
    rest."""
    _, top = utils.kineticEnergy(True)
    return O.bodies[top].state.vel.norm() if top >= 0 else 0.0


def largest_speed():
    """The largest speed (m/s) of a dynamic body: a pass over every body in Python (about 1 us
    each), made every SCAN_EVERY reads only."""
    return max((b.state.vel.norm() for b in O.bodies if b is not None and b.dynamic), default=0.0)


def smallest_rayleigh_time():
    """Rayleigh time (s) of the smallest sphere in the scene (None if there is none): one pass
    for the smallest radius of each material, then one Rayleigh time per material."""
    smallest = {}                                  # material id -> (radius, material)
    sphere = wrapper.Sphere
    for b in O.bodies:
        if b is not None and isinstance(b.shape, sphere):
            r, mat = b.shape.radius, b.material
            if mat.id not in smallest or r < smallest[mat.id][0]:
                smallest[mat.id] = (r, mat)
    times = [float(placement.rayleigh_time(r, mat.density, mat.young, mat.poisson))
             for r, mat in smallest.values()]
    return min(times) if times else None


class TimeStep:
    """O.dt at most time_step_fraction of the Rayleigh time of the smallest sphere present; a
    smaller O.dt is kept. With time_step_fraction=None the user owns O.dt: warn when it exceeds
    20 % of that Rayleigh time (Hertz contacts go unstable near it)."""

    def __init__(self, fraction, warn):
        self.fraction = fraction
        self.warn = warn                      # warn(cause, message), once per cause

    def at_attach(self, rayleigh_time, user_dt):
        """`user_dt`: O.dt if the user set one before attach, else None."""
        if rayleigh_time is None:
            return
        if not self.fraction:
            self.check(rayleigh_time)
        elif user_dt is None or user_dt > self.fraction * rayleigh_time:
            O.dt = self.fraction * rayleigh_time

    def check(self, rayleigh_time):
        if O.dt > 0.2 * rayleigh_time:
            self.warn("dt", (
                f"O.dt = {O.dt:.3g} s is {100 * O.dt / rayleigh_time:.0f} % of the Rayleigh time "
                f"of the smallest sphere ({rayleigh_time:.3g} s): contacts may go unstable and "
                f"energies be wrong; use time_step_fraction (0.05 recommended) or lower O.dt"))

    def for_fragments(self, radius, material):
        """The time step fragments of `radius` (m) need (inf if O.dt stays the user's)."""
        tr = float(placement.rayleigh_time(radius, material.density, material.young,
                                           material.poisson))
        if self.fraction:
            return self.fraction * tr
        self.check(tr)
        return math.inf

    @staticmethod
    def lower(new_dt, moving):
        """O.dt = new_dt, keeping the leapfrog exact across the change.

        YADE's Newton takes v(n+1/2) = v(n-1/2) + a dt with the new dt; across a change the right
        increment is a (dt_old + dt_new) / 2. Without the a (dt_old - dt_new) / 2 added here, a
        body in mid-contact when a breakage shrinks dt gains energy (1.9 % measured on impacts of
        5.5 mm copper ore at 100 J/kg when dt fell 19-fold). Done for the bodies in
        tracked contacts (`moving()`, asked only when dt falls), the only ones with a large
        acceleration that yadebreak knows of."""
        old = O.dt
        if not new_dt < old:
            return
        newton = next((e for e in O.engines if isinstance(e, wrapper.NewtonIntegrator)), None)
        gravity = newton.gravity if newton is not None else None
        half = 0.5 * (old - new_dt)
        for bid in moving():
            b = O.bodies[bid]
            if b is None or not b.dynamic:
                continue
            accel = O.forces.f(bid) / b.state.mass
            if gravity is not None:
                accel = accel + gravity
            b.state.vel = b.state.vel + accel * half
        O.dt = new_dt


class FragmentDamping:
    """The paper's global damping: fragments only, from their creation, for global_damping_time
    seconds (None: as long as they exist). Each material has its strength (its file's
    global_damping, or attach's global_damping for all).

    It is YADE's Newton (Cundall) damping, switched on for fragments only through
    state.isDamped: on a damped body each component of the force (and torque) is reduced by the
    strength times its magnitude when it speeds the body up and increased likewise when it slows
    it down, i.e. a force of `strength` times the force on the body, always against the body's
    motion (the EDEM manual's "percentage of total contact force upon the particle"). It is never
    on the parent or any body that existed at attach, so the contacts that stress an intact
    particle (the impact, Eqs. 1-6) are untouched; it only takes kinetic energy from fragments
    (its power -strength sum |F_i v_i| <= 0), in C++ every step at no cost in Python. Newton has
    one damping value per scene: materials with different non-zero strengths in one scene are
    refused (attach's global_damping sets one for all). docs/high_energy.md, "Global damping"."""

    def __init__(self, strengths, duration):
        """strengths: material label -> strength in [0, 1); duration: s, or None (for the
        fragment's life)."""
        self.duration = duration
        nonzero = sorted({v for v in strengths.values() if v > 0.0})
        if len(nonzero) > 1:
            raise AttachError(
                f"global_damping: the materials' files give {nonzero} (by label: "
                f"{dict(strengths)}) but YADE's Newton damping is one value per scene: pass "
                f"global_damping (in [0, 1)) to attach() for all")
        self.strength = nonzero[0] if nonzero else 0.0
        self.damped_labels = {lab for lab, v in strengths.items() if v > 0.0}
        self.until = []                       # [time (s), [ids]]

    def apply_at_attach(self):
        """Newton's damping set to the strength, and taken off every body present."""
        if self.strength <= 0.0:
            return
        newton = next((e for e in O.engines if isinstance(e, wrapper.NewtonIntegrator)), None)
        if newton is None:
            raise AttachError(f"global_damping = {self.strength:g}: the scene has no "
                              f"NewtonIntegrator to apply it; add one or set global_damping=0")
        newton.damping = self.strength
        for b in O.bodies:
            if b is not None:
                b.state.isDamped = False

    def add(self, ids):
        if self.strength > 0.0 and self.duration is not None:
            self.until.append((O.time + self.duration, list(ids)))

    def release(self):
        if not self.until:
            return
        now = O.time
        keep = []
        for until, ids in self.until:
            if now >= until:
                for i in ids:
                    b = O.bodies[i] if i < len(O.bodies) else None
                    if b is not None:
                        b.state.isDamped = False
            else:
                keep.append((until, ids))
        self.until = keep
