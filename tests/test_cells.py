"""Convex cells for polyhedral breakage (yadebreak.model.cells): pure geometry, no yade."""
import time

import numpy as np
import pytest
from scipy.spatial import ConvexHull

from yadebreak import model
from yadebreak.model import cells
from yadebreak.criteria import load_material

CUBE = np.array([[x, y, z] for x in (0.0, 1.0) for y in (0.0, 1.0) for z in (0.0, 1.0)])


def _rotation(rng):
    q, r = np.linalg.qr(rng.normal(size=(3, 3)))
    return q * np.sign(np.diag(r))


def _box(a, b, c):
    return CUBE * [a, b, c]


def _fibonacci_sphere(n, radius):
    k = np.arange(n) + 0.5
    z = 1.0 - 2.0 * k / n
    phi = np.pi * (1.0 + 5.0 ** 0.5) * k
    rho = np.sqrt(1.0 - z * z)
    return radius * np.column_stack([rho * np.cos(phi), rho * np.sin(phi), z])


def _irregular_parent(rng):
    """A less regular convex parent: the hull of 14 points on a stretched, rotated ellipsoid."""
    pts = rng.normal(size=(14, 3))
    pts /= np.linalg.norm(pts, axis=1)[:, None]
    return (pts * [0.6, 0.45, 0.35]) @ _rotation(rng).T + [0.2, -0.1, 0.3]


# --------------------------------------------------------------------------- one convex body
def test_box_mass_properties_match_closed_forms():
    rng = np.random.default_rng(0)
    a, b, c = 0.3, 0.2, 0.1
    rot = _rotation(rng)
    shift = np.array([1.0, -2.0, 0.5])
    body = cells.convex_polyhedron((_box(a, b, c) - [a / 2, b / 2, c / 2]) @ rot.T + shift)
    assert body.volume == pytest.approx(a * b * c, rel=1e-12)
    np.testing.assert_allclose(body.centroid, shift, atol=1e-12)
    # a box's inertia per unit density: V/12 diag(b^2 + c^2, a^2 + c^2, a^2 + b^2), rotated
    local = a * b * c / 12.0 * np.diag([b * b + c * c, a * a + c * c, a * a + b * b])
    np.testing.assert_allclose(body.inertia, rot @ local @ rot.T, atol=1e-14)
    assert body.sieve_size == pytest.approx(b, rel=1e-9)      # the intermediate side


def test_cube_sieve_size_is_its_side_in_any_orientation():
    rng = np.random.default_rng(1)
    for _ in range(5):
        side = rng.uniform(0.01, 2.0)
        pts = (CUBE * side) @ _rotation(rng).T
        assert cells.sieve_size(pts) == pytest.approx(side, rel=1e-9)
        assert cells.convex_polyhedron(pts).volume == pytest.approx(side ** 3, rel=1e-12)


def test_sphere_like_polyhedron_sieves_at_its_diameter():
    """400 points on a sphere of radius 0.5: their hull's volume is within 1.5 % of the sphere's
    (the hull's faces cut 1.2 % off), inertia within 3 % of 2/5 m r^2, sieve size within 2 % of
    the diameter (the faces sit at 0.99 r or more from the centre)."""
    r = 0.5
    body = cells.convex_polyhedron(_fibonacci_sphere(400, r))
    sphere = 4.0 / 3.0 * np.pi * r ** 3
    assert body.volume == pytest.approx(sphere, rel=0.015)
    assert body.volume < sphere
    np.testing.assert_allclose(body.inertia, 0.4 * sphere * r * r * np.eye(3), atol=0.03 * 0.4 * sphere * r * r)
    assert body.sieve_size == pytest.approx(2.0 * r, rel=0.02)
    assert body.sieve_size <= 2.0 * r


