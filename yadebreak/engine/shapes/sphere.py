"""A sphere breaks into a family of spheres (the paper's Section 2.4; docs/model.md, Sections
6-8): draw a family for the event's t10', place it inside the parent, insert it with the parent's
mass and momentum, give the fragments their state, and zero their artificial overlaps. The work
is proportional to the family and the parent's neighbours, never to the scene."""
from __future__ import annotations

import numpy as np

from yadebreak import model
from yadebreak.model import placement
from yadebreak.adapter.yade_api import O, utils, wrapper
from yadebreak.engine.contacts.hertz import contact_elastic_energy
from yadebreak.engine.shapes.base import Frame, Progeny, Shape


class Sphere(Shape):
    """YADE's Sphere: its size is its diameter; it breaks into a family of spheres."""

    name, plural = "sphere", "spheres"
    yade_shape = "Sphere"
    paraview_from_start = True

    def size(self, body):
        return 2.0 * body.shape.radius

    def frame(self, bodies):
        """A point per sphere, at its centre, with its radius (one pass over the bodies)."""
        ids, pos, vel, radius = [], [], [], []
        sphere = wrapper.Sphere
        for b in bodies:
            if b is not None and isinstance(b.shape, sphere):
                ids.append(b.id)
                pos.append(tuple(b.state.pos))
                vel.append(tuple(b.state.vel))
                radius.append(b.shape.radius)
        return Frame(np.array(ids, np.int64), np.array(vel, float).reshape(-1, 3),
                     np.array(pos, float).reshape(-1, 3),
                     arrays=[("radius", np.array(radius, float), "Float64")])

    def replace(self, breaking, body, bid, t10, direction, dmin):
        """A sphere's family, coarse fragments across `direction` (Shape.replace)."""
        label, table, recipe = breaking.label, breaking.table, breaking.recipe
        radius = float(table.columns["radius"][bid])
        mass = float(table.columns["mass"][bid])
        fam = recipe.families.draw(breaking.rng, t10)
        center = np.array(body.state.pos)
        radii = fam.relative_sizes * radius
        centers = placement.place_fragments(center, radius, radii, direction, breaking.rng)
        masses = placement.fragment_masses(mass, radii)
        parent_vel, parent_spin = np.array(body.state.vel), np.array(body.state.angVel)
        # the fragments' rigid field may hold more rotational energy than the parent's spin did
        # (fragments far from the centre): its spin is then scaled down to the parent's energy
        spin = parent_spin * placement.spin_scale(centers, masses, radii, center,
                                                  float(body.state.inertia[0]), parent_spin)
        vel = placement.fragment_velocities(centers, masses, center, parent_vel, spin)
        material = body.material
        carry = {} if breaking.options.contact_energy_at_break == "carried" else None
        neighbours, elastic_before = breaking.neighbours(bid, each=carry)
        kinetic_before = 0.5 * (mass * parent_vel @ parent_vel
                                + float(body.state.inertia[0]) * parent_spin @ parent_spin)
        O.bodies.erase(bid)
        breaking.zeroing.drop_body(bid)
        keep = np.arange(len(radii))
        if breaking.options.dummies == "ledger":
            # dummy fines leave the DEM: their mass, momentum and t10' go to the ledger
            for k in np.nonzero(fam.is_dummy)[0]:
                breaking.ledger.add(masses[k], 2.0 * radius, t10, label, masses[k] * vel[k])
            keep = keep[~fam.is_dummy]
        inertias = 0.4 * masses * radii ** 2
        kinetic_after = 0.5 * float(masses @ (vel * vel).sum(axis=1)
                                    + inertias.sum() * spin @ spin)
        radii, centers, masses, vel = radii[keep], centers[keep], masses[keep], vel[keep]
        damped = recipe.damped
        soft = recipe.dummy_material or material
        kinds = [soft if d else material for d in fam.is_dummy[keep].tolist()]
        new = [sphere_body(k, c, r, m, v, spin, damped)
               for k, c, r, m, v in zip(kinds, centers.tolist(), radii.tolist(), masses.tolist(),
                                        vel.tolist())]
        ids = list(O.bodies.append(new))
        breaking.add_rows(ids, label, fam.is_dummy[keep], radii, masses, t10, 2.0 * radius,
                       int(table.columns["generation"][bid]) + 1, dmin)
        held, elastic_after, pairs = (_contacts(breaking, ids, centers, radii, neighbours) if ids
                                      else (np.zeros(0), 0.0, []))
        breaking.zeroing.wake()
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
            audit["carried_energy"] = (_carry(breaking, ids, centers, radii, masses, pairs, carry,
                                              material.id) if ids else 0.0)
        smallest = {}
        for r, k in zip(radii.tolist(), kinds):
            if k.id not in smallest or r < smallest[k.id][0]:
                smallest[k.id] = (r, k)
        return Progeny(ids, fam.t10, speed_excess, list(smallest.values()), audit)


def sphere_body(material, center, radius, mass, vel, angvel, damped):
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


def _carry(breaking, ids, centers, radii, masses, pairs, held, parent_material):
    """contact_energy_at_break="carried": the parent's share (Eq. 4) of the elastic energy
    each of its contacts held (`held`: neighbour id -> J) is counted as Ek' already absorbed
    by the fragments that take that contact over: those that now overlap the neighbour
    (`pairs` of _contacts), in proportion to the Hertz energy of their overlaps, sqrt(R*)
    overlap^2.5 (the same materials on both sides), or else the fragment nearest to it (a
    sphere or a wall; the family sits inside the parent, so that a shallow contact has
    none overlapping). Their event is open from now, and the next read judges them. No
    force changes. Returns the energy carried (J)."""
    c = breaking.table.columns
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
    stiffness = breaking.reader.stiffness
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
        breaking.open_events.add(i)
    return float(energy.sum())

def _contacts(breaking, ids, centers, radii, neighbours):
    """Make the fragments' contacts (with each other and with the parent's neighbours) and
    zero their artificial overlaps: every overlap of a fresh fragment is the zero of its
    contact, so that only later loading makes force. The energy the parent's contacts held
    went into breaking it: had a child kept the parent's real overlap, that energy would push
    one fragment, often a fine one near the loaded point, and throw it many times faster than
    the impact. Every overlapping pair is inherited: the reader counts its work from now on.
    Returns the elastic energy (J) each fragment's contacts hold (0 when zeroed, but for
    local_damping's released share), the energy of all those contacts (J) and the pairs
    (fragment, other body, overlap (m), made through YADE's geometry)."""
    zeroed = breaking.options.zero_overlaps
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
            breaking.zeroing.zero_pair(a, b, ov, created=created)
        elif not created:                    # made now, as the collider would next step
            utils.createInteraction(a, b)
    breaking.reader.inherit([(a, b) for a, b, _, _ in pairs])
    held, total = np.zeros(len(ids)), 0.0
    if zeroed and breaking.zeroing.local_damping == 0.0:
        return held, total, pairs            # nothing held: no need to look
    index = {i: k for k, i in enumerate(ids)}
    for a, b, _, _ in pairs:
        energy = contact_elastic_energy(O.interactions[a, b],
                                        breaking.zeroing.pairs.get((min(a, b), max(a, b))))
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
