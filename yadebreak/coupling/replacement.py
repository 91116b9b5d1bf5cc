"""Replacing a broken sphere by its progeny (the paper's Section 2.4; docs/model.md, Sections 6-8):
draw a family for the event's t10', place it inside the parent, insert it with the parent's mass
and momentum, give the fragments their state, and zero their artificial overlaps. The work is
proportional to the family and the parent's neighbours, never to the scene.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .. import model, placement
from ._yade import O, utils, wrapper
from .state import BREAKABLE, DUMMY, UNBREAKABLE


@dataclass
class Progeny:
    """What a replacement made: fragment ids (spheres in the scene), the family's t10' (%), the
    largest fragment speed beyond the parent's rigid field (m/s), the smallest fragment radius (m,
    None if every fragment went to the ledger)."""

    ids: list
    family_t10: float
    speed_excess: float
    smallest_radius: float | None


def _neighbours(bid, zeroing):
    """The parent's neighbours and its real (force-producing) overlap (m) with each."""
    found = []
    for inter in O.interactions.withBody(bid):
        other = inter.id2 if inter.id1 == bid else inter.id1
        real = inter.geom.penetrationDepth - zeroing.artificial(bid, other)
        found.append((other, max(real, 0.0)))
    return found


def _sphere_body(material, center, radius, mass, vel, angvel, damped):
    """A sphere built directly (11 us) rather than with utils.sphere (36 us), which would also
    compute a mass and inertia we replace and pick a random colour."""
    b = wrapper.Body()
    b.shape = wrapper.Sphere(radius=radius)
    b.material = material
    b.bound = wrapper.Aabb()
    state = b.state
    state.pos = state.refPos = center
    state.mass = mass
    inertia = 0.4 * mass * radius * radius
    state.inertia = (inertia, inertia, inertia)
    state.vel = vel
    state.angVel = angvel
    if damped:
        state.isDamped = True          # global damping acts on fresh fragments only
    return b


