"""A convex polyhedron (a YADE Polyhedra body) breaks into the convex cells it splits into
(model.cells.fragment_cells at the event's t10'): every cell finer than the smallest resolved
size, as the spheres' dummy class (X_MIN of the parent's size), goes to the fines ledger; the
others become Polyhedra bodies of the parent's YADE material. The cells tile the parent, so
mass and volume are the parent's; each cell moves with the parent's rigid field (v + w x r at
its centroid, spin w), so momentum, angular momentum and kinetic energy are the parent's too
(ledger included: its cells' translation in its momenta, their spin in the audit).
"""
from __future__ import annotations

from typing import NamedTuple

import numpy as np

from yadebreak import model
from yadebreak.model.cells import fragment_cells, polyhedron_mass_properties, sieve_size
from yadebreak.adapter.yade_api import Matrix3, O, Quaternion, Vector3, wrapper
from yadebreak.engine.shapes.base import Frame, Progeny, Shape


class Pose(NamedTuple):
    """A rigid body's pose and motion: rotation matrix (body to world), centroid (m), velocity
    (m/s), angular velocity (rad/s, world)."""
    rotation: np.ndarray
    position: np.ndarray
    velocity: np.ndarray
    spin: np.ndarray


class Cells(NamedTuple):
    """The cells of one breakage in the world frame: vertices relative to each cell's centroid
    (list of (k, 3), m), centroids (n, 3), masses (kg), velocities (n, 3), inertia tensors about
    the centroid (n, 3, 3), sieve sizes (m); `resolved` marks the cells that become bodies."""
    vertices: list
    centroids: np.ndarray
    masses: np.ndarray
    velocities: np.ndarray
    inertias: np.ndarray
    sieve_sizes: np.ndarray
    resolved: np.ndarray


def pose_of(body):
    """The Pose of a YADE body now."""
    s = body.state
    return Pose(np.array(s.ori.toRotationMatrix()), np.array(s.pos), np.array(s.vel),
                np.array(s.angVel))


def body_kinetic_energy(body):
    """Kinetic energy (J) of a YADE body: translation plus rotation about its principal axes
    (state.inertia, in the frame state.ori)."""
    s = body.state
    local = np.array(s.ori.conjugate() * s.angVel)
    return 0.5 * (s.mass * s.vel.squaredNorm() + float(np.array(s.inertia) @ (local * local)))


def world_cells(frag, pose, mass, min_volume_fraction=0.0):
    """The Cells of a Fragmentation made in the parent's body frame (centred on its centroid),
    carried by `pose`: rotated, translated, moving with the parent's rigid field. Masses split
    the parent's `mass` (kg) by volume, so that they sum to it to round-off. A cell of less
    volume than `min_volume_fraction` times the cube of the smallest resolved size is not
    resolved (Rocky's Minimum Volume Fraction for Fragment Disabling: its mass goes to the
    ledger)."""
    local = list(frag.vertices) + list(frag.ledger_vertices)
    volumes = np.concatenate([frag.volumes, frag.ledger_volumes])
    centroids = np.concatenate([frag.centroids, frag.ledger_centroids]).reshape(-1, 3)
    masses = mass * volumes / volumes.sum()
    rot = pose.rotation
    arms = centroids @ rot.T                       # centroid minus the parent's, world frame
    inertias = np.empty((len(local), 3, 3))
    for k, verts in enumerate(local):
        _, _, unit = polyhedron_mass_properties(verts)
        inertias[k] = rot @ unit @ rot.T * (masses[k] / volumes[k])
    resolved = ((np.arange(len(local)) < len(frag.vertices))
                & (volumes >= min_volume_fraction * frag.smallest_size ** 3))
    return Cells([(v - c) @ rot.T for v, c in zip(local, centroids)], pose.position + arms, masses,
                 pose.velocity + np.cross(pose.spin, arms), inertias,
                 np.concatenate([frag.sieve_sizes, frag.ledger_sieve_sizes]), resolved)


