"""Breakage of convex polyhedra (YADE Polyhedra): tracked at attach by their sieve size, broken
into the Laguerre cells of model.cells, the finest to the fines ledger. Conservation is checked
on the bodies YADE holds after the breakage against the parent just before it."""
from typing import NamedTuple

import numpy as np
import pytest
from scipy.optimize import linprog
from scipy.spatial import ConvexHull

from yadebreak import load_material, model
from yadebreak.model.cells import convex_polyhedron, fragment_cells, sieve_size

pytestmark = pytest.mark.yade

SIZE = 0.02          # m, the parent's size
VEL = (1.5, -0.4, 2.0)
SPIN = (30.0, -12.0, 45.0)


def _world_vertices(body):
    s = body.state
    return np.array([tuple(s.ori * v + s.pos) for v in body.shape.v])


def _set_spin(body, spin):
    """angVel and the angular momentum YADE integrates an aspherical body from."""
    from yade import Vector3
    s = body.state
    rot = np.array(s.ori.toRotationMatrix())
    s.angVel = Vector3(*spin)
    s.angMom = Vector3(*(rot @ (np.array(s.inertia) * (rot.T @ np.asarray(spin)))))


def _rigid(body, origin):
    """Momentum, angular momentum about `origin` and kinetic energy of a YADE body."""
    from yadebreak.engine.shapes.polyhedron import body_kinetic_energy
    s = body.state
    rot = np.array(s.ori.toRotationMatrix())
    inertia = rot @ np.diag(np.array(s.inertia)) @ rot.T
    p = s.mass * np.array(s.vel)
    arm = np.array(s.pos) - origin
    return p, np.cross(arm, p) + inertia @ np.array(s.angVel), body_kinetic_energy(body)


def _free_polyhedron(seed=3):
    """A random convex copper ore body, moving and spinning in free space, a few steps run."""
    from yade import O, Vector3
    from yadebreak import engine
    from yadebreak.scenes import polyhedra
    ip2, _ = polyhedra.polyhedra_materials({"ore": "copper_ore"})
    O.engines = polyhedra.polyhedra_engines(ip2)
    vertices = polyhedra.random_convex_vertices(SIZE, np.random.default_rng(seed))
    body = polyhedra.polyhedron(vertices, "ore", (0.01, -0.02, 0.03), VEL)
    bid = O.bodies.append(body)
    _set_spin(O.bodies[bid], SPIN)
    O.dt = 1e-6
    O.run(20, True)
    brk = engine.attach({"ore": "copper_ore"}, seed=4)
    return brk, bid


def _interiors_meet(a, b, scale):
    """Depth (m) of the deepest point inside both hulls (LP on their face planes); <= 0: their
    interiors are disjoint."""
    ha, hb = ConvexHull(a), ConvexHull(b)
    eq = np.vstack([ha.equations, hb.equations])       # unit normals: n.x + d <= 0 inside
    res = linprog([0, 0, 0, -1], A_ub=np.column_stack([eq[:, :3], np.ones(len(eq))]),
                  b_ub=-eq[:, 3], bounds=[(None, None)] * 3 + [(None, scale)], method="highs")
    return res.x[3]


def test_polyhedron_tracked_at_attach_by_its_sieve_size(scene):
    from yade import O
    brk, bid = _free_polyhedron()
    body = O.bodies[bid]
    row = brk.bodies[bid]
    size = sieve_size(_world_vertices(body))
    assert row.kind == "breakable" and bid in brk.state.tracked
    assert 2.0 * row.radius == pytest.approx(size, rel=1e-12)
    assert row.mass == body.state.mass
    # the fracture energy is the criterion's draw at the sieve size, from the engine's seed
    energies, _ = brk.criteria["ore"].sample(np.random.default_rng(4), np.array([size]))
    assert row.fracture_energy == pytest.approx(float(energies[0]), rel=1e-12)


class Before(NamedTuple):
    """A parent just before its breakage: its pose, mass, volume, momenta and energy."""
    mass: float
    volume: float
    origin: np.ndarray          # centroid (m)
    rotation: np.ndarray        # body frame to world
    local: np.ndarray           # vertices in the body frame (m)
    spin_local: np.ndarray      # angular velocity in the body frame (rad/s)
    hull: np.ndarray            # world vertices (m)
    rigid: tuple                # _rigid: momentum, angular momentum, kinetic energy


def _before(body):
    s = body.state
    hull = _world_vertices(body)
    return Before(s.mass, convex_polyhedron(hull).volume, np.array(s.pos),
                  np.array(s.ori.toRotationMatrix()), np.array([tuple(v) for v in body.shape.v]),
                  np.array(s.ori.conjugate() * s.angVel), hull, _rigid(body, np.array(s.pos)))


