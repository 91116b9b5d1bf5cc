"""Reading a contact of YADE's volumetric law for convex polyhedra
(Law2_PolyhedraGeom_PolyhedraPhys_Volumetric: a normal force kn V, V the volume the two bodies
share, no dashpot).

PolyhedraGeom gives no approach to integrate the force over (docs/polyhedra.md), so the approach
is taken from the bodies' motion: over a read, the normal approach of the two material points at
the contact point c,

    d(delta) = -[(v_b + w_b x (c - x_b)) - (v_a + w_a x (c - x_a))] . n  (t - t_read),

n the contact normal (from a to b), v and w YADE's velocities at the read (the leapfrog's, that
moved the bodies to where the force was computed), and the work of the normal force by the
trapezoid, (F_read + F) / 2 d(delta). A row counts the work while the approach grows (the
stressing energy, as for Hertz-Mindlin: what the criteria judge) in WORK, and the running
integral over loading and unloading, the elastic energy the contact holds (the law is elastic in
the normal direction), in HELD. OVERLAP holds the approach since the contact began (m).

Read every step (Volumetric.reads_every_step: between reads the approach is extrapolated from
the velocities of one instant), contact by contact (read_rows, calling fresh() and advance() for
each). A fragment's overlaps inherited from its parent are zeroed (ZeroedVolumes), as a sphere
fragment's are (engine/zeroing.py). Volumetric is what the reader and the replacer ask of this
law (laws.py lists the laws). Duck-typed on YADE's objects; no yade import.
"""
from __future__ import annotations

import numpy as np

from yadebreak.engine.contacts.law import own_share, total_work
from yadebreak.engine.contacts.loading import Loading, StrongestContacts
from yadebreak.engine.contacts.table import (FORCE, OFFSET_A, OFFSET_B, OVERLAP, OVERLAP_BEFORE,
                                             SHARE_A, SHARE_B, SHEAR_WORK, TIME_READ, WORK,
                                             fresh_row)

#: the column of a volumetric row that holds its elastic energy (J): the running integral of
#: F d(delta); a Hertz row keeps the overlap of the read before there
HELD = OVERLAP_BEFORE
#: O.dt on this law, as a fraction of the Rayleigh time of a body's volume-equivalent sphere
#: with the Young's modulus its contacts act with (Volumetric.fragment_time_step): a face-on
#: impact lasts about one such time, so this gives it about 100 steps; measured
#: (tests/test_polyhedra_reading.py), the energy a cube reads at 300 J/kg is then within 0.1 %
#: of Eq. 4's share face, edge or corner first
STEP_FRACTION = 0.01


def approach_rate(geom, state_a, state_b):
    """The rate (m/s) at which the two bodies' material points at the contact point close along
    the contact normal (from a to b)."""
    c = geom.contactPoint
    relative = (state_b.vel + state_b.angVel.cross(c - state_b.pos)
                - state_a.vel - state_a.angVel.cross(c - state_a.pos))
    return -relative.dot(geom.normal)


def fresh(stiffness, bodies, a, b, phys, now, previous, inherited):
    """The row of a contact seen first at this read: it began after the last read (at
    `previous`, s), its force growing from nothing since; an `inherited` one (a fragment's,
    overlapping as its parent did) and any at the first read (previous == now) count from
    their present force."""
    row = fresh_row(stiffness, bodies, a, b, previous)
    if inherited or previous == now:
        row[FORCE], row[TIME_READ] = phys.normalForce.norm(), now
    return row


def advance(row, geom, phys, state_a, state_b, now):
    """Bring a row to the present; returns whether its loading work grew."""
    force = phys.normalForce.norm()
    step = approach_rate(geom, state_a, state_b) * (now - row[TIME_READ])
    work = 0.5 * (row[FORCE] + force) * step
    row[HELD] += work
    row[OVERLAP] += step
    row[FORCE] = force
    row[TIME_READ] = now
    if step > 0.0 and work > 0.0:
        row[WORK] += work
        return True
    return False


class PairChecks:
    """What YADE's warning "Unhandled switch case:0, function do_intersect" would count. Its
    Ig2_Polyhedra_Polyhedra_PolyhedraGeom tests each pair of polyhedra whose bounding boxes
    overlap by do_intersect, from the separating plane kept in the pair's geometry; a pair with
    none kept warns: a pair seen for the first time, and at every step a pair whose boxes
    overlap without touching (a potential interaction has no geometry to keep one in).
    Measured: two separated cubes whose boxes overlap, one warning a step; touching, one in
    all. The engine silences that warning (adapter.yade_api.silence_polyhedra_pair_checks)
    and counts here, at each read (every step on this law), the pairs that warned since the
    last: those not touching, and those touching now that did not at the last read."""

    def __init__(self):
        self.count = 0
        self.touching = set()
        self._polyhedron = {}               # body id -> is a polyhedron (shapes do not change)

    def add(self, interactions, bodies):
        """Count the checks of this step from YADE's interactions, real and potential."""
        polyhedron, touching, separated = self._polyhedron, set(), 0
        for inter in interactions.all(False):
            a, b = inter.id1, inter.id2
            for i in (a, b):
                if i not in polyhedron:
                    polyhedron[i] = type(bodies[i].shape).__name__ == "Polyhedra"
            if polyhedron[a] and polyhedron[b]:
                if inter.isReal:
                    touching.add((a, b))
                else:
                    separated += 1
        self.count += separated + len(touching - self.touching)
        self.touching = touching


