"""A read of YADE's volumetric law for convex polyhedra (Law2_PolyhedraGeom_PolyhedraPhys_Volumetric:
a normal force kn V, V the volume the two bodies share, no dashpot).

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
is extrapolated from the velocities of one instant). Duck-typed on YADE's objects; no yade import.
"""
from __future__ import annotations

import numpy as np

from yadebreak.engine.contacts.law import own_share
from yadebreak.engine.contacts.loading import Loading, StrongestContacts
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


def _advance(row, geom, phys, state_a, state_b, now):
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


def read_volumetric(reader, real, bodies, tracked, now, previous):
    """One read of `real` (YADE's real interactions) into reader.table; returns the Loading.
    `previous`: the time (s) of the last read; a contact seen first now began after it (its force
    grew from nothing since then), but an inherited one (a fragment's, overlapping as its parent
    did) and any at the first read (previous == now) count from their present force."""
    table, cs, emin, inherited = reader.table, reader.cs, reader.emin, reader.inherited
    index = table.index
    if index is None:
        index = dict(zip(zip(table.a.tolist(), table.b.tolist()), range(len(table.a))))
    old_rows = table.row_lists()
    a_list, b_list, rows, geoms, physs = [], [], [], [], []
    new_index, energy, found, grew, by_body = {}, {}, {}, set(), {}
    for inter in real:
        a, b = inter.id1, inter.id2
        in_a = a in tracked
        in_b = b in tracked
        if not (in_a or in_b):
            continue
        geom, phys = inter.geom, inter.phys
        j = index.get((a, b))
        if j is not None:
            row = old_rows[j]
        else:
            row = fresh_row(reader.stiffness, bodies, a, b, previous)
            pair = (a, b) if a < b else (b, a)
            if previous == now or (inherited and pair in inherited):
                row[FORCE], row[TIME_READ] = phys.normalForce.norm(), now
        if _advance(row, geom, phys, bodies[a].state, bodies[b].state, now):
            if in_a:
                grew.add(a)
            if in_b:
                grew.add(b)
        k = len(rows)
        new_index[(a, b)] = k
        rows.append(row)
        a_list.append(a)
        b_list.append(b)
        geoms.append(geom)
        physs.append(phys)
        for side, body, other, offset, share_col, sign in ((in_a, a, b, OFFSET_A, SHARE_A, 1.0),
                                                           (in_b, b, a, OFFSET_B, SHARE_B, -1.0)):
            if not side:
                continue
            by_body.setdefault(body, []).append((k, 0 if sign > 0 else 1))
            counted, share = own_share(row[WORK], row[offset], row[share_col], emin)
            if counted:
                energy[body] = energy.get(body, 0.0) + share
                if share > found.get(body, (0.0,))[0]:
                    found[body] = (share, k, sign, other)
    table.set(np.array(a_list, np.int64), np.array(b_list, np.int64), None, geoms, physs,
              rows=rows, by_body=by_body, index=new_index)
    return Loading(energy, StrongestContacts(found, geoms), grew)


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


def held_total(table, body):
    """Elastic energy (J) a body's volumetric contacts hold, both sides."""
    return sum(max(table.value(row, HELD), 0.0) for row, _ in table.rows_of(body))