def _break_and_check(brk, bid, ratio, generation):
    """Break body `bid` and check conservation, tracking and geometry; returns the event."""
    from yade import O
    parent = O.bodies[bid]
    density = parent.material.density
    was = _before(parent)
    twin = np.random.default_rng()
    twin.bit_generator.state = brk.state.rng.bit_generator.state
    ledger_before = len(brk.ledger)
    event = brk.break_body(bid, ratio=ratio)
    frags = event["fragments"]
    # the same draws give the same cells: the ledger's cells are known
    frag = fragment_cells(twin, was.local, event["t10"], load_material("copper_ore").beta_params,
                          model.X_MIN * 2.0 * event["radius"])
    assert O.bodies[bid] is None and len(frags) == len(frag.volumes) >= 2
    bodies = [O.bodies[i] for i in frags]
    ledger = brk.ledger.entries[ledger_before:]
    assert len(ledger) == len(frag.ledger_volumes)
    assert all(e["parent_size"] == 2.0 * event["radius"] and e["t10"] == event["t10"]
               for e in ledger)
    # mass and volume
    m_ledger = sum(e["mass"] for e in ledger)
    assert sum(b.state.mass for b in bodies) + m_ledger == pytest.approx(was.mass, rel=1e-13)
    v_cells = sum(convex_polyhedron(_world_vertices(b)).volume for b in bodies)
    assert v_cells + m_ledger / density == pytest.approx(was.volume, rel=1e-12)
    # momentum, angular momentum, kinetic energy (ledger cells: translation in their momenta,
    # spin from their own geometry)
    p0, l0, k0 = was.rigid
    sums = [_rigid(b, was.origin) for b in bodies]
    p1 = sum(s[0] for s in sums) + sum(np.array(e["momentum"]) for e in ledger)
    np.testing.assert_allclose(p1, p0, rtol=0, atol=1e-12 * np.linalg.norm(p0))
    l_ledger, k_spin = _ledger_spin(frag, ledger, was, was.mass / frag.parent_volume)
    l1 = sum(s[1] for s in sums) + l_ledger
    np.testing.assert_allclose(l1, l0, rtol=0, atol=1e-12 * np.linalg.norm(l0))
    k_ledger = sum(0.5 * np.dot(e["momentum"], e["momentum"]) / e["mass"] for e in ledger)
    assert sum(s[2] for s in sums) + k_ledger + k_spin == pytest.approx(k0, rel=1e-12)
    assert event["kinetic_energy_before"] == pytest.approx(k0, rel=1e-12)
    assert event["kinetic_energy_after"] == pytest.approx(k0, rel=1e-12)
    # fragments: tracked, one generation on
    rows = [brk.bodies[i] for i in frags]
    assert all(i in brk.state.tracked for i in frags)
    assert {r.generation for r in rows} == {generation}
    assert {r.kind for r in rows} <= {"breakable", "unbreakable"}
    _check_geometry(bodies, rows, was.hull)
    return event


def _check_geometry(bodies, rows, parent):
    """Each cell inside the parent, sized by its sieve size, its interior disjoint from every
    other's (its centroid outside every other cell; no point deeper than 1e-9 of the parent's
    size inside two cells)."""
    outer = ConvexHull(parent).equations
    scale = float(np.ptp(parent, axis=0).max())
    hulls = [_world_vertices(b) for b in bodies]
    for r, v in zip(rows, hulls):
        assert 2.0 * r.radius == pytest.approx(sieve_size(v), rel=1e-9)
        assert np.max(v @ outer[:, :3].T + outer[:, 3]) < 1e-12 * scale
    for i, a in enumerate(hulls):
        inside = ConvexHull(a).equations
        for j, b in enumerate(hulls):
            if i == j:
                continue
            c = convex_polyhedron(b).centroid
            assert np.max(inside[:, :3] @ c + inside[:, 3]) > 0.0
            if j > i:
                assert _interiors_meet(a, b, scale) < 1e-9 * scale


def test_breakage_of_a_spinning_polyhedron_conserves_everything(scene):
    from yade import O
    brk, bid = _free_polyhedron()
    mass = O.bodies[bid].state.mass
    first = _break_and_check(brk, bid, 5.0, generation=1)
    assert len(first["fragments"]) >= 4
    assert brk.total_mass() == pytest.approx(mass, rel=1e-13)
    # the largest fragment breaks again, spinning and moving with the parent's field
    largest = max(first["fragments"], key=lambda i: brk.bodies[i].mass)
    assert brk.bodies[largest].kind == "breakable"
    second = _break_and_check(brk, largest, 5.0, generation=2)
    assert second["generation"] == 1
    assert brk.total_mass() == pytest.approx(mass, rel=1e-13)