def read_rows(reader, real, bodies, tracked, now, previous):
    """One read of `real` (YADE's real interactions) into reader.table, each contact brought to
    the present by advance(); `previous` the time (s) of the last read. Returns the Loading."""
    table, cs, emin, inherited = reader.table, reader.cs, reader.emin, reader.inherited
    index = table.index
    if index is None:
        index = dict(zip(zip(table.a.tolist(), table.b.tolist()), range(len(table.a))))
    old_rows, old_geoms, old_physs = table.row_lists(), table.geoms, table.physs
    kept = []                                         # (a, b, row, geom, phys) of each row
    energy, found, grew, by_body, new_index = {}, {}, set(), {}, {}
    for inter in real:
        a, b = inter.id1, inter.id2
        in_a, in_b = a in tracked, b in tracked
        if not (in_a or in_b):
            continue
        j = index.get((a, b))
        if j is None:
            geom, phys = inter.geom, inter.phys
            row = fresh(reader.stiffness, bodies, a, b, phys, now, previous,
                        bool(inherited) and ((a, b) if a < b else (b, a)) in inherited)
        elif old_geoms[j] is None:                        # restored from a save
            row, geom, phys = old_rows[j], inter.geom, inter.phys
        else:
            row, geom, phys = old_rows[j], old_geoms[j], old_physs[j]
        if advance(row, geom, phys, bodies[a].state, bodies[b].state, now):
            grew.update(i for i, mine in ((a, in_a), (b, in_b)) if mine)
        k = new_index[(a, b)] = len(kept)
        kept.append((a, b, row, geom, phys))
        total = total_work(row[WORK], row[SHEAR_WORK], cs)
        for body, other, mine, offset, share, sign in ((a, b, in_a, OFFSET_A, SHARE_A, 1.0),
                                                       (b, a, in_b, OFFSET_B, SHARE_B, -1.0)):
            if not mine:
                continue
            by_body.setdefault(body, []).append((k, 0 if sign > 0.0 else 1))
            counted, own = own_share(total, row[offset], row[share], emin)
            if counted:
                energy[body] = energy.get(body, 0.0) + own
                if own > found.get(body, (0.0,))[0]:
                    found[body] = (own, k, sign, other)
    a_list, b_list, rows, geoms, physs = ((list(c) for c in zip(*kept)) if kept
                                         else ([], [], [], [], []))
    table.set(np.array(a_list, np.int64), np.array(b_list, np.int64), None, geoms, physs, rows=rows,
              by_body=by_body, index=new_index)
    return Loading(energy, StrongestContacts(found, geoms), grew)


class ZeroedVolumes:
    """The overlap volumes fragments inherit from their parent, each the zero of its contact:
    the force of such a pair is kn (V - V0), not YADE's kn V, so that only later loading makes
    force (the energy the parent's contacts held went into breaking it; kept, a fine cell deep in
    its parent's overlap with the plate would take the parent's force and pass its own fracture
    energy many times over within a step). V0 is the pair's volume when YADE makes it, the step
    after the replacement, and follows V down as the bodies separate; a pair is dropped when V0
    reaches 0 or the interaction ends, or at once if YADE did not make it (that neighbour did not
    overlap the fragment: most of the pairs of a cell and its parent's neighbours). The
    correction is made after the InteractionLoop, before the read: YADE applied F = kn V along
    the normal at the contact point (-F on id1, +F on id2); kn V0 of it is taken back from both
    bodies' forces and torques and from phys.normalForce, which the read and the law's next step
    see."""

    def __init__(self):
        self.volumes = {}                     # (smaller id, larger id) -> V0 (m3), None: not
        #                                       seen yet

    def add(self, pairs):
        for a, b in pairs:
            self.volumes.setdefault((a, b) if a < b else (b, a), None)

    def settle(self, interactions, bodies, forces):
        """Take each zeroed pair's kn V0 back from this step's forces (see the class)."""
        for pair, zero in list(self.volumes.items()):
            a, b = pair
            if bodies[a] is None or bodies[b] is None:      # one broke or left: the pair ends
                del self.volumes[pair]
                continue
            inter = interactions[a, b] if interactions.has(a, b) else None
            if inter is None or not inter.isReal:       # ended, or never overlapped
                del self.volumes[pair]
                continue
            volume = inter.geom.penetrationVolume
            zero = volume if zero is None else min(zero, volume)
            if zero <= 0.0:
                del self.volumes[pair]
                continue
            self.volumes[pair] = zero
            phys, geom = inter.phys, inter.geom
            force = phys.normalForce
            magnitude = force.norm()
            if magnitude <= 0.0:
                continue
            back = force * (min(phys.kn * zero, magnitude) / magnitude)
            phys.normalForce = force - back
            c, one, two = geom.contactPoint, inter.id1, inter.id2
            forces.addF(one, back)
            forces.addF(two, -back)
            forces.addT(one, (c - bodies[one].state.pos).cross(back))
            forces.addT(two, -(c - bodies[two].state.pos).cross(back))

    def to_list(self):
        return [[a, b, v] for (a, b), v in sorted(self.volumes.items())]

    def restore(self, saved):
        self.volumes = {(a, b): v for a, b, v in saved}