class Replacer:
    """Replaces broken spheres; one per engine."""

    def __init__(self, options, table, rng, criteria, families, zeroing, reader, ledger,
                 pause_steps, damped):
        self.options = options         # config.Replacement
        self.table = table
        self.rng = rng
        self.criteria = criteria       # material label -> criterion
        self.families = families       # material label -> families.FamilyTable
        self.zeroing = zeroing
        self.reader = reader           # told which contacts the fragments inherit
        self.ledger = ledger
        self.pause_steps = pause_steps  # material label -> steps
        self.damped = damped           # fragments start damped (global damping)

    def replace(self, bid, t10, direction, dmin):
        """Erase body `bid` and insert its progeny for t10' (%), coarse fragments across
        `direction` (the normal of its most energetic contact)."""
        body = O.bodies[bid]
        label = self.table.label_of(bid)
        radius = float(self.table.columns["radius"][bid])
        mass = float(self.table.columns["mass"][bid])
        fam = self.families[label].draw(self.rng, t10)
        center = np.array(body.state.pos)
        radii = fam.relative_sizes * radius
        centers = placement.place_fragments(center, radius, radii, direction, self.rng)
        masses = placement.fragment_masses(mass, radii)
        vel = placement.fragment_velocities(centers, masses, center, np.array(body.state.vel),
                                            np.array(body.state.angVel))
        angvel = body.state.angVel
        # no fragment may leave faster than the parent's rigid field allows: |v| + 2 |w| r bounds
        # it (v + w x (c_i - c_cm) after the momentum shift); the event records the margin
        speed_excess = float(np.linalg.norm(vel, axis=1).max() - np.linalg.norm(body.state.vel)
                             - 2.0 * np.linalg.norm(angvel) * radius)
        material = body.material
        neighbours = _neighbours(bid, self.zeroing)
        O.bodies.erase(bid)
        self.zeroing.drop_body(bid)
        keep = np.arange(len(radii))
        if self.options.dummies == "ledger":
            # dummy fines leave the DEM: their mass, momentum and t10' go to the ledger
            for k in np.nonzero(fam.is_dummy)[0]:
                self.ledger.add(masses[k], 2.0 * radius, t10, label, masses[k] * vel[k])
            keep = keep[~fam.is_dummy]
        radii, centers, masses, vel = radii[keep], centers[keep], masses[keep], vel[keep]
        new = [_sphere_body(material, c, r, m, v, angvel, self.damped)
               for c, r, m, v in zip(centers.tolist(), radii.tolist(), masses.tolist(),
                                     vel.tolist())]
        ids = list(O.bodies.append(new))
        self._new_rows(ids, label, fam.is_dummy[keep], radii, masses, t10, 2.0 * radius,
                       int(self.table.columns["generation"][bid]) + 1, dmin)
        if self.options.zero_overlaps and ids:
            self._zero(ids, centers, radii, neighbours)
        self.zeroing.wake()
        return Progeny(ids, fam.t10, speed_excess, float(radii.min()) if ids else None)

    def _new_rows(self, ids, label, is_dummy, radii, masses, t10, parent_size, generation, dmin):
        """The fragments' state: dummy, unbreakable (its own progeny would be finer than dmin)
        or breakable, with fracture energies drawn at their own sizes (unbreakable ones too:
        their first would-be breakage gives the t10' they keep)."""
        if not ids:
            return
        kinds = np.where(is_dummy, DUMMY,
                         np.where(model.X_MIN * 2.0 * radii < dmin, UNBREAKABLE, BREAKABLE))
        values = {"generation": generation}
        pause = self.pause_steps[label]
        if pause:
            values["pause_until"] = O.iter + pause
        self.table.add(ids, kinds, label, masses, radii, **values)
        ids = np.asarray(ids)
        dummies = ids[is_dummy]
        self.table.columns["t10"][dummies] = t10
        self.table.columns["parent_size"][dummies] = parent_size
        need = np.nonzero(~is_dummy)[0]
        if len(need):
            energies, extra = self.criteria[label].sample(self.rng, 2.0 * radii[need])
            c = self.table.columns
            c["fracture_energy"][ids[need]] = energies
            c["fracture_energy_initial"][ids[need]] = energies
            for name, value in extra.items():
                c[name][ids[need]] = value

    def _zero(self, ids, centers, radii, neighbours):
        """Zero the artificial overlaps: between siblings entirely; with each neighbour of the
        parent, the child overlapping it most keeps the parent's real overlap as real force and
        everything beyond it is zeroed, while the other children's overlaps with that neighbour
        are zeroed entirely (else k children would each press with the parent's overlap and
        multiply the force the parent carried). Every overlapping pair is inherited: the reader
        counts its work from now on."""
        zero = self.zeroing.zero_pair
        inherited = []
        ii, jj, overlap = placement.overlapping_pairs(centers, radii)
        for a, b, ov in zip(ii, jj, overlap):
            zero(ids[a], ids[b], float(ov), created=False)
            inherited.append((ids[a], ids[b]))
        for other, real in neighbours:
            ob = O.bodies[other]
            if ob is None:
                continue
            if isinstance(ob.shape, wrapper.Sphere):
                ov = radii + ob.shape.radius - np.linalg.norm(centers - np.array(ob.state.pos),
                                                              axis=1)
                created = False
            else:                                # walls, facets: ask YADE's own geometry
                ov = np.array([_overlap_with(i, other) for i in ids])
                created = True
            touching = np.nonzero(ov > 0.0)[0]
            if len(touching) == 0:
                continue
            keeper = touching[np.argmax(ov[touching])]
            for k in touching:
                inherited.append((ids[k], other))
                artificial = ov[k] - real if k == keeper else ov[k]
                if artificial > 0.0:
                    zero(ids[k], other, float(artificial), created=created)
        self.reader.inherit(inherited)


def _overlap_with(fragment, other):
    """A fragment's overlap (m) with a wall or facet, through an interaction made now; -1 where
    YADE finds no contact geometry for the pair."""
    try:
        return utils.createInteraction(fragment, other).geom.penetrationDepth
    except RuntimeError:               # YADE: "no contact geometry" for a pair that does not touch
        return -1.0