# --------------------------------------------------------------------------- power cells
def _check_tessellation(parent, seeds, weights):
    """Volumes sum to the parent's (1e-12 relative); each cell (an intersection of half-spaces,
    so convex) within the parent; sample points fall in exactly one cell (interiors disjoint)."""
    parent_hull = ConvexHull(parent)
    got = cells.laguerre_cells(parent, seeds, weights)
    live = [c for c in got if c is not None]
    volumes = np.array([ConvexHull(c).volume for c in live])
    assert volumes.sum() == pytest.approx(parent_hull.volume, rel=1e-12)
    for c in live:
        eq = parent_hull.equations
        assert np.all(c @ eq[:, :3].T + eq[:, 3] <= 1e-12)
    rng = np.random.default_rng(7)
    lo, hi = parent_hull.min_bound, parent_hull.max_bound
    pts = lo + (hi - lo) * rng.random((4000, 3))
    pts = pts[np.all(pts @ parent_hull.equations[:, :3].T + parent_hull.equations[:, 3] < -1e-9, axis=1)]
    inside = np.zeros(len(pts), dtype=int)
    for c in live:
        h = ConvexHull(c)
        inside += np.all(pts @ h.equations[:, :3].T + h.equations[:, 3] <= 1e-12, axis=1)
    assert np.all(inside == 1)
    return got


def test_voronoi_cells_of_a_cube_tile_it():
    rng = np.random.default_rng(2)
    seeds = rng.random((20, 3))
    got = _check_tessellation(CUBE, seeds, np.zeros(20))
    assert all(c is not None for c in got)
    # equal weights: every vertex of cell i is at least as near its seed as any other seed
    for i, c in enumerate(got):
        d = np.linalg.norm(c[:, None, :] - seeds[None, :, :], axis=2)
        assert np.all(d[:, i] <= d.min(axis=1) + 1e-12)


def test_power_cells_share_face_planes_and_report_empty_cells():
    rng = np.random.default_rng(3)
    parent = _irregular_parent(rng)
    seeds = parent.mean(axis=0) + 0.15 * rng.normal(size=(25, 3))
    seeds = seeds[np.all(seeds @ ConvexHull(parent).equations[:, :3].T
                         + ConvexHull(parent).equations[:, 3] < 0, axis=1)]
    weights = rng.uniform(0.0, 0.01, len(seeds))
    weights[0] = -5.0                        # a seed whose power cell cannot win anywhere
    got = _check_tessellation(parent, seeds, weights)
    assert got[0] is None
    # a vertex shared by two cells lies on their common plane: the cells touch face to face
    sq = (seeds ** 2).sum(axis=1)
    for i in range(1, len(seeds)):
        for j in range(i + 1, len(seeds)):
            if got[i] is None or got[j] is None:
                continue
            shared = got[i][np.min(np.linalg.norm(got[i][:, None] - got[j][None], axis=2), axis=1) < 1e-10]
            plane = 2.0 * shared @ (seeds[j] - seeds[i]) - (sq[j] - sq[i] - weights[j] + weights[i])
            np.testing.assert_allclose(plane, 0.0, atol=1e-12)


# --------------------------------------------------------------------------- weights
@pytest.mark.parametrize("shape", ["cube", "irregular"])
def test_weights_reach_targets_spanning_1_to_100(shape):
    rng = np.random.default_rng(4)
    parent = CUBE if shape == "cube" else _irregular_parent(rng)
    hull = ConvexHull(parent)
    n = 30
    seeds = np.empty((0, 3))
    while len(seeds) < n:
        p = hull.min_bound + (hull.max_bound - hull.min_bound) * rng.random((50, 3))
        seeds = np.vstack([seeds, p[np.all(p @ hull.equations[:, :3].T + hull.equations[:, 3] < 0, axis=1)]])
    seeds = seeds[:n]
    target = np.geomspace(1.0, 100.0, n)
    rng.shuffle(target)
    target *= hull.volume / target.sum()
    sol = cells.solve_weights(parent, seeds, target, tol=1e-3, max_iter=30)
    assert sol.converged and sol.iterations <= 30
    assert np.all(np.abs(sol.volumes - target) <= 1e-3 * target)
    # the cells are the tessellation's own: re-cut with the weights, measured from the vertices
    volumes = [ConvexHull(c).volume for c in cells.laguerre_cells(parent, seeds, sol.weights)]
    np.testing.assert_allclose(volumes, sol.volumes, rtol=1e-12)
    assert sum(volumes) == pytest.approx(hull.volume, rel=1e-12)