def _ledger_spin(frag, ledger, was, density):
    """Angular momentum about the parent's centroid (world frame) and spin energy 0.5 w.I w of
    the ledger's cells: their inertia from their vertices in the parent's body frame, their
    density the parent's mass over its volume."""
    rot, spin_local = was.rotation, was.spin_local
    momentum, energy = np.zeros(3), 0.0
    for verts, centroid, entry in zip(frag.ledger_vertices, frag.ledger_centroids, ledger):
        inertia = convex_polyhedron(verts).inertia * density
        momentum += np.cross(rot @ centroid, np.array(entry["momentum"]))
        momentum += rot @ (inertia @ spin_local)
        energy += 0.5 * spin_local @ inertia @ spin_local
    return momentum, energy


def test_small_polyhedron_gets_its_principal_inertia(scene):
    """A 3 mm body: YADE alone would skip its turn to principal axes (off-diagonal products of
    inertia below its absolute 1e-13 m^5) and take the diagonal as the principal moments."""
    from yade import O
    from yadebreak.scenes import polyhedra
    polyhedra.polyhedra_materials({"ore": "copper_ore"})
    vertices = polyhedra.random_convex_vertices(0.003, np.random.default_rng(0))
    body = O.bodies[O.bodies.append(polyhedra.polyhedron(vertices, "ore", (0.1, 0.2, 0.3)))]
    exact = convex_polyhedron(vertices)
    moments = np.linalg.eigvalsh(exact.inertia) * body.material.density
    np.testing.assert_allclose(np.sort(np.array(body.state.inertia)), moments, rtol=1e-12)
    world = _world_vertices(body)
    np.testing.assert_allclose(convex_polyhedron(world).centroid, (0.1, 0.2, 0.3), rtol=1e-14)
    # the same body where it was given (its vertices, moved to the position), turned nowhere
    given = vertices - exact.centroid + np.array([0.1, 0.2, 0.3])
    gap = np.linalg.norm(world[:, None, :] - given[None, :, :], axis=2).min(axis=1)
    assert gap.max() < 1e-15 * 0.3 * 10


@pytest.mark.parametrize("material", ["copper_ore", "ab_t10_ore"])
def test_each_criterion_draws_a_polyhedron_fracture_energy_at_its_sieve_size(scene, material):
    from yade import O
    from yadebreak import engine
    from yadebreak.scenes import polyhedra
    ip2, _ = polyhedra.polyhedra_materials({"ore": material})
    O.engines = polyhedra.polyhedra_engines(ip2)
    cube = polyhedra.box_vertices(0.02, 0.01, 0.005)          # sieves at its breadth, 10 mm
    bid = O.bodies.append(polyhedra.polyhedron(cube, "ore"))
    O.dt = 1e-7
    brk = engine.attach({"ore": material}, seed=7)
    row = brk.bodies[bid]
    assert 2.0 * row.radius == pytest.approx(0.01, rel=1e-12)
    energies, extra = brk.criteria["ore"].sample(np.random.default_rng(7), np.array([0.01]))
    assert row.fracture_energy == float(energies[0])
    for name, value in extra.items():
        assert getattr(row, name) == pytest.approx(float(np.ravel(value)[0]), rel=1e-12)


def test_cube_on_a_plate_is_damaged_by_the_energy_it_absorbs(scene):
    """A 20 mm cube face first on a steel plate above its centre (the case Hertz-Mindlin through
    ScGeom gets right, docs/polyhedra.md), undamped: the engine reads e m v^2/2 (Eq. 4's share
    e against steel) and weakens the cube by Eqs. 5-6 at that ratio."""
    from yade import O
    from yadebreak import engine
    from yadebreak.scenes import polyhedra
    speed = 3.0
    impact = polyhedra.polyhedron_impact_scene(polyhedra.box_vertices(0.02, 0.02, 0.02), speed,
                                               "face", material="copper_ore")
    brk = engine.attach({"particle": "copper_ore"}, seed=1, emin=0.0, read_period="every_step")
    row = brk.bodies[impact.particle]
    row.fracture_energy = row.fracture_energy_initial = 50.0    # above e v^2/2 (about 3 J/kg)
    record = polyhedra.follow_impact(impact, read=False)
    O.run(5, True)
    assert record.ended and record.finite
    mat = load_material("copper_ore")
    e = mat.energy_partition(load_material("steel"))
    (ev,) = [x for x in brk.events if x["kind"] == "damage"]
    assert ev["id"] == impact.particle
    assert ev["specific_energy"] == pytest.approx(e * speed ** 2 / 2.0, rel=1e-3)
    expected = model.weakened_fracture_energy(50.0, ev["specific_energy"] / 50.0, mat.params.gamma)
    assert row.fracture_energy == pytest.approx(float(expected), rel=1e-12)
    assert row.damage == pytest.approx(1.0 - float(expected) / 50.0, rel=1e-12)