def cells_kinetic_energy(cells, spin):
    """Kinetic energy (J) of the cells: 0.5 m |v|^2 + 0.5 w.I w, summed (ledger cells too)."""
    translation = float(cells.masses @ (cells.velocities ** 2).sum(axis=1))
    rotation = float(np.einsum("i,kij,j->", spin, cells.inertias, spin))
    return 0.5 * (translation + rotation)


#: YADE's Polyhedra turns a shape to its principal axes only when the off-diagonal products of
#: inertia per unit density (m^5) sum to more than this (pkg/dem/Polyhedra.cpp, Initialize)
YADE_TURN_THRESHOLD = 1e-13


def principal_axes(vertices):
    """The principal axes (columns, a right-handed rotation) of the hull of `vertices`."""
    _, _, inertia = polyhedron_mass_properties(vertices)
    _, axes = np.linalg.eigh(inertia)
    if np.linalg.det(axes) < 0.0:
        axes[:, 2] = -axes[:, 2]
    return axes


def skipped_turn(vertices):
    """The principal axes of the hull of `vertices` (centred on its centroid) where YADE would
    not turn the shape to them though its inertia is not diagonal (YADE_TURN_THRESHOLD); None
    where YADE's own turn is right."""
    _, _, inertia = polyhedron_mass_properties(vertices)
    off = abs(inertia[0, 1]) + abs(inertia[0, 2]) + abs(inertia[1, 2])
    if off >= YADE_TURN_THRESHOLD or off <= 1e-12 * np.trace(inertia):
        return None
    return principal_axes(vertices)


def cell_body(material, vertices, centroid, mass, velocity, spin, damped):
    """A Polyhedra body of `vertices` (relative to its centroid, world frame) at `centroid`, its
    inertia scaled to `mass`. The shape is given to YADE in its principal axes: YADE turns a
    shape to them only when the off-diagonal products of inertia per unit density sum to more
    than YADE_TURN_THRESHOLD (an absolute one), and takes the diagonal as the principal moments
    otherwise, 15-35 % off for the cells of a 20 mm parent (measured). Aspherical bodies are
    integrated from their angular momentum: it is set from `spin`."""
    axes = principal_axes(vertices)
    b = wrapper.Body()
    b.aspherical = True
    b.shape = wrapper.Polyhedra(v=[Vector3(*p) for p in (vertices @ axes).tolist()])
    b.material = material
    b.bound = wrapper.Aabb()
    s = b.state
    s.mass = mass
    s.inertia = b.shape.GetInertia() * (mass / b.shape.GetVolume())
    s.ori = Quaternion(Matrix3(*axes.ravel().tolist())) * b.shape.GetOri()
    s.pos = s.refPos = Vector3(*centroid)
    s.vel = Vector3(*velocity)
    s.angVel = Vector3(*spin)
    rot = np.array(s.ori.toRotationMatrix())
    s.angMom = Vector3(*(rot @ (np.array(s.inertia) * (rot.T @ np.asarray(spin)))))
    if damped is not None:
        s.isDamped = damped
    return b


