"""Scenes of convex polyhedra (YADE's Polyhedra bodies) on the Hertz-Mindlin law: materials, bodies
from vertices, a plate as a fixed polyhedron, the engine list, and a single impact of a
polyhedron on a plate, face, edge or corner first. YADE layer.

Which law (benchmarks/polyhedra_contact_law.py, docs/polyhedra.md): Ig2_Polyhedra_Polyhedra_ScGeom
fixes two radii at first touch (each centre to the intersection's centroid) and then treats the
pair as two spheres: overlap r1 + r2 - |x2 - x1|, normal along the line of centres. Where the
contact point lies on that line (a cube face, edge or corner first above the plate's centre) the
energy is conserved to 1e-5 and the engine's reader counts it; anywhere else the overlap at first
touch is far from zero and the impact blows up (a random convex body: 5 to 1e5 times the energy
fired; edge first it passed through the plate). YADE's volumetric law conserves energy on every
case measured; the engine reads it (engine/contacts/volumetric.py) and the breakage scenes of
polyhedra use it (volumetric_impact_scene).
"""
from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from yadebreak.adapter.yade_api import Matrix3, O, Quaternion, Vector3, utils, wrapper as _w
from yadebreak.engine import add_materials, attach
from yadebreak.engine.contacts.volumetric import STEP_FRACTION
from yadebreak.engine.shapes.polyhedron import skipped_turn
from yadebreak.engine.state import TrackedBodies
from yadebreak import model
from yadebreak.model import placement
from yadebreak.model.cells import convex_polyhedron, random_convex_vertices, sieve_size

#: the three ways a body can meet a plate first (orientation())
CONTACTS = ("face", "edge", "corner")


def polyhedra_materials(labels, stiffness_scale=1.0, volumetric=False, size=None):
    """YADE materials for the labels (material files) and the Hertz-Mindlin Ip2 with the files'
    restitution and friction per pair (add_materials): FrictMat, as for spheres. Not
    PolyhedraMat: its `young` is a member of its own that hides FrictMat's, so the Hertz-Mindlin
    Ip2 reads the hidden default, 1 GPa (measured: a copper ore cube on a steel plate got kno =
    5.1e7 instead of 4.2e9 N/m^1.5). volumetric: PolyhedraMat (the volumetric law reads its
    `young` as kn, N/m3), with `size` (m) each kn = Y / (1 - nu^2) / size of its file (a pair
    in series then has E* / size, and Eq. 4's shares those of Hertz); without, the Young's
    modulus (set kn afterwards). Returns (ip2, {label: Material})."""
    kind = "PolyhedraMat" if volumetric else "FrictMat"
    ip2, mats = add_materials(labels, stiffness_scale=stiffness_scale,
                              kinds={label: kind for label in labels})
    if volumetric and size is not None:
        for label, mat in mats.items():
            _material(label).young = stiffness_scale * mat.hertz_stiffness / float(size)
    return ip2, mats


def elastic(ip2):
    """The Ip2 with every restitution set to 1 (no dashpot: Mindlin's beta is 0 at en = 1), for
    energy checks; friction kept. Returns ip2."""
    for name in ("en", "es"):
        maker = getattr(ip2, name)
        rows = [(int(a), int(b), 1.0) for a, b, _ in maker.matches]
        setattr(ip2, name, _w.MatchMaker(matches=rows))
    return ip2


def _material(label):
    found = [m for m in O.materials if m.label == label]
    if not found:
        raise KeyError(f"no YADE material labelled {label!r}")
    return found[0]


def polyhedron(vertices, material, position=(0.0, 0.0, 0.0), velocity=(0.0, 0.0, 0.0),
               fixed=False):
    """A body of the convex hull of `vertices` (n x 3, m; any frame) with YADE material label
    `material`, its centroid at `position`. YADE re-centres the shape on its centroid, turns it
    to its principal axes and gives its volume and inertia exactly; mass and inertia are those
    times the density. `fixed`: every degree of freedom blocked (a plate). Not appended.
    A small body, whose turn to its principal axes YADE skips
    (engine.shapes.polyhedron.skipped_turn), is given to YADE in them."""
    mat = _material(material)
    pts = np.asarray(vertices, dtype=float)
    centred = pts - convex_polyhedron(pts).centroid
    axes = skipped_turn(centred)
    if axes is not None:
        pts = centred @ axes
    body = _w.Body()
    body.aspherical = True
    body.shape = _w.Polyhedra(v=[Vector3(*map(float, v)) for v in pts])
    body.material = mat
    body.state.mass = mat.density * body.shape.GetVolume()
    body.state.inertia = body.shape.GetInertia() * mat.density
    body.state.ori = body.shape.GetOri()
    if axes is not None:
        body.state.ori = Quaternion(Matrix3(*axes.ravel().tolist())) * body.state.ori
    body.state.pos = Vector3(*map(float, position))
    body.state.vel = Vector3(*map(float, velocity))
    if fixed:
        body.state.blockedDOFs = "xyzXYZ"
    return body


