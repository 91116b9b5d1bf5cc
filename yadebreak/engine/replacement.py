"""Replacing a broken sphere by its progeny (the paper's Section 2.4; docs/model.md, Sections 6-8):
draw a family for the event's t10', place it inside the parent, insert it with the parent's mass
and momentum, give the fragments their state, and zero their artificial overlaps. The work is
proportional to the family and the parent's neighbours, never to the scene.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from yadebreak import model
from yadebreak.model import placement
from yadebreak.adapter.yade_api import O, utils, wrapper
from yadebreak.engine.cells_replacement import CellBreakage
from yadebreak.engine.state import BREAKABLE, DUMMY, UNBREAKABLE


@dataclass
class Progeny:
    """What a replacement made: fragment ids (spheres in the scene), the family's t10' (%), the
    largest fragment speed beyond the parent's rigid field (m/s), the smallest fragment of each
    YADE material among them as [(radius (m), material)] (empty if every fragment went to the
    ledger; what the time step needs), and the energy audit (J): kinetic and elastic energy of
    the parent just before, of the progeny just after (see Replacer.replace)."""

    ids: list
    family_t10: float
    speed_excess: float
    smallest: list
    audit: dict


def contact_elastic_energy(inter, zeroed):
    """Elastic energy (J) a Hertz-Mindlin contact holds: 0.4 kno0 (d - d0)^2.5 in the normal
    direction (Fn = kno0 (d - d0)^1.5, d0 its zeroed overlap, if any; none while the zeroing
    holds it slack, kno = 0) plus |Fs|^2 / (2 ks) of the elastic shear force (the law's
    shearForce adds the viscous part)."""
    phys, d = inter.phys, inter.geom.penetrationDepth
    kno0, d0 = (zeroed.kno0, zeroed.artificial) if zeroed is not None else (phys.kno, 0.0)
    if phys.kno == 0.0:
        kno0 = 0.0                    # a slack zeroed pair (asleep too): it makes no force
    energy = 0.4 * kno0 * max(d - d0, 0.0) ** 2.5
    if phys.ks > 0.0:
        energy += 0.5 * phys.shearElastic.squaredNorm() / phys.ks
    return energy


def _neighbours(bid, zeroing, reader=None, each=None):
    """The parent's neighbours (ids) and the elastic energy (J) of its contacts with them (on
    the volumetric law, what the reader's rows hold); `each` (a dict), if given, receives the
    energy of each neighbour's contact."""
    if reader is not None and reader.volumetric:
        found = [i.id2 if i.id1 == bid else i.id1 for i in O.interactions.withBody(bid)]
        return found, reader.held(bid)
    found, energy = [], 0.0
    for inter in O.interactions.withBody(bid):
        other = inter.id2 if inter.id1 == bid else inter.id1
        found.append(other)
        held = contact_elastic_energy(inter,
                                      zeroing.pairs.get((min(bid, other), max(bid, other))))
        energy += held
        if each is not None:
            each[other] = held
    return found, energy


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
    if damped is not None:
        # global damping acts on fragments of damped materials only (without any, YADE's
        # default is left as it always was)
        state.isDamped = damped
    return b


@dataclass(frozen=True)
class Recipe:
    """How the progeny of one breakable material are made."""

    criterion: object      # draws the fragments' fracture energies (criteria.Criterion)
    families: object       # model.families.FamilyTable: the family of an event's t10'
    pause_steps: int       # steps a fresh fragment is not judged (0: none)
    damped: object         # True/False: fragments start damped (global damping); None: no
    #                        material of the scene is damped (YADE's default is left alone)
    dummy_material: object  # YADE material of its dummies (a softer one), None: its own