def test_weight_solver_cost_is_bounded():
    """Cost on this 2-core machine (shared, nice): 10 / 30 / 100 cells in a cube, targets 1:100,
    ~0.04 / 0.2 / 1.2 s (docs/model.md). Asserted loosely (10 times that) to hold on any machine;
    the iteration count is the bounded quantity."""
    rng = np.random.default_rng(5)
    for n, budget in ((10, 0.5), (30, 3.0), (100, 15.0)):
        seeds = rng.random((n, 3))
        target = np.exp(rng.uniform(0.0, np.log(100.0), n))
        target /= target.sum()
        start = time.perf_counter()
        sol = cells.solve_weights(CUBE, seeds, target)
        assert time.perf_counter() - start < budget
        assert sol.converged and sol.iterations <= 12


# --------------------------------------------------------------------------- one breakage
@pytest.mark.parametrize("law", cells.LAWS)
def test_fragment_cells_closes_the_parent_volume(law):
    beta = load_material("copper_ore").beta_params
    parent = _irregular_parent(np.random.default_rng(6))
    body = cells.convex_polyhedron(parent)
    smallest = 0.15 * body.sieve_size
    frag = cells.fragment_cells(np.random.default_rng(16), parent, 20.0, beta, smallest, law=law)
    assert frag.solution.converged
    assert frag.volumes.sum() + frag.ledger_volume == pytest.approx(body.volume, rel=1e-12)
    assert len(frag.volumes) >= 3 and np.all(frag.sieve_sizes >= smallest)
    assert np.all(frag.ledger_sieve_sizes < smallest) or frag.ledger_volume > 0.0
    for verts, vol, cen in zip(frag.vertices, frag.volumes, frag.centroids):
        one = cells.convex_polyhedron(verts)
        assert one.volume == pytest.approx(vol, rel=1e-12)
        np.testing.assert_allclose(one.centroid, cen, atol=1e-12)
    # passing: the ledger's share at the smallest size, everything at the parent's size
    p = frag.passing([0.5 * smallest, smallest, body.sieve_size * 10.0])
    assert p[-1] == pytest.approx(1.0, rel=1e-12)
    law_fn = cells.progeny_law(20.0, beta, law)
    x = smallest / body.sieve_size
    assert p[0] == pytest.approx(frag.ledger_volume / body.volume * law_fn(0.5 * x) / law_fn(x), rel=1e-12)
    # every draw from the Generator: the same seed, the same cells
    again = cells.fragment_cells(np.random.default_rng(16), parent, 20.0, beta, smallest, law=law)
    np.testing.assert_array_equal(again.solution.weights, frag.solution.weights)


def test_gaudin_schuhmann_law_passes_t10_at_one_tenth():
    law = cells.progeny_law(25.0, None, "gaudin_schuhmann")
    assert law(0.1) == pytest.approx(0.25, rel=1e-12)
    assert law(1.0) == pytest.approx(1.0)
    with pytest.raises(ValueError):
        cells.progeny_law(25.0, None, "rosin")


