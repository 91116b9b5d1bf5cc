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

Read every step (the schedule reads polyhedra on this law every step: between reads the approach
is extrapolated from the velocities of one instant), by the scalar read (each.py), which calls
fresh() and advance() for each contact. Duck-typed on YADE's objects; no yade import.
"""
from __future__ import annotations

from yadebreak.engine.contacts.table import (FORCE, OFFSET_A, OFFSET_B, OVERLAP, OVERLAP_BEFORE,
                                             SHARE_A, SHARE_B, TIME_READ, WORK, fresh_row)

#: the column of a volumetric row that holds its elastic energy (J): the running integral of
#: F d(delta); a Hertz row keeps the overlap of the read before there
HELD = OVERLAP_BEFORE


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


def held_share(table, body, cs, emin):
    """Elastic energy (J) a body holds now in its counted volumetric contacts: its share of what
    each holds."""
    total = 0.0
    value = table.value
    for row, side in table.rows_of(body):
        offset = value(row, OFFSET_B if side else OFFSET_A)
        held = value(row, HELD)
        if table.total(row, cs) - offset >= emin and held > 0.0:
            total += value(row, SHARE_B if side else SHARE_A) * held
    return total


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


def held_total(table, body):
    """Elastic energy (J) a body's volumetric contacts hold, both sides."""
    return sum(max(table.value(row, HELD), 0.0) for row, _ in table.rows_of(body))