class Replacer:
    """Replaces broken bodies, by the parent's shape: a sphere by a family of spheres, a convex
    polyhedron by its cells (cells_replacement); one per engine."""

    def __init__(self, options, state, recipes, zeroing, reader):
        self.options = options         # config.Replacement
        self.state = state
        self.table = state.table
        self.rng = state.rng
        self.ledger = state.ledger
        self.recipes = recipes         # material label -> Recipe
        self.zeroing = zeroing
        self.reader = reader           # told which contacts the fragments inherit
        self.cells = CellBreakage(self)

    def replace(self, bid, t10, direction, dmin):
        """Erase body `bid` and insert its progeny for t10' (%): a polyhedron's cells, or a
        sphere's family, coarse fragments across `direction` (the normal of its most energetic
        contact). Returns a Progeny."""
        body = O.bodies[bid]
        if isinstance(body.shape, wrapper.Polyhedra):
            neighbours, elastic = _neighbours(bid, self.zeroing, self.reader)
            return Progeny(*self.cells.replace(bid, t10, dmin, elastic, neighbours))
        return self._replace_sphere(body, bid, t10, direction, dmin)

    def _replace_sphere(self, body, bid, t10, direction, dmin):
        """A sphere's family (replace)."""
        label = self.table.label_of(bid)
        radius = float(self.table.columns["radius"][bid])
        mass = float(self.table.columns["mass"][bid])
        recipe = self.recipes[label]
        fam = recipe.families.draw(self.rng, t10)
        center = np.array(body.state.pos)
        radii = fam.relative_sizes * radius
        centers = placement.place_fragments(center, radius, radii, direction, self.rng)
        masses = placement.fragment_masses(mass, radii)
        parent_vel, parent_spin = np.array(body.state.vel), np.array(body.state.angVel)
        # the fragments' rigid field may hold more rotational energy than the parent's spin did
        # (fragments far from the centre): its spin is then scaled down to the parent's energy
        spin = parent_spin * placement.spin_scale(centers, masses, radii, center,
                                                  float(body.state.inertia[0]), parent_spin)
        vel = placement.fragment_velocities(centers, masses, center, parent_vel, spin)
        material = body.material
        carry = {} if self.options.contact_energy_at_break == "carried" else None
        neighbours, elastic_before = _neighbours(bid, self.zeroing, each=carry)
        kinetic_before = 0.5 * (mass * parent_vel @ parent_vel
                                + float(body.state.inertia[0]) * parent_spin @ parent_spin)
        O.bodies.erase(bid)
        self.zeroing.drop_body(bid)
        keep = np.arange(len(radii))
        if self.options.dummies == "ledger":
            # dummy fines leave the DEM: their mass, momentum and t10' go to the ledger
            for k in np.nonzero(fam.is_dummy)[0]:
                self.ledger.add(masses[k], 2.0 * radius, t10, label, masses[k] * vel[k])
            keep = keep[~fam.is_dummy]
        inertias = 0.4 * masses * radii ** 2
        kinetic_after = 0.5 * float(masses @ (vel * vel).sum(axis=1)
                                    + inertias.sum() * spin @ spin)
        radii, centers, masses, vel = radii[keep], centers[keep], masses[keep], vel[keep]
        damped = recipe.damped
        soft = recipe.dummy_material or material
        kinds = [soft if d else material for d in fam.is_dummy[keep].tolist()]
        new = [_sphere_body(k, c, r, m, v, spin, damped)
               for k, c, r, m, v in zip(kinds, centers.tolist(), radii.tolist(), masses.tolist(),
                                        vel.tolist())]
        ids = list(O.bodies.append(new))
        self.new_rows(ids, label, fam.is_dummy[keep], radii, masses, t10, 2.0 * radius,
                       int(self.table.columns["generation"][bid]) + 1, dmin)
        held, elastic_after, pairs = (self._contacts(ids, centers, radii, neighbours) if ids
                                      else (np.zeros(0), 0.0, []))
        self.zeroing.wake()
        # no fragment may leave faster than the parent's rigid field allows, |v| + 2 |w| R
        # (v + w x (c_i - c_cm) after the momentum shift), counting the energy its contacts can
        # still give it; the event records the margin (> 0 only with local_damping)
        reach = np.sqrt((vel * vel).sum(axis=1) + 2.0 * held / masses) if ids else np.zeros(1)
        speed_excess = float(reach.max() - np.linalg.norm(parent_vel)
                             - 2.0 * np.linalg.norm(parent_spin) * radius)
        audit = {"kinetic_energy_before": float(kinetic_before),
                 "elastic_energy_before": float(elastic_before),
                 "kinetic_energy_after": kinetic_after,
                 "elastic_energy_after": elastic_after}
        if carry is not None:
            audit["carried_energy"] = (self._carry(ids, centers, radii, masses, pairs, carry,
                                                   material.id) if ids else 0.0)
        smallest = {}
        for r, k in zip(radii.tolist(), kinds):
            if k.id not in smallest or r < smallest[k.id][0]:
                smallest[k.id] = (r, k)
        return Progeny(ids, fam.t10, speed_excess, list(smallest.values()), audit)

    def new_rows(self, ids, label, is_dummy, radii, masses, t10, parent_size, generation, dmin):
        """The fragments' state: dummy, unbreakable (its own progeny would be finer than dmin)
        or breakable, with fracture energies drawn at their own sizes (unbreakable ones too:
        their first would-be breakage gives the t10' they keep)."""
        if not ids:
            return
        kinds = np.where(is_dummy, DUMMY,
                         np.where(model.X_MIN * 2.0 * radii < dmin, UNBREAKABLE, BREAKABLE))
        values = {"generation": generation}
        recipe = self.recipes[label]
        pause = recipe.pause_steps
        if pause:
            values["pause_until"] = O.iter + pause
        self.table.add(ids, kinds, label, masses, radii, **values)
        ids = np.asarray(ids)
        dummies = ids[is_dummy]
        self.table.columns["t10"][dummies] = t10
        self.table.columns["parent_size"][dummies] = parent_size
        need = np.nonzero(~is_dummy)[0]
        if len(need):
            energies, extra = recipe.criterion.sample(self.rng, 2.0 * radii[need])
            c = self.table.columns
            c["fracture_energy"][ids[need]] = energies
            c["fracture_energy_initial"][ids[need]] = energies
            for name, value in extra.items():
                c[name][ids[need]] = value

    def _carry(self, ids, centers, radii, masses, pairs, held, parent_material):
        """contact_energy_at_break="carried": the parent's share (Eq. 4) of the elastic energy
        each of its contacts held (`held`: neighbour id -> J) is counted as Ek' already absorbed
        by the fragments that take that contact over: those that now overlap the neighbour
        (`pairs` of _contacts), in proportion to the Hertz energy of their overlaps, sqrt(R*)
        overlap^2.5 (the same materials on both sides), or else the fragment nearest to it (a
        sphere or a wall; the family sits inside the parent, so that a shallow contact has
        none overlapping). Their event is open from now, and the next read judges them. No
        force changes. Returns the energy carried (J)."""
        c = self.table.columns
        index = {i: k for k, i in enumerate(ids)}
        weights = {}                          # neighbour -> [(fragment row, weight)]
        for a, other, overlap, _ in pairs:
            if other not in held:             # a pair of fragments
                continue
            k = index[a]
            r = float(radii[k])
            ob = O.bodies[other]
            if isinstance(ob.shape, wrapper.Sphere):
                r = r * ob.shape.radius / (r + ob.shape.radius)
            weights.setdefault(other, []).append((k, np.sqrt(r) * overlap ** 2.5))
        for other in held:
            if other not in weights and held[other] > 0.0:
                k = _nearest(O.bodies[other], centers, radii)
                if k is not None:
                    weights[other] = [(k, 1.0)]
        stiffness = self.reader.stiffness
        energy = np.zeros(len(ids))
        for other, shares in weights.items():
            partner = stiffness[O.bodies[other].material.id]
            share = float(model.energy_partition(stiffness[parent_material], partner))
            total = sum(w for _, w in shares)
            for k, w in shares:
                energy[k] += share * held[other] * w / total
        got = np.flatnonzero(energy > 0.0)
        for k in got.tolist():
            i = ids[k]
            c["carried"][i] = energy[k]
            c["specific_energy"][i] = energy[k] / float(masses[k])   # no jump at the next read
            self.state.open_events.add(i)
        return float(energy.sum())

    def _contacts(self, ids, centers, radii, neighbours):
        """Make the fragments' contacts (with each other and with the parent's neighbours) and
        zero their artificial overlaps: every overlap of a fresh fragment is the zero of its
        contact, so that only later loading makes force. The energy the parent's contacts held
        went into breaking it: had a child kept the parent's real overlap, that energy would push
        one fragment, often a fine one near the loaded point, and throw it many times faster than
        the impact. Every overlapping pair is inherited: the reader counts its work from now on.
        Returns the elastic energy (J) each fragment's contacts hold (0 when zeroed, but for
        local_damping's released share), the energy of all those contacts (J) and the pairs
        (fragment, other body, overlap (m), made through YADE's geometry)."""
        zeroed = self.options.zero_overlaps
        pairs = []
        ii, jj, overlap = placement.overlapping_pairs(centers, radii)
        for a, b, ov in zip(ii, jj, overlap):
            pairs.append((ids[a], ids[b], float(ov), False))
        for other in neighbours:
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
            for k in np.nonzero(ov > 0.0)[0]:
                pairs.append((ids[k], other, float(ov[k]), created))
        for a, b, ov, created in pairs:
            if zeroed:
                self.zeroing.zero_pair(a, b, ov, created=created)
            elif not created:                    # made now, as the collider would next step
                utils.createInteraction(a, b)
        self.reader.inherit([(a, b) for a, b, _, _ in pairs])
        held, total = np.zeros(len(ids)), 0.0
        if zeroed and self.zeroing.local_damping == 0.0:
            return held, total, pairs            # nothing held: no need to look
        index = {i: k for k, i in enumerate(ids)}
        for a, b, _, _ in pairs:
            energy = contact_elastic_energy(O.interactions[a, b],
                                            self.zeroing.pairs.get((min(a, b), max(a, b))))
            total += energy
            for i in (a, b):
                if i in index:
                    held[index[i]] += energy
        return held, total, pairs


def _nearest(body, centers, radii):
    """The row of the fragment whose surface is nearest to `body` (a sphere or a wall; None for
    other shapes or a body gone)."""
    if body is None:
        return None
    if isinstance(body.shape, wrapper.Sphere):
        gap = np.linalg.norm(centers - np.array(body.state.pos), axis=1) - body.shape.radius
    elif isinstance(body.shape, wrapper.Wall):
        axis = body.shape.axis
        gap = np.abs(centers[:, axis] - body.state.pos[axis])
    else:
        return None
    return int(np.argmin(gap - radii))


def _overlap_with(fragment, other):
    """A fragment's overlap (m) with a wall or facet, through an interaction made now; -1 where
    YADE finds no contact geometry for the pair."""
    try:
        return utils.createInteraction(fragment, other).geom.penetrationDepth
    except RuntimeError:               # YADE: "no contact geometry" for a pair that does not touch
        return -1.0