def box_vertices(a, b, c):
    """The 8 corners of a box a x b x c (m) centred on the origin, edges along the axes."""
    return np.array([(x, y, z) for x in (-a / 2, a / 2) for y in (-b / 2, b / 2)
                     for z in (-c / 2, c / 2)])


def plate(material, side=0.1, thickness=0.01, top=0.0, centre=(0.0, 0.0)):
    """A fixed square plate (a polyhedron) whose top face lies at z = top, centred on `centre`
    (x, y). Not appended. With Ig2_Polyhedra_Polyhedra_ScGeom the normal of a contact is the
    line of centres: a body must hit the plate above its centre to be pushed straight up."""
    return polyhedron(box_vertices(side, side, thickness), material,
                      (centre[0], centre[1], top - thickness / 2.0), fixed=True)


def _rotation_to_down(direction):
    """The rotation matrix that takes the unit vector `direction` to -z."""
    a = np.asarray(direction, float) / np.linalg.norm(direction)
    b = np.array([0.0, 0.0, -1.0])
    v, c = np.cross(a, b), float(a @ b)
    if c < -1.0 + 1e-12:                       # a = +z: half a turn about x
        return np.diag([1.0, -1.0, -1.0])
    vx = np.array([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])
    return np.eye(3) + vx + vx @ vx / (1.0 + c)


def orientation(vertices, contact):
    """`vertices` (centred on the centroid) turned so that one face, edge or corner (`contact`,
    one of CONTACTS) is the lowest feature: the face nearest the centroid with its outward
    normal down; the edge between the two faces whose shared edge lies farthest from the
    centroid, down along the sum of their normals (inside the edge's normal cone, so the edge
    alone is lowest); the vertex farthest from the centroid, down along its direction (it alone
    is the support point there). Returns the turned vertices (n x 3)."""
    from scipy.spatial import ConvexHull
    pts = np.asarray(vertices, float)
    hull = ConvexHull(pts)
    normals, offsets = hull.equations[:, :3], -hull.equations[:, 3]    # n . x <= offset
    if contact == "face":
        down = normals[int(np.argmin(offsets))]
    elif contact == "corner":
        down = pts[int(np.argmax(np.linalg.norm(pts, axis=1)))]
    elif contact == "edge":
        down = _edge_direction(pts, normals)
    else:
        raise ValueError(f"contact = {contact!r}: accepted {CONTACTS}")
    return pts @ _rotation_to_down(down).T


def _edge_direction(pts, normals):
    """The sum of the normals of the two distinct face planes that meet on the edge farthest
    from the centroid (its midpoint's distance)."""
    planes = np.unique(np.round(normals, 9), axis=0)
    best, found = -1.0, None
    for i in range(len(planes)):
        for j in range(i + 1, len(planes)):
            on_i = np.abs(pts @ planes[i] - np.max(pts @ planes[i])) < 1e-9 * np.ptp(pts)
            on_j = np.abs(pts @ planes[j] - np.max(pts @ planes[j])) < 1e-9 * np.ptp(pts)
            shared = pts[on_i & on_j]
            if len(shared) == 2:
                reach = float(np.linalg.norm(shared.mean(axis=0)))
                if reach > best:
                    best, found = reach, planes[i] + planes[j]
    return found


def polyhedra_engines(ip2, gravity=(0.0, 0.0, 0.0), verlet_dist=0.0, label="law"):
    """The Hertz-Mindlin engine list for polyhedra: polyhedra among themselves through
    Ig2_Polyhedra_Polyhedra_ScGeom (YADE: EXPERIMENTAL), a ball on polyhedra through
    Ig2_Sphere_Polyhedra_ScGeom, spheres among themselves; Ip2 `ip2` (polyhedra_materials);
    undamped Newton. Walls and facets meet polyhedra only through the volumetric law
    (volumetric_engines): a plate here is a fixed polyhedron. verlet_dist (m): the collider's
    (its default is a fraction of the smallest sphere's radius, 0 without spheres)."""
    return [
        _w.ForceResetter(),
        _w.InsertionSortCollider([_w.Bo1_Polyhedra_Aabb(), _w.Bo1_Sphere_Aabb()],
                                 verletDist=verlet_dist),
        _w.InteractionLoop([_w.Ig2_Polyhedra_Polyhedra_ScGeom(), _w.Ig2_Sphere_Polyhedra_ScGeom(),
                            _w.Ig2_Sphere_Sphere_ScGeom()], [ip2],
                           [_w.Law2_ScGeom_MindlinPhys_Mindlin(label=label)]),
        _w.NewtonIntegrator(damping=0.0, gravity=gravity, label="newton"),
    ]


