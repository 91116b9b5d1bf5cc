"""Breakage of convex polyhedra (YADE Polyhedra): tracked at attach by their sieve size, broken
into the Laguerre cells of model.cells, the finest to the fines ledger. Conservation is checked
on the bodies YADE holds after the breakage against the parent just before it."""
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
    from yadebreak.engine.cells_replacement import body_kinetic_energy
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


def test_breakage_of_a_spinning_polyhedron_conserves_everything(scene):
    from yade import O
    brk, bid = _free_polyhedron()
    parent = O.bodies[bid]
    mass, origin = parent.state.mass, np.array(parent.state.pos)
    density = parent.material.density
    volume = convex_polyhedron(_world_vertices(parent)).volume
    p0, l0, k0 = _rigid(parent, origin)
    local = np.array([tuple(v) for v in parent.shape.v])
    spin_local = np.array(parent.state.ori.conjugate() * parent.state.angVel)
    rot = np.array(parent.state.ori.toRotationMatrix())
    twin = np.random.default_rng()
    twin.bit_generator.state = brk.state.rng.bit_generator.state
    event = brk.break_body(bid, ratio=5.0)
    frags = event["fragments"]
    # the same draws give the same cells: the ledger's cells are known
    size = 2.0 * event["radius"]
    frag = fragment_cells(twin, local, event["t10"], load_material("copper_ore").beta_params,
                          model.X_MIN * size)
    assert O.bodies[bid] is None and len(frags) == len(frag.volumes) >= 4
    bodies = [O.bodies[i] for i in frags]
    ledger = brk.ledger.entries
    assert len(ledger) == len(frag.ledger_volumes)
    # mass and volume
    m_ledger = sum(e["mass"] for e in ledger)
    assert sum(b.state.mass for b in bodies) + m_ledger == pytest.approx(mass, rel=1e-13)
    v_cells = sum(convex_polyhedron(_world_vertices(b)).volume for b in bodies)
    assert v_cells + m_ledger / density == pytest.approx(volume, rel=1e-12)
    assert brk.total_mass() == pytest.approx(mass, rel=1e-13)
    # momentum, angular momentum, kinetic energy (ledger cells: translation in their momenta,
    # spin 0.5 w.I w from their own geometry, turned to the world frame)
    sums = [_rigid(b, origin) for b in bodies]
    p1 = sum(s[0] for s in sums) + sum(np.array(e["momentum"]) for e in ledger)
    np.testing.assert_allclose(p1, p0, rtol=0, atol=1e-12 * np.linalg.norm(p0))
    l_ledger, k_ledger_spin = _ledger_spin(frag, ledger, rot, spin_local, mass / frag.parent_volume)
    k1 = sum(s[2] for s in sums) + brk.ledger.kinetic_energy() + k_ledger_spin
    assert k1 == pytest.approx(k0, rel=1e-12)
    assert event["kinetic_energy_after"] == pytest.approx(k0, rel=1e-12)
    l1 = sum(s[1] for s in sums) + l_ledger
    np.testing.assert_allclose(l1, l0, rtol=0, atol=1e-12 * np.linalg.norm(l0))
    assert event["kinetic_energy_before"] == pytest.approx(k0, rel=1e-12)
    # fragments: tracked, one generation on, disjoint, inside the parent
    rows = [brk.bodies[i] for i in frags]
    assert all(i in brk.state.tracked for i in frags)
    assert {r.generation for r in rows} == {1}
    assert {r.kind for r in rows} <= {"breakable", "unbreakable"} and rows[0].kind == "breakable"
    hulls = [_world_vertices(b) for b in bodies]
    for r, v in zip(rows, hulls):
        assert 2.0 * r.radius == pytest.approx(sieve_size(v), rel=1e-9)
    for i, a in enumerate(hulls):
        inside = ConvexHull(a).equations
        for j, b in enumerate(hulls):
            if i == j:
                continue
            c = convex_polyhedron(b).centroid
            assert np.max(inside[:, :3] @ c + inside[:, 3]) > 0.0     # outside cell i
            if j > i:
                assert _interiors_meet(a, b, SIZE) < 1e-9 * SIZE
    return brk, frags


def _ledger_spin(frag, ledger, rot, spin_local, density):
    """Angular momentum about the parent's centroid (world frame) and spin energy 0.5 w.I w of
    the ledger's cells: their inertia from their vertices in the parent's body frame (rotation
    `rot` to the world), their density the parent's mass over its volume."""
    momentum, energy = np.zeros(3), 0.0
    for verts, centroid, entry in zip(frag.ledger_vertices, frag.ledger_centroids, ledger):
        inertia = convex_polyhedron(verts).inertia * density
        momentum += np.cross(rot @ centroid, np.array(entry["momentum"]))
        momentum += rot @ (inertia @ spin_local)
        energy += 0.5 * spin_local @ inertia @ spin_local
    return momentum, energy
