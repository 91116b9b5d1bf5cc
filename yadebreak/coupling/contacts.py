"""Reading the stressing energy from YADE's interactions (Eqs. 14-16).

ContactReader turns the real interactions that involve a tracked body into ContactRecords and,
at each read, into the loading of each body: its counted energy Ek' (J), its most energetic
contact, its contacts, and whether any of them still worked. The work law of YADE's
Hertz-Mindlin contacts is one object, HertzMindlinWork. Duck-typed on YADE's interaction,
geometry and physics objects; no yade import.
"""
from __future__ import annotations

import math

from .. import model


class ContactRecord:
    """What is kept of one contact between reads (J, m, N, s).

    offset_a, offset_b: the contact's work already counted in an earlier event of body a (b);
    share_a, share_b: Eq. 4's share of each body. geom and phys are YADE's objects, held while the
    contact lives and never saved."""

    __slots__ = ("overlap", "force", "work", "offset_a", "offset_b", "share_a", "share_b",
                 "shear_disp", "shear_force", "shear_work", "overlap_before", "time_before",
                 "time_read", "geom", "phys")
    #: the fields saved with the scene, in this order
    SAVED = __slots__[:13]

    def __init__(self, share_a, share_b, now, geom, phys):
        self.overlap = self.force = self.work = 0.0
        self.offset_a = self.offset_b = 0.0
        self.share_a, self.share_b = share_a, share_b
        self.shear_disp = self.shear_force = self.shear_work = 0.0
        self.overlap_before = 0.0
        self.time_before = self.time_read = now
        self.geom, self.phys = geom, phys

    def start_here(self):
        """Count work from the present state on, not from first touch: a contact that a fresh
        fragment inherited overlapping (with a neighbour or a sibling) did no work on it yet;
        counted from zero, its whole overlap, artificial part included, would count as if the
        fragment had just been loaded through it."""
        self.overlap = self.overlap_before = self.geom.penetrationDepth
        self.force = self.phys.normalForce.norm()
        self.shear_disp = self.phys.usTotal.norm()
        self.shear_force = self.phys.shearForce.norm()

    def total(self, cs):
        """Normal plus cs times shear work (Eq. 14), J."""
        return self.work + cs * self.shear_work

    def offset(self, side):
        return self.offset_b if side else self.offset_a

    def share(self, side):
        return self.share_b if side else self.share_a

    def saved(self):
        return [getattr(self, f) for f in self.SAVED]

    @classmethod
    def restored(cls, values):
        record = cls.__new__(cls)
        for f, v in zip(cls.SAVED, values):
            setattr(record, f, v)
        record.geom = record.phys = None
        return record


class HertzMindlinWork:
    """Eqs. 15-16 for YADE's Law2_ScGeom_MindlinPhys_Mindlin: the normal work while the overlap
    grows, with F = kno delta^1.5 + dashpot.

    The Hertz part is exact between two reads, 0.4 kno (d1^2.5 - d0^2.5); the dashpot part
    (total force minus kno d^1.5) by the trapezoidal rule, except from first touch, where
    Mindlin's dashpot grows like delta^(1/4) at a nearly constant rate: over k steps its work is
    (0.8 - 0.3 / k^2) F d (the trapezoid's 0.5 over one step, which is what YADE's leapfrog makes
    of it, 0.8 over many). Pairs whose kno varies (zeroed artificial overlaps) take the trapezoid
    on their total force."""

    @staticmethod
    def first_touch_factor(interval):
        return 0.8 - 0.3 / interval ** 2

    @staticmethod
    def loading(c, delta, force, hertz, first_touch):
        """Work (J) from the last read's overlap c.overlap up to delta (> c.overlap)."""
        d0 = c.overlap
        if not hertz:
            return 0.5 * (c.force + force) * (delta - d0)
        kno = c.phys.kno
        el0 = kno * d0 * math.sqrt(d0)
        el1 = kno * delta * math.sqrt(delta)
        if d0 > 0.0:
            return 0.4 * (el1 * delta - el0 * d0) + 0.5 * (c.force - el0 + force - el1) * (delta - d0)
        return 0.4 * el1 * delta + first_touch * (force - el1) * delta

    @staticmethod
    def to_peak(c, delta, now, hertz):
        """Work (J) from the last read up to the peak of the parabola through the last three
        overlaps, when the overlap peaked between two reads (sparse reads); 0 if it did not."""
        d0 = c.overlap
        peak = (model.parabolic_peak(c.time_before, c.overlap_before, c.time_read, d0, now, delta)
                if hertz else d0)
        if not peak > d0:
            return None
        kno = c.phys.kno
        el0 = kno * d0 * math.sqrt(d0)
        return 0.4 * kno * (peak ** 2.5 - d0 ** 2.5) + 0.5 * (c.force - el0) * (peak - d0)

    @staticmethod
    def stored(kno, delta):
        """Elastic energy (J) held in a Hertz contact: 0.4 kno delta^2.5."""
        return 0.4 * kno * delta ** 2.5