def volumetric_engines(gravity=(0.0, 0.0, 0.0), verlet_dist=0.0, label="law"):
    """YADE's volumetric law for polyhedra (Elias 2014): a normal force kn V along the normal of
    the intersection (volume V), kn = PolyhedraMat.young of the pair in series (N/m3, not a
    Young's modulus); polyhedra, walls and facets. The engine reads it
    (engine/contacts/volumetric.py)."""
    return [
        _w.ForceResetter(),
        _w.InsertionSortCollider([_w.Bo1_Polyhedra_Aabb(), _w.Bo1_Wall_Aabb(),
                                  _w.Bo1_Facet_Aabb()], verletDist=verlet_dist),
        _w.InteractionLoop([_w.Ig2_Polyhedra_Polyhedra_PolyhedraGeom(),
                            _w.Ig2_Wall_Polyhedra_PolyhedraGeom(),
                            _w.Ig2_Facet_Polyhedra_PolyhedraGeom()],
                           [_w.Ip2_PolyhedraMat_PolyhedraMat_PolyhedraPhys()],
                           [_w.Law2_PolyhedraGeom_PolyhedraPhys_Volumetric(label=label)]),
        _w.NewtonIntegrator(damping=0.0, gravity=gravity, label="newton"),
    ]


def volume_equivalent_radius(vertices):
    """Radius (m) of the sphere of the hull's volume."""
    return (3.0 * convex_polyhedron(vertices).volume / (4.0 * math.pi)) ** (1.0 / 3.0)


def rayleigh_step(vertices, mat, fraction):
    """`fraction` of the Rayleigh time of the volume-equivalent sphere of the hull of `vertices`
    in Material `mat` (s)."""
    radius = volume_equivalent_radius(vertices)
    return fraction * float(placement.rayleigh_time(radius, mat.density, mat.young_modulus,
                                                    mat.poisson_ratio))


class PolyhedronImpact(NamedTuple):
    """What an impact scene built: body ids and the fired body's kinetic energy."""
    particle: int               # the body fired
    plate: int                  # the body it hits (fixed)
    kinetic_energy: float       # J, translation only (fired without spin)
    mass: float                 # kg, of the fired body


def polyhedron_impact_scene(vertices, speed, contact="face", material="copper_ore",
                            target="steel", law="mindlin", damped=False, fraction=0.05,
                            volumetric_stiffness=None, gap=1e-4, wall=False, offset=0.0):
    """One convex polyhedron (`vertices`, m, centred) turned `contact` first (orientation) and
    fired down at `speed` (m/s) on a fixed steel plate (a polyhedron), its centroid above the
    plate's centre, its lowest point `gap` (m) above the plate. law: "mindlin" (polyhedra_engines;
    `damped` False sets every restitution to 1) or "volumetric" (volumetric_engines, with kn =
    `volumetric_stiffness` N/m3 for both bodies' PolyhedraMat.young in series: the pair's kn is
    half of it; `wall`: the plate is a YADE Wall). `offset` (m): the plate's centre that far
    along x from below the body (with ScGeom the line of centres then leans). O.dt = `fraction` of the body's Rayleigh time
    (rayleigh_step). No breakage engine is attached. Returns a PolyhedronImpact."""
    O.reset()
    volumetric = law == "volumetric"
    ip2, mats = polyhedra_materials({"particle": material, "target": target}, volumetric=volumetric)
    if volumetric:
        for m in O.materials:
            m.young = float(volumetric_stiffness)
        engines = volumetric_engines()
    elif law == "mindlin":
        engines = polyhedra_engines(ip2 if damped else elastic(ip2))
    else:
        raise ValueError(f"law = {law!r}: accepted 'mindlin' or 'volumetric'")
    turned = orientation(vertices, contact)
    size = float(np.ptp(turned, axis=0).max())
    if wall and volumetric:
        plate_id = O.bodies.append(utils.wall(0.0, axis=2, sense=1, material="target"))
    else:
        plate_id = O.bodies.append(plate("target", side=6.0 * size + 2.0 * abs(offset),
                                         thickness=size, centre=(offset, 0.0)))
    particle = polyhedron(turned, "particle", (0.0, 0.0, gap - turned[:, 2].min()),
                          (0.0, 0.0, -float(speed)))
    pid = O.bodies.append(particle)
    O.engines = engines
    O.dt = rayleigh_step(turned, mats["particle"], fraction)
    mass = particle.state.mass
    return PolyhedronImpact(pid, plate_id, 0.5 * mass * float(speed) ** 2, mass)