class Volumetric:
    """The reader's view of Law2_PolyhedraGeom_PolyhedraPhys_Volumetric: read every step,
    contact by contact (read_rows); YADE's do_intersect warnings counted (PairChecks)."""

    name = "volumetric"
    yade_law = "Law2_PolyhedraGeom_PolyhedraPhys_Volumetric"
    #: between reads the approach would be extrapolated from one instant's velocities
    reads_every_step = True
    #: said once when the engine attaches to a scene on this law with YADE's default O.dt
    time_step_advice = ("the engine sets no time step for polyhedra on the volumetric law; set "
                        "O.dt before attach (the scenes use 1 % of a particle's Rayleigh time: "
                        "docs/polyhedra.md)")

    def __init__(self):
        #: the checks YADE's silenced do_intersect warning counts
        self.pair_checks = PairChecks()
        #: fragments' inherited overlaps, zeroed
        self.zeroed = ZeroedVolumes()

    def inherited(self, pairs, zeroed):
        """Fresh fragments overlap their parent's neighbours as `pairs` (ids); `zeroed`: the
        replacement's zero_overlaps (those overlaps make no force)."""
        if zeroed:
            self.zeroed.add(pairs)

    def settle(self, scene):
        """After the InteractionLoop, before the read (`scene`: YADE's Omega): the zeroed
        overlaps' force taken back."""
        if self.zeroed.volumes:
            self.zeroed.settle(scene.interactions, scene.bodies, scene.forces)

    def to_dict(self):
        return {"zeroed_volumes": self.zeroed.to_list()}

    def restore(self, data):
        self.zeroed.restore(data.get("zeroed_volumes", ()))

    def problems(self, reading):
        """What in the read options (config.Reading) this law cannot honour, in one line."""
        if reading.cs > 0.0:
            return (f"cs = {reading.cs:g}: the volumetric law's shear work is not read; accepted "
                    "0 with polyhedra on Law2_PolyhedraGeom_PolyhedraPhys_Volumetric")
        return None

    def young_is_stiffness(self, material):
        """Whether a YADE material's `young` is this law's kn (N/m3): a PolyhedraMat's is."""
        return type(material).__name__ == "PolyhedraMat"

    def fragment_time_step(self, time_step, radius, material):
        """The time step (s) fragments of `radius` (m) in a YADE `material` need: STEP_FRACTION
        (or time_step_fraction, if smaller) of the Rayleigh time with the Young's modulus their
        contacts act with. A face-on contact of a body of size s on this law
        stiffens as kn s^2 and its mass grows as s^3, so it lasts as sqrt(rho s / kn): as a
        Hertz body of size s and Young's modulus kn (1 - nu^2) s. The scenes set
        kn = Y / (1 - nu^2) / S for particles of size S (scenes/polyhedra.py): at s = S this
        is the material file's Y, and the step the scene set; a finer fragment needs a step
        finer as sqrt(s) (taking kn for Y would make it finer as s, and the step 10-40 times
        finer than the contacts need)."""
        if not self.young_is_stiffness(material):
            return time_step.for_fragments(radius, material, material.young)
        modulus = material.young * (1.0 - material.poisson ** 2) * 2.0 * radius
        return time_step.for_fragments(radius, material, modulus, STEP_FRACTION)

    def read(self, reader, interactions, bodies, tracked, zeroed, now, interval, asleep, counts,
             zeroing_changes):
        """One read (ContactReader.read), every step: the zeroing does not act on this law."""
        self.pair_checks.add(interactions, bodies)
        previous = reader.last_time if reader.last_time is not None else now
        return read_rows(reader, interactions.all(True), bodies, tracked, now, previous)

    @staticmethod
    def held(table, row, physs):
        """Elastic energy (J) contact `row` holds now: the running integral of F d(delta)."""
        return table.value(row, HELD)

    @staticmethod
    def neighbour_energy(reader, body, interactions, zeroed_pairs, each=None):
        """The neighbours (ids) of `body` over `interactions` and the elastic energy (J) its
        contacts hold, both sides, as the reader's rows integrate it."""
        found = [i.id2 if i.id1 == body else i.id1 for i in interactions]
        energy = sum(max(reader.table.value(row, HELD), 0.0)
                     for row, _ in reader.table.rows_of(body))
        return found, energy