class Loading:
    """The bodies' loading found by one read."""

    __slots__ = ("energy", "strongest", "touching", "grew")

    def __init__(self):
        self.energy = {}          # body -> Ek' (J) counted now
        self.strongest = {}       # body -> (share of energy, contact normal, sign, the other body)
        self.touching = {}        # tracked body -> [(ContactRecord, side: 0 for id1, 1 for id2)]
        self.grew = set()         # tracked bodies with a contact that worked since the last read


class ContactReader:
    """The contacts of tracked bodies, read every time the schedule says."""

    def __init__(self, stiffness_by_material_id, cs, emin):
        self.stiffness = stiffness_by_material_id     # YADE material id -> Hertz stiffness (Pa)
        self.cs = cs
        self.emin = emin
        self.contacts = {}                            # (id1, id2) -> ContactRecord
        self.inherited = set()                        # (smaller id, larger id): see inherit()
        self.law = HertzMindlinWork()

    def read(self, interactions, bodies, tracked, zeroed, now, interval, asleep=()):
        """One pass over the interactions; contacts that ceased drop out. `zeroed` holds the pairs
        whose kno varies, `asleep` those of them that carry no force and are not visited now
        (their records stay as they were: they do no work), all keyed (smaller id, larger id);
        `interval` is the steps since the last read."""
        cs, emin = self.cs, self.emin
        inherited = self.inherited
        work_loading, work_to_peak = self.law.loading, self.law.to_peak
        first_touch = self.law.first_touch_factor(interval)
        contacts = self.contacts
        seen = {}
        out = Loading()
        energy, strongest, touching, grew = out.energy, out.strongest, out.touching, out.grew
        for i in interactions:
            a = i.id1
            b = i.id2
            in_a = a in tracked
            in_b = b in tracked
            if not (in_a or in_b):
                continue
            key = (a, b)
            # zeroed, asleep and inherited pairs are (smaller id, larger id); YADE's id1 may be
            # the larger
            pair = key if a < b else (b, a)
            c = contacts.get(key)
            update = True
            if c is None:
                c = self._new_record(i, bodies, now)
                if c is None:
                    continue
                contacts[key] = c
                if inherited and pair in inherited:
                    c.start_here()
            elif c.geom is None:                  # restored from a save: YADE's objects again
                c.geom, c.phys = i.geom, i.phys
            elif asleep and pair in asleep:
                update = False                    # a slack zeroed pair: no force, no work
            if update:
                g = c.geom
                delta = g.penetrationDepth
                force = c.phys.normalForce.norm()    # compressive while the overlap grows
                d0 = c.overlap
                peaked = delta < d0 and c.overlap_before < d0 and c.time_read > c.time_before
                if delta > d0 or peaked:
                    hertz = not (zeroed and pair in zeroed)
                    if delta > d0:
                        work = work_loading(c, delta, force, hertz, first_touch)
                    else:
                        work = work_to_peak(c, delta, now, hertz)
                    if work is not None:
                        c.work += work
                        if in_a:
                            grew.add(a)
                        if in_b:
                            grew.add(b)
                c.overlap_before = d0
                c.time_before = c.time_read
                c.time_read = now
                c.overlap = delta
                c.force = force
                if cs > 0.0:
                    ph = c.phys
                    us = ph.usTotal.norm()
                    fs = ph.shearForce.norm()
                    if us > c.shear_disp:
                        c.shear_work += 0.5 * (c.shear_force + fs) * (us - c.shear_disp)
                    c.shear_disp = us
                    c.shear_force = fs
            seen[key] = c
            total = c.work + cs * c.shear_work
            # both endpoints written out, not looped: this runs for every contact at every read
            if in_a:
                touching.setdefault(a, []).append((c, 0))
                own = total - c.offset_a
                if own >= emin:
                    share = c.share_a * own
                    energy[a] = energy.get(a, 0.0) + share
                    if share > strongest.get(a, (0.0,))[0]:
                        strongest[a] = (share, c.geom.normal, 1.0, b)   # normal points a -> b
            if in_b:
                touching.setdefault(b, []).append((c, 1))
                own = total - c.offset_b
                if own >= emin:
                    share = c.share_b * own
                    energy[b] = energy.get(b, 0.0) + share
                    if share > strongest.get(b, (0.0,))[0]:
                        strongest[b] = (share, c.geom.normal, -1.0, a)
        self.contacts = seen
        inherited.clear()                 # read now or gone
        return out

    def inherit(self, pairs):
        """Pairs (ids) that fresh fragments inherit overlapping: their records, made at the next
        read, count work from that state on (ContactRecord.start_here)."""
        self.inherited.update((a, b) if a < b else (b, a) for a, b in pairs)

    def _new_record(self, inter, bodies, now):
        """A record for a contact seen for the first time, with Eq. 4's shares (None while YADE
        has no geometry for it)."""
        if inter.geom is None:
            return None
        ka = self.stiffness[bodies[inter.id1].material.id]
        kb = self.stiffness[bodies[inter.id2].material.id]
        return ContactRecord(float(model.energy_partition(ka, kb)),
                             float(model.energy_partition(kb, ka)), now, inter.geom, inter.phys)

    def stored_share(self, touching):
        """Elastic energy (J) a body holds now in its counted contacts: its share of the Hertz
        energy, with kno as the law uses it (scaled for zeroed pairs)."""
        total = 0.0
        for c, side in touching:
            if c.total(self.cs) - c.offset(side) >= self.emin and c.overlap > 0.0:
                total += c.share(side) * self.law.stored(c.phys.kno, c.overlap)
        return total

    def restart(self, touching):
        """Count a body's energy from now on: its offsets become its contacts' present work."""
        for c, side in touching:
            if side:
                c.offset_b = c.total(self.cs)
            else:
                c.offset_a = c.total(self.cs)

    def touching(self, ids):
        """{body: [(record, side)]} for the bodies `ids`, from the contacts kept (one pass)."""
        found = {}
        for (a, b), c in self.contacts.items():
            if a in ids:
                found.setdefault(a, []).append((c, 0))
            if b in ids:
                found.setdefault(b, []).append((c, 1))
        return found

    def bodies_in_contact(self):
        return {k for key in self.contacts for k in key}

    def to_dict(self):
        return {"fields": list(ContactRecord.SAVED),
                "rows": [[a, b, *c.saved()] for (a, b), c in self.contacts.items()],
                "inherited": sorted(self.inherited)}

    def restore(self, data):
        if data["fields"] != list(ContactRecord.SAVED):
            raise ValueError("saved contacts have other fields than this yadebreak's")
        # a contact that had separated at its last read (overlap < 0) is left out: the law erases
        # such an interaction, and the run this continues counted its next touch from zero;
        # YADE's saved scene may still hold the interaction
        restored = ((row, ContactRecord.restored(row[2:])) for row in data["rows"])
        self.contacts = {(row[0], row[1]): c for row, c in restored if c.overlap >= 0.0}
        self.inherited = {tuple(pair) for pair in data.get("inherited", ())}