def ball_on_polyhedron_scene(vertices, speed, contact="face", ball=10e-3, material="copper_ore",
                             target="steel", damped=False, fraction=0.05, gap=1e-4):
    """A steel ball (diameter `ball`, m; material `target`) fired down at `speed` (m/s) on a
    fixed polyhedron (`vertices`, centred) turned with its face, edge or corner (`contact`) up,
    above the polyhedron's centroid (Ig2_Sphere_Polyhedra_ScGeom; polyhedra_engines, every
    restitution 1 unless `damped`). O.dt = `fraction` of the ball's Rayleigh time. Returns a
    PolyhedronImpact (particle: the ball; plate: the polyhedron)."""
    O.reset()
    ip2, mats = polyhedra_materials({"particle": material, "target": target})
    O.engines = polyhedra_engines(ip2 if damped else elastic(ip2))
    turned = orientation(vertices, contact) * np.array([1.0, 1.0, -1.0])   # feature up
    target_id = O.bodies.append(polyhedron(turned, "particle", fixed=True))
    body = utils.sphere((0.0, 0.0, turned[:, 2].max() + gap + ball / 2.0), ball / 2.0,
                        material="target")
    body.state.vel = Vector3(0.0, 0.0, -float(speed))
    bid = O.bodies.append(body)
    steel = mats["target"]
    O.dt = fraction * float(placement.rayleigh_time(ball / 2.0, steel.density, steel.young_modulus,
                                                    steel.poisson_ratio))
    return PolyhedronImpact(bid, target_id, 0.5 * body.state.mass * float(speed) ** 2,
                            body.state.mass)


class ImpactRecord(NamedTuple):
    """One impact followed step by step (follow_impact); energies in J, lengths in m."""
    work_peak: float        # peak of the contact's normal work, sum of F_n d(delta) (1)
    reader_peak: float      # peak of the work the engine's ContactReader counts (nan: not read)
    hertz_peak: float       # 0.4 kno delta^2.5 at the deepest overlap (nan: no Hertz law)
    approach_peak: float    # peak of delta, the normal approach of the contact point (1)
    force_peak: float       # N, the largest normal force
    rebound: float          # kinetic energy after the contact (every body, rotation included)
    contact_steps: int      # steps with a real contact
    touch_gap: float        # the fired body's lowest point above the target's highest when the
    #                         contact began (0 for a contact found where it is; it is found once
    #                         the step crosses it, so up to speed x dt below)
    ended: bool             # the fired body left the contact within max_steps
    finite: bool            # no NaN or infinity anywhere


# (1) each step, F_n = |normalForce| from the positions at the step's start and
# d(delta) = -(v + w x (c - x)) . n dt, the fired body's velocity at the contact point c averaged
# over the step (n towards the fired body, the target fixed): the same measure for both laws, and
# for a translation the leapfrog's own kinetic energy change.


def _heights(body):
    """(lowest, highest) z (m) of a body: a polyhedron's vertices, a sphere, a wall's plane."""
    state, shape = body.state, body.shape
    if isinstance(shape, _w.Polyhedra):
        z = [(state.ori * v + state.pos)[2] for v in shape.v]
        return min(z), max(z)
    if isinstance(shape, _w.Sphere):
        return state.pos[2] - shape.radius, state.pos[2] + shape.radius
    return state.pos[2], state.pos[2]