# --------------------------------------------------------------------------- against the target
@pytest.mark.parametrize("t10, smallest, count", [(25.0, 0.2, 100)])
def test_cells_follow_the_progeny_distribution(t10, smallest, count):
    """`count` breakages of a unit cube (copper ore, Eq. 10), fixed seed: the mean mass passing
    the sieves of 1/2, 1/4, 1/10, 1/25 of the cube's side (its sieve size) at least 2.5 times
    the smallest resolved size `smallest` (relative: Rocky's manual, the distribution holds only
    above about 2.5 times the minimum size), cells at their own sieve size, against Eq. 10: 15 %
    relative, 2 points absolute below 10 %. Finer sieves test mostly the ledger, which cells
    sieving just under `smallest` join: there the passing runs 15 % high (below).

    Measured (other seeds): 200 breakages at 25 % down to 0.2: 89.8 / 55.9 / 26.1 / 14.5 %
    against 90.1 / 55.0 / 25.0 / 13.9 %, standard errors 0.65 / 0.22 / 0.04 / 0.02 points; the
    sieve held, 1/2 (bias -0.3 points, one breakage's standard deviation 9.2), stays within
    its 13.5 points by bias plus three standard errors of the mean of 100 (2.8). 40 at 10 %
    down to 0.1 (1-6 s each, 80-260 cells): 60.3 / 27.7 / 11.6 / 6.1 % against 56.9 / 24.2 /
    10.0 / 5.3 %, standard errors 2.8 / 1.0 / 0.06 / 0.03: within the tolerance at 1/2 and 1/4,
    but a test of it would need some 100 breakages (one's standard deviation at 1/2 is 17.7
    points); the random parents' test below holds the engine's settings.
    """
    beta = load_material("copper_ore").beta_params
    rng = np.random.default_rng(43)
    sieves = np.array([1 / 2, 1 / 4, 1 / 10, 1 / 25])
    passing = np.mean([cells.fragment_cells(rng, CUBE, t10, beta, smallest).passing(sieves)
                       for _ in range(count)], axis=0) * 100.0
    target = model.progeny_passing(t10, beta, sieves)
    allowed = np.where(target < 10.0, 2.0, 0.15 * target)
    held = sieves >= 2.5 * smallest
    assert held.any()
    assert np.all(np.abs(passing - target)[held] <= allowed[held]), (passing, target)


def test_a_vanished_cell_is_revived():
    """Start with a weight that leaves one cell empty: the fallback raises it until its seed is
    inside its own cell, and Newton then reaches the targets."""
    rng = np.random.default_rng(8)
    seeds = rng.random((12, 3))
    target = np.full(12, 1.0 / 12.0)
    start = np.zeros(12)
    start[3] = -2.0
    assert cells.laguerre_cells(CUBE, seeds, start)[3] is None
    sol = cells.solve_weights(CUBE, seeds, target, weights=start)
    assert sol.converged and sol.max_relative_error <= 1e-3


def test_cells_of_random_convex_parents_follow_the_progeny_distribution():
    """200 breakages of random convex parents (random_convex_vertices, the single-impact
    scenes' shape) at t10' drawn uniformly in 2-20 % (the DEM's: primary breakages at 2-5 %,
    successive ones higher), smallest resolved size the engine's X_MIN of the parent: the mean
    passing at 1/2, 1/4, 1/10, 1/25 of the parent's sieve size against the mean of Eq. 10 at each
    breakage's own t10', 15 % relative (2 points absolute below 10 %). Measured 56.8 / 27.5 /
    11.6 / 6.2 % against 57.0 / 26.2 / 11.1 / 5.9 %, standard errors 1.8 / 0.9 / 0.4 / 0.2
    points. Bias plus three standard errors stays within the tolerance at 1/2 (5.6 of 8.5
    points), 1/4 (3.9 of 3.9) and 1/25 (0.9 of 2); at 1/10 it is 1.75 against 1.66: held on
    this fixed seed (+0.58, 1.5 standard errors)."""
    beta = load_material("copper_ore").beta_params
    rng = np.random.default_rng(200)
    sieves = np.array([1 / 2, 1 / 4, 1 / 10, 1 / 25])
    got, want = [], []
    for _ in range(200):
        parent = cells.random_convex_vertices(1.0, rng)
        t10 = rng.uniform(2.0, 20.0)
        frag = cells.fragment_cells(rng, parent, t10, beta, model.X_MIN * cells.sieve_size(parent))
        got.append(100.0 * frag.passing(sieves * frag.parent_sieve_size))
        want.append(model.progeny_passing(t10, beta, sieves))
    passing, target = np.mean(got, axis=0), np.mean(want, axis=0)
    allowed = np.where(target < 10.0, 2.0, 0.15 * target)
    assert np.all(np.abs(passing - target) <= allowed), (passing, target)