class Polyhedron(Shape):
    """YADE's Polyhedra (convex): its size is its sieve size (model.cells.sieve_size: 2 radius
    is the size of Eq. 3 and of the t10 sieves, as a sphere's diameter is); it breaks into the
    cells of model.cells.fragment_cells."""

    name, plural = "polyhedron", "polyhedra"
    yade_shape = "Polyhedra"

    def size(self, body):
        return sieve_size([tuple(v) for v in body.shape.v])

    def frame(self, bodies):
        """Each polyhedron's faces as polygons over its vertices where they are now, with its
        volume."""
        ids, vel, volume, points, faces, owner = [], [], [], [], [], []
        for b in bodies:
            if b is None or not isinstance(b.shape, wrapper.Polyhedra):
                continue
            first = len(points)
            pos, ori = b.state.pos, b.state.ori
            points.extend(tuple(pos + ori * v) for v in b.shape.v)
            for face in b.shape.GetSurfaces():
                faces.append([first + int(k) for k in face])
                owner.append(len(ids))
            ids.append(b.id)
            vel.append(tuple(b.state.vel))
            volume.append(b.shape.GetVolume())
        return Frame(np.array(ids, np.int64), np.array(vel, float).reshape(-1, 3),
                     np.array(points, float).reshape(-1, 3), faces, np.array(owner, np.int64),
                     [("volume", np.array(volume, float), "Float64")])

    def replace(self, breaking, body, bid, t10, direction, dmin):
        """Erase polyhedron `bid` and insert its cells for t10' (%) (Shape.replace; the cells
        take no direction). The parent's neighbours' contacts with the cells count work from
        the state they start in (the reader's inherit). No contact is made here
        (elastic_energy_after 0): the collider finds the cells' contacts. They touch face to
        face: on the volumetric law a shared face makes no force; through
        Ig2_Polyhedra_Polyhedra_ScGeom they start with an overlap and fly apart
        (docs/polyhedra.md)."""
        rep = breaking
        neighbours, elastic_before = rep.neighbours(bid)
        table, label, recipe = rep.table, rep.label, rep.recipe
        mass = float(table.columns["mass"][bid])
        parent_size = 2.0 * float(table.columns["radius"][bid])
        pose = pose_of(body)
        local = np.array([tuple(v) for v in body.shape.v])
        frag = fragment_cells(rep.rng, local, t10, recipe.families.beta_params,
                              model.X_MIN * parent_size)
        cells = world_cells(frag, pose, mass, rep.options.min_volume_fraction)
        material = body.material
        kinetic_before = body_kinetic_energy(body)
        O.bodies.erase(bid)
        rep.zeroing.drop_body(bid)
        for k in np.flatnonzero(~cells.resolved):
            rep.ledger.add(cells.masses[k], parent_size, t10, label,
                           cells.masses[k] * cells.velocities[k])
        keep = np.flatnonzero(cells.resolved)
        new = [cell_body(material, cells.vertices[k], cells.centroids[k], cells.masses[k],
                         cells.velocities[k], pose.spin, recipe.damped) for k in keep]
        ids = list(O.bodies.append(new)) if new else []
        rep.reader.inherit([(i, n) for i in ids for n in neighbours], rep.options.zero_overlaps)
        radii = 0.5 * cells.sieve_sizes[keep]
        rep.add_rows(ids, label, np.zeros(len(ids), bool), radii, cells.masses[keep], t10,
                     parent_size, int(table.columns["generation"][bid]) + 1, dmin)
        reach = np.linalg.norm(local, axis=1).max()
        speed = np.linalg.norm(cells.velocities[keep], axis=1).max() if ids else 0.0
        excess = float(speed - np.linalg.norm(pose.velocity) - np.linalg.norm(pose.spin) * reach)
        audit = {"kinetic_energy_before": float(kinetic_before),
                 "elastic_energy_before": float(elastic_before),
                 "kinetic_energy_after": cells_kinetic_energy(cells, pose.spin),
                 "elastic_energy_after": 0.0}
        return Progeny(ids, float(t10), excess, self._smallest(cells, keep, material), audit)

    @staticmethod
    def _smallest(cells, keep, material):
        """[(radius, material)] of the finest cell for the time step: the smaller of half its
        sieve size and its volume-equivalent radius (a flat cell is thinner than it sieves)."""
        if not len(keep):
            return []
        volume = cells.masses[keep] / material.density
        equivalent = np.cbrt(3.0 * volume / (4.0 * np.pi))
        radius = np.minimum(0.5 * cells.sieve_sizes[keep], equivalent)
        return [(float(radius.min()), material)]