def follow_impact(impact, max_steps=50000, read=True):
    """Run an impact scene until the fired body leaves its target (or max_steps) and measure the
    work of the contact forces (ImpactRecord). read: also run the engine's own ContactReader
    (engine/contacts) on the fired body every step (Hertz-Mindlin contacts only)."""
    from yadebreak.engine.contacts.reader import ContactReader
    reader = None
    if read:
        stiffness = {m.id: float(model.hertz_stiffness(m.young, m.poisson)) for m in O.materials}
        reader = ContactReader(stiffness, cs=0.0, emin=0.0)
    work = approach = 0.0
    peaks = [0.0, 0.0, 0.0, 0.0, 0.0]      # work, reader, hertz, approach, force
    steps, touched, ended, touch_gap = 0, False, False, math.nan
    fired = O.bodies[impact.particle]
    state = fired.state
    for _ in range(max_steps):
        before = (Vector3(state.pos), Vector3(state.vel), Vector3(state.angVel),
                  _heights(fired)[0] - _heights(O.bodies[impact.plate])[1])
        O.step()
        real = [i for i in O.interactions.withBody(impact.particle) if i.isReal]
        if not real:
            if touched:
                ended = True
                break
            continue
        if not touched:
            touch_gap = before[3]
        touched, steps = True, steps + 1
        vel, spin = 0.5 * (before[1] + state.vel), 0.5 * (before[2] + state.angVel)
        for i in real:
            n = i.geom.normal if i.id2 == impact.particle else -i.geom.normal
            at = vel + spin.cross(i.geom.contactPoint - before[0])
            step = -at.dot(n) * O.dt
            force = i.phys.normalForce.norm()
            work += force * step
            peaks[4] = max(peaks[4], force)
            approach += step
            if hasattr(i.phys, "kno"):
                peaks[2] = max(peaks[2], 0.4 * i.phys.kno * max(i.geom.penetrationDepth, 0.0)
                               ** 2.5)
        if reader is not None:
            reader.read(O.interactions, O.bodies, TrackedBodies([impact.particle]), set(), O.time, 1)
            peaks[1] = max(peaks[1], float(np.sum(reader.table.work)))
        peaks[0], peaks[3] = max(peaks[0], work), max(peaks[3], approach)
    rebound = float(utils.kineticEnergy())
    finite = all(math.isfinite(v) for v in (*peaks, rebound, *fired.state.pos))
    return ImpactRecord(peaks[0], peaks[1] if read else math.nan,
                        peaks[2] if peaks[2] > 0.0 else math.nan, peaks[3], peaks[4], rebound, steps,
                        touch_gap, ended, finite)


#: O.dt of a breakage scene of polyhedra on the volumetric law, as a fraction of the Rayleigh time
#: of a particle's volume-equivalent sphere (with its material file's Young's modulus): the
#: law's own (engine/contacts/volumetric.py), which the engine keeps for finer fragments
VOLUMETRIC_STEP = STEP_FRACTION


def random_particle(size, rng):
    """Vertices (m) of a random convex particle of sieve size `size` (model.cells.sieve_size),
    turned at random: random_convex_vertices scaled to that size."""
    pts = random_convex_vertices(size, rng)
    pts = pts * (size / sieve_size(pts))
    q, r = np.linalg.qr(rng.normal(size=(3, 3)))
    return pts @ (q * np.sign(np.diag(r))).T


def volumetric_impact_scene(material="copper_ore", size=20e-3, speeds=(5.0,), target="steel",
                            seed=0, gap_fraction=0.02, **options):
    """Random convex polyhedra of sieve size `size` (m), one per speed (m/s), far apart, turned
    at random, fired normally at a plate (a YADE Wall at z = 0) on YADE's volumetric law, each
    material's kn its file's Y / (1 - nu^2) / size (polyhedra_materials); O.dt VOLUMETRIC_STEP
    of the smallest particle's Rayleigh time (the engine lowers it for fragments). The
    particles' shapes come from a Generator seeded `seed`, the engine's draws from `seed`
    itself. Returns (controller, particle ids); `options` are attach()'s."""
    O.reset()
    _, mats = polyhedra_materials({"particle": material, "target": target}, volumetric=True,
                                  size=size)
    O.engines = volumetric_engines()
    O.bodies.append(utils.wall(0.0, axis=2, sense=1, material="target"))
    rng = np.random.default_rng([int(seed), 43])
    side = int(math.ceil(math.sqrt(len(speeds))))
    ids, dt = [], math.inf
    for k, v in enumerate(speeds):
        pts = random_particle(size, rng)
        x, y = (k % side) * 4 * size, (k // side) * 4 * size
        lift = gap_fraction * size / 2.0 - pts[:, 2].min()
        ids.append(O.bodies.append(polyhedron(pts, "particle", (x, y, lift),
                                              (0.0, 0.0, -float(v)))))
        dt = min(dt, rayleigh_step(pts, mats["particle"], VOLUMETRIC_STEP))
    O.dt = dt
    brk = attach({"particle": material}, seed=seed, **options)
    return brk, ids
