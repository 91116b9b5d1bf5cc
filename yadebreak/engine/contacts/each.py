"""A read contact by contact on Python scalars, over YADE's list of real interactions: for a few
contacts (laboratory scenes), where numpy's cost per call outweighs its cost per contact
(reader.py gives the measurements). It gives the numbers the numpy read (arrays.py) gives
(tests/test_contact_paths.py)."""
from __future__ import annotations

import math

import numpy as np

from yadebreak.engine.contacts.law import HertzMindlinWork, own_share, total_work
from yadebreak.engine.contacts.table import (FORCE, OFFSET_A, OFFSET_B, OVERLAP, OVERLAP_BEFORE,
                                             SHARE_A, SHARE_B, SHEAR_DISP, SHEAR_FORCE,
                                             SHEAR_WORK, TIME_BEFORE, TIME_READ, WORK, fresh_row)
from yadebreak.engine.contacts.loading import Loading, StrongestContacts

_law = HertzMindlinWork


def _advance(row, geom, phys, delta, zeroed_pair, first_touch, cs, now):
    """Bring one contact's numbers (`row`, a list of FIELDS) to the present overlap `delta` and
    YADE's forces; returns whether its normal work grew."""
    if delta is None:
        delta = geom.penetrationDepth
    force = phys.normalForce.norm()
    d0 = row[OVERLAP]
    work = None
    if delta > d0:
        if zeroed_pair:
            work = _law.trapezoid(d0, row[FORCE], delta, force)
        elif d0 > 0.0:
            work = _law.from_overlap(d0, row[FORCE], phys.kno, delta, force, math.sqrt)
        else:
            work = _law.from_first_touch(phys.kno, delta, force, first_touch, math.sqrt)
    elif (not zeroed_pair
          and _law.peaked(d0, delta, row[OVERLAP_BEFORE], row[TIME_BEFORE], row[TIME_READ])):
        work = _law.past_peak(d0, row[FORCE], phys.kno, row[OVERLAP_BEFORE], row[TIME_BEFORE],
                              row[TIME_READ], now, delta)
    if work is not None:
        row[WORK] += work
    row[OVERLAP_BEFORE] = d0
    row[TIME_BEFORE] = row[TIME_READ]
    row[TIME_READ] = now
    row[OVERLAP] = delta
    row[FORCE] = force
    if cs > 0.0:
        us = phys.usTotal.norm()
        fs = phys.shearForce.norm()
        if us > row[SHEAR_DISP]:
            row[SHEAR_WORK] += _law.trapezoid(row[SHEAR_DISP], row[SHEAR_FORCE], us, fs)
        row[SHEAR_DISP] = us
        row[SHEAR_FORCE] = fs
    return work is not None


def _start_here(row, geom, phys, cs):
    """A fresh row of an inherited pair counts work from its present state (see
    arrays.ArrayRead._start_here)."""
    row[OVERLAP] = row[OVERLAP_BEFORE] = geom.penetrationDepth
    row[FORCE] = phys.normalForce.norm()
    if cs > 0.0:
        row[SHEAR_DISP] = phys.usTotal.norm()
        row[SHEAR_FORCE] = phys.shearForce.norm()


def read_each(reader, real, bodies, tracked, zeroed, now, interval, asleep):
    """One read of `real` (YADE's real interactions) into reader.table; returns the Loading."""
    table, cs, emin, inherited = reader.table, reader.cs, reader.emin, reader.inherited
    first_touch = _law.first_touch_factor(interval)
    index = table.index
    if index is None:             # the last read was numpy's
        index = dict(zip(zip(table.a.tolist(), table.b.tolist()), range(len(table.a))))
    new_index = {}
    old_rows, old_geoms, old_physs = table.row_lists(), table.geoms, table.physs
    a_list, b_list, rows, geoms, physs = [], [], [], [], []
    energy, found, grew, by_body = {}, {}, set(), {}
    paired = bool(zeroed or asleep or inherited)     # else no contact's pair is looked up
    for inter in real:
        a, b = inter.id1, inter.id2
        in_a, in_b = a in tracked, b in tracked
        if not (in_a or in_b):
            continue
        pair = ((a, b) if a < b else (b, a)) if paired else None   # (smaller id, larger)
        j = index.get((a, b))
        update, delta = True, None
        if j is not None:
            geom = old_geoms[j]
            if geom is None:                              # restored from a save
                row, geom, phys = old_rows[j], inter.geom, inter.phys
            else:
                delta = geom.penetrationDepth
                if delta < 0.0:       # the law erased it after the last read, YADE made it anew
                    j, delta = None, None
                else:
                    row, phys = old_rows[j], old_physs[j]
                    update = not (asleep and pair in asleep)   # a slack zeroed pair: no work
        if j is None:
            geom, phys = inter.geom, inter.phys
            row = fresh_row(reader.stiffness, bodies, a, b, now)
            if inherited and pair in inherited:
                _start_here(row, geom, phys, cs)
        if update and _advance(row, geom, phys, delta, paired and pair in zeroed, first_touch, cs,
                               now):
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
        total = total_work(row[WORK], row[SHEAR_WORK], cs)
        if in_a:
            by_body.setdefault(a, []).append((k, 0))
            counted, share = own_share(total, row[OFFSET_A], row[SHARE_A], emin)
            if counted:
                energy[a] = energy.get(a, 0.0) + share
                if share > found.get(a, (0.0,))[0]:
                    found[a] = (share, k, 1.0, b)
        if in_b:
            by_body.setdefault(b, []).append((k, 1))
            counted, share = own_share(total, row[OFFSET_B], row[SHARE_B], emin)
            if counted:
                energy[b] = energy.get(b, 0.0) + share
                if share > found.get(b, (0.0,))[0]:
                    found[b] = (share, k, -1.0, a)
    table.set(np.array(a_list, np.int64), np.array(b_list, np.int64), None, geoms, physs, rows=rows,
              by_body=by_body, index=new_index)
    return Loading(energy, StrongestContacts(found, geoms), grew)
