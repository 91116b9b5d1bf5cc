"""The judge stage of a read: which bodies break, which stressing events open or close (with
damage), and how long the loaded bodies allow until the next read. No yade import: the caller
passes the step and the recorder of events.

Two paths, because each is the faster one somewhere (measured: CPU time per read of
Judge.plan_each and plan_all on scripted reads of one material): a few bodies (laboratory scenes)
are judged one by one on Python scalars (Tavares: 2 us for 1 body, 7 us for 4, against 24-26 us
with numpy), many bodies (process scale) with numpy over all of them (Tavares: 63 us for 200
bodies, against 246 us one by one). Both call the same criterion function (criteria: judge_one on
an id and scalars or on ids and arrays) and give the same decisions and numbers
(tests/test_engine_parts.py)."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from yadebreak.criteria import judge_all

#: up to this many bodies in a read are judged one by one, unless a criterion of the scene says
#: fewer (its `judged_one_by_one`, where the two paths cost the same)
SMALL = 24

# what a body needs after the criteria spoke
NOTHING, FORGET, PAUSE, BREAK, OPEN, CLOSE_IF_UNLOADED = range(6)
#: the warning that a read came late: a body's criterion variable rose by more than this share of
#: its fracture energy between two reads, so that its t10' follows the read, not the crossing
LATE_JUMP = 0.8


def steps_allowed(tolerance, threshold, level, rise, interval):
    """"fast" reads: steps until the next read for bodies whose criterion variable is `level`
    below `threshold` (J/kg) and rose by `rise` over the last `interval` steps: half the way to
    the threshold, or `tolerance` of it, at the present rate (scalars or arrays)."""
    floor, half = tolerance * threshold, 0.5 * (threshold - level)
    larger = np.maximum(floor, half) if isinstance(floor, np.ndarray) else max(floor, half)
    return larger * interval / rise


class Plan:
    """A read's decisions: for each candidate its need (codes above), criterion order (None: one
    criterion for all), Ek' (J), jump and threshold (J/kg; plan_all's as arrays: they are asked
    of breaking bodies only); and the steps the loaded bodies allow (a list; fast reads)."""

    __slots__ = ("need", "order", "ek", "jump", "threshold", "limits")

    def __init__(self, need, order, ek, jump, threshold, limits):
        self.need, self.order, self.ek = need, order, ek
        self.jump, self.threshold, self.limits = jump, threshold, limits


@dataclass(frozen=True)
class Rules:
    """The options a judge follows."""

    energy_factor: float            # fragments_energy_factor
    fast_tolerance: float           # read_period="fast": see steps_allowed
    at_peak: bool = False           # break_at="peak"
    pausing: bool = False           # some material pauses fresh fragments
    carried: bool = False           # contact_energy_at_break="carried"


def _ignore(*args, **fields):
    return None


def _within(mask, active):
    """`mask` on the active candidates only (`active` None: every candidate is)."""
    return mask if active is None else mask & active


class Judge:
    """Judges the bodies a read found loaded (or with an open event), and tells `record(kind,
    id, **fields)` of each event, `warn_jump(id, rise, threshold, Ek')` of a read that came
    late, `warn_emin(id, rise, threshold, Ek', start)` of a body that broke on a contact's first
    counted energy (`start`, J/kg: see first_count), `weakened(id)` of each body a damage
    weakened."""

    def __init__(self, state, criterion_of, reader, rules, *, record=_ignore, warn_jump=_ignore,
                 warn_emin=_ignore, weakened=_ignore):
        self.state = state
        self.criterion_of = criterion_of          # material index -> criterion
        self.reader = reader                      # contacts.ContactReader
        self.at_peak = rules.at_peak
        self.energy_factor = rules.energy_factor
        self.pausing = rules.pausing
        self.carried = rules.carried
        self.fast_tolerance = rules.fast_tolerance
        self.record, self.warn_jump, self.weakened = record, warn_jump, weakened
        self.warn_emin = warn_emin
        #: up to this many candidates a read is judged body by body (plan_each)
        self.small = min([SMALL, *(c.judged_one_by_one for c in criterion_of)])

    def judge(self, loading, interval, now_iter, fast):
        """Returns [(id, Ek', strongest contact)] of the bodies that break now, and the steps the
        loaded ones allow before the next read (None unless `fast`)."""
        # in id order: the decisions (and the random draws of breakages in one read) do not
        # depend on the order in which YADE or the reader met the contacts
        open_events = self.state.open_events
        if loading.ids is None:                   # a read contact by contact: a few bodies
            ids = candidates = sorted(open_events.union(loading.energy))
        else:
            ids = np.union1d(loading.ids, np.fromiter(open_events, np.int64, len(open_events)))
            candidates = ids.tolist()
        if not candidates:
            return [], None
        if len(candidates) <= self.small:
            plan = self.plan_each(candidates, loading, interval, now_iter, fast)
        else:
            plan = self.plan_all(ids, loading, interval, now_iter, fast)
        return self.settle(candidates, plan, loading), plan.limits

    def _specific(self, i, e, c):
        if self.energy_factor != 1.0 and c["generation"][i] > 0:
            e = e * self.energy_factor
        return e, e / c["mass"][i]

    def plan_each(self, candidates, loading, interval, now_iter, fast):
        """The decisions body by body (Python scalars)."""
        c = self.state.table.columns
        tracked = self.state.tracked
        n = len(candidates)
        need, order = [NOTHING] * n, [0] * n
        eks, jumps, thresholds, limits = [0.0] * n, [0.0] * n, [1.0] * n, []
        energy = loading.energy
        for k, i in enumerate(candidates):
            if i not in tracked:
                need[k] = FORGET
                continue
            if self.pausing and c["pause_until"][i] > now_iter:
                need[k] = PAUSE
                c["event_max"][i] = c["specific_energy"][i] = 0.0
                continue
            e = energy.get(i, 0.0)
            if self.carried:
                e += c["carried"][i]
            e, specific = self._specific(i, e, c)
            crit = self.criterion_of[c["material"][i]]
            breaks, level, threshold, rising, rise, jump = crit.judge_one(c, i, e, specific)
            if fast and rising:
                limits.append(steps_allowed(self.fast_tolerance, threshold, level, rise, interval))
            c["specific_energy"][i] = specific
            before = c["event_max"][i]
            if self.at_peak and (breaks or c["cracked"][i]):
                breaks = e <= before             # the event's peak has passed: break now
                if not breaks:                   # still loading: the peak is ahead
                    c["cracked"][i] = 1
                    jump = 0.0
                e = max(e, before)
            if breaks:
                need[k] = BREAK
            elif e > before:
                c["event_max"][i] = e
                c["event_partner"][i] = loading.strongest.partner(i)
                need[k] = OPEN
            elif before > 0.0:
                need[k] = CLOSE_IF_UNLOADED
            order[k], eks[k], jumps[k], thresholds[k] = crit.order, e, jump, threshold
        return Plan(need, order, eks, jumps, thresholds, limits)

    def plan_all(self, candidates, loading, interval, now_iter, fast):
        """The same decisions with numpy over all the candidates (a list or an array of ids)."""
        c = self.state.table.columns
        ids = np.asarray(candidates, np.int64)
        n = len(ids)
        # no mask is made that would select every candidate (all tracked, none paused) or none
        # (paused): numpy's cost per call is most of a read's judging; `active` None stands for
        # every candidate
        known = self.state.tracked.mask(int(ids.max()) + 1)[ids]
        if known.all():
            known = None
        paused = None
        if self.pausing:
            paused = _within(c["pause_until"][ids] > now_iter, known)
            if not paused.any():
                paused = None
        active = known if paused is None else _within(~paused, known)
        ek = loading.energies(ids)
        if self.carried:
            ek = ek + c["carried"][ids]
        if self.energy_factor != 1.0:
            ek = np.where(c["generation"][ids] > 0, ek * self.energy_factor, ek)
        specific = ek / c["mass"][ids]
        v = judge_all(self.criterion_of, self.state.table, ids, active, ek, specific)
        limits = None
        if fast and v.rising.any():
            r = v.rising
            limits = steps_allowed(self.fast_tolerance, v.threshold[r], v.level[r], v.rise[r],
                                   interval).tolist()
        event_max = c["event_max"][ids]
        breaks = v.breaks                                # False where inactive
        if self.at_peak:
            crossed = _within(breaks | (c["cracked"][ids] > 0), active)
            breaks = crossed & (ek <= event_max)         # the event's peak has passed
            c["cracked"][ids[crossed & ~breaks]] = 1     # still loading: the peak is ahead
            ek = np.where(breaks, np.maximum(ek, event_max), ek)
            v.jump = np.where(crossed, 0.0, v.jump)
        grows = _within(~breaks & (ek > event_max), active)
        if active is None:
            c["specific_energy"][ids] = specific
        else:
            c["specific_energy"][ids[active]] = specific[active]
        growing = ids[grows]
        c["event_max"][growing] = ek[grows]
        c["event_partner"][growing] = loading.strongest.partners(growing)
        need = np.full(n, NOTHING, np.int8)
        need[_within(event_max > 0.0, active)] = CLOSE_IF_UNLOADED
        need[grows] = OPEN
        need[breaks] = BREAK
        if paused is not None:
            c["event_max"][ids[paused]] = 0.0
            c["specific_energy"][ids[paused]] = 0.0
            need[paused] = PAUSE
        if known is not None:
            need[~known] = FORGET
        # Ek', jump and threshold stay arrays: settle asks them of breaking bodies only
        return Plan(need.tolist(), None if v.order is None else v.order.tolist(), ek, v.jump,
                    v.threshold, limits)

    def settle(self, candidates, plan, loading):
        """Events open, close or break, body by body in the criteria's order (Tavares bodies,
        then Ab-T10's: the order of the event log and of the random draws)."""
        open_events = self.state.open_events
        broken = []
        visit = range(len(candidates))
        if plan.order is not None and any(plan.order):
            visit = sorted(visit, key=plan.order.__getitem__)      # stable
        unloaded = self._unloaded(candidates, plan, loading)
        closing = []                   # closed together once visited (each body's own state)
        for k in visit:
            what = plan.need[k]
            if what == NOTHING:
                continue
            i = candidates[k]
            if what == OPEN:
                open_events.add(i)
            elif what == CLOSE_IF_UNLOADED:
                if i in unloaded:
                    closing.append(i)
            elif what == BREAK:
                jump, threshold = float(plan.jump[k]), float(plan.threshold[k])
                if jump > LATE_JUMP * threshold:
                    start = self.first_count(i, loading)
                    if jump - start > LATE_JUMP * threshold:
                        self.warn_jump(i, jump, threshold, float(plan.ek[k]))
                    else:
                        self.warn_emin(i, jump, threshold, float(plan.ek[k]), start)
                broken.append((i, float(plan.ek[k]), loading.strongest.get(i)))
            elif what == PAUSE:
                # Rocky's safeguard: a fresh fragment counts nothing yet, and what its contacts
                # did meanwhile is never counted later
                self.reader.restart(i)
                self.state.table.columns["carried"][i] = 0.0
                open_events.discard(i)
            else:
                open_events.discard(i)
        self.close_events(closing)
        return broken

    def first_count(self, i, loading):
        """The specific energy (J/kg) body i's count rises by, at the least, when its strongest
        contact at this read is first counted: its share (Eq. 4) of emin, a contact's energy
        counting only from emin on (the paper's Emin). So much of a rise no closer read removes:
        a body whose fracture energy is below it breaks on that contact's first count."""
        at = loading.strongest.row(i)
        if at is None:
            return 0.0
        row, side = at
        share = self.reader.table.value(row, side)
        return self._specific(i, share * self.reader.emin, self.state.table.columns)[1]

    def _unloaded(self, candidates, plan, loading):
        """The bodies whose event may close that unloaded: none of their contacts worked and
        their contacts hold at most emin (asked at once: closing one body's event restarts its
        own offsets only, so the order does not matter)."""
        asked = [i for i, what in zip(candidates, plan.need)
                 if what == CLOSE_IF_UNLOADED and i not in loading.grew]
        if not asked:
            return ()
        emin = self.reader.emin
        return {i for i, held in zip(asked, self.reader.stored_shares(asked)) if held <= emin}

    def close_events(self, ids):
        """End of stressing events without breakage (`ids`, a list, logged in its order): each
        criterion's damage rule (Eqs. 5-6 or 9.2) with the event's largest Ek'; the next event
        starts from the present state. Done together: a collisional cloud closes hundreds of
        light events a read, and what one event changes is its own body's."""
        if not ids:
            return
        table = self.state.table
        c = table.columns
        rows = np.asarray(ids, np.int64)
        energies = c["fracture_energy"][rows]                # a copy: the energies before
        specific = (c["event_max"][rows] / c["mass"][rows]).tolist()
        partners = c["event_partner"][rows].tolist()
        criteria = self.criterion_of
        materials = c["material"][rows].tolist()
        fields = [None] * len(ids)
        for m in set(materials):            # each criterion on its bodies (their own columns)
            at = [k for k, of in enumerate(materials) if of == m]
            for k, f in zip(at, criteria[m].unload_all(table, [ids[k] for k in at])):
                fields[k] = f
        kinds = [criteria[m].event_kind for m in materials]
        for i, kind, f, e, partner in zip(ids, kinds, fields, specific, partners):
            if f is not None:
                self.record(kind, i, specific_energy=e, partner=int(partner), **f)
        c["event_max"][rows] = c["specific_energy"][rows] = c["carried"][rows] = 0.0
        self.state.open_events.difference_update(ids)
        self.reader.restart_all(ids)
        # only a change of E moves the read schedule: Ab-T10's unloading keeps E, and a light
        # touch's E (1 - D) rounds to E
        changed = (c["fracture_energy"][rows] != energies).tolist()
        weakened = [i for i, f, moved in zip(ids, fields, changed) if f is not None and moved]
        if weakened:
            self.weakened(weakened)
