"""Convex cells of a broken convex polyhedron: a Laguerre (power) tessellation clipped to the parent.

Pure geometry for polyhedral breakage: numpy and scipy only, never yade. Lengths in metres,
volumes in m^3 (multiply by the density for masses).

- `convex_polyhedron` (and `polyhedron_mass_properties`, `sieve_size`): volume, centroid,
  inertia tensor about the centroid (unit density) and sieve size of a convex body given by points.
- `laguerre_cells`: the power cells of seeds with weights, clipped to the convex parent. Cell i is
  the parent cut by the half-spaces 2 (s_j - s_i).x <= |s_j|^2 - |s_i|^2 - w_j + w_i: neighbouring
  cells share their face plane, so the cells touch face to face and never overlap.
- `solve_weights`: damped Newton on the concave dual (gradient: target minus actual volume,
  Hessian entries: face area / (2 |s_i - s_j|)) until each cell's volume is within a relative
  tolerance of its target. The cells are the tessellation's own: nothing is rescaled afterwards.
- `fragment_cells`: one breakage: target sieve sizes drawn from the progeny law at t10' (Eq. 10
  or Gaudin-Schuhmann), seeds, weights, cells; cells finer than the smallest resolved size go to
  the ledger.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import linprog
from scipy.spatial import ConvexHull, HalfspaceIntersection, QhullError

from yadebreak.model.equations import fines_passing, progeny_passing

__all__ = ['ConvexPolyhedron', 'convex_polyhedron', 'polyhedron_mass_properties', 'sieve_size',
           'laguerre_cells', 'WeightSolution', 'solve_weights', 'progeny_law', 'target_sizes',
           'place_seeds', 'Fragmentation', 'fragment_cells', 'random_convex_vertices', 'cell_volume', 'CELL_SHAPE_FACTOR',
           'CELL_SHAPE_EXPONENT', 'LAWS']

#: Volume V of the cells fragment_cells makes against their sieve size b, both relative to the
#: parent's sieve size X: V/X^3 = k (V^(1/3)/X)^c b^3/X^3, k and c fitted to the geometric means
#: of V/b^3 in bins of V (copper ore, t10' = 10 %, cube, 12 breakages, 2400 cells: 0.32 at
#: V^(1/3) = 0.075 X rising to 0.50 at 0.55 X, scatter 0.10-0.19 in ln b; small cells are flattened
#: between large ones). It turns a target sieve size into a target volume (cell_volume).
CELL_SHAPE_FACTOR = 0.578
CELL_SHAPE_EXPONENT = 0.233

#: The progeny laws fragment_cells accepts (Rocky's two options).
LAWS = ("incomplete_beta", "gaudin_schuhmann")


# --------------------------------------------------------------------------- one convex body
@dataclass(frozen=True)
class ConvexPolyhedron:
    """A convex body: its hull's vertices (n, 3), volume (m^3), centroid (m), inertia tensor about
    the centroid per unit density (m^5; times the density gives kg m^2) and sieve size (m)."""

    vertices: np.ndarray
    volume: float
    centroid: np.ndarray
    inertia: np.ndarray
    sieve_size: float


def polyhedron_mass_properties(vertices):
    """(volume, centroid, inertia about the centroid per unit density) of the hull of `vertices`.

    Exact for a polyhedron: the hull's triangles and an interior point make tetrahedra; each
    tetrahedron's second moment about the origin is V/20 (sum v v^T + (sum v)(sum v)^T) over its
    vertices v; summed, shifted to the centroid, I = tr(C) 1 - C.
    """
    hull = ConvexHull(np.asarray(vertices, dtype=float))
    pts = hull.points[hull.vertices]
    apex = pts.mean(axis=0)                       # interior: the hull is convex
    tri = hull.points[hull.simplices] - apex      # (T, 3, 3), relative to the apex
    vol = np.abs(np.einsum("ij,ij->i", tri[:, 0], np.cross(tri[:, 1], tri[:, 2]))) / 6.0
    volume = vol.sum()
    total = tri.sum(axis=1)                       # the apex is at the origin
    centre = (vol[:, None] * total).sum(axis=0) / (4.0 * volume)
    second = (np.einsum("t,tki,tkj->ij", vol, tri, tri)
              + np.einsum("t,ti,tj->ij", vol, total, total)) / 20.0
    second -= volume * np.outer(centre, centre)   # about the centroid
    inertia = np.trace(second) * np.eye(3) - second
    return float(volume), apex + centre, inertia


#: Boxes whose volumes differ by less than this (relative) are equally small: round-off, which
#: the body's orientation changes, must not choose among them (a cell can have two boxes of one
#: volume and different breadths); the one of least breadth is taken.
_BOX_TIE = 1e-9


def _flush_box_extents(points, hull):
    """Sorted extents (largest first) of the smallest-volume box with a face flush on a hull face
    (of equally small ones, _BOX_TIE, the one of least intermediate extent).

    For every distinct face normal n, the box's other axes follow the directions of the hull's
    edges projected on the plane normal to n (a rectangle of least area around a convex polygon
    has a side on one of its edges); the box of least volume wins.
    """
    normals = np.unique(np.round(hull.equations[:, :3], 12), axis=0)
    edges = np.concatenate([hull.simplices[:, [0, 1]], hull.simplices[:, [1, 2]],
                            hull.simplices[:, [2, 0]]])
    edge_dirs = points[edges[:, 1]] - points[edges[:, 0]]
    pts = points[hull.vertices]
    best = None
    for chunk in np.array_split(normals, max(1, len(normals) * len(edge_dirs) // 20000)):
        e1 = edge_dirs[None, :, :] - np.einsum("ne,ke->nk", chunk, edge_dirs)[:, :, None] * chunk[:, None, :]
        length = np.linalg.norm(e1, axis=2)
        ok = length > 1e-9 * np.linalg.norm(edge_dirs, axis=1)[None, :]
        n_idx, k_idx = np.nonzero(ok)
        a1 = e1[n_idx, k_idx] / length[n_idx, k_idx, None]
        a3 = chunk[n_idx]
        a2 = np.cross(a3, a1)
        ext = np.sort(np.stack([np.ptp(pts @ a.T, axis=0) for a in (a1, a2, a3)], axis=1),
                      axis=1)[:, ::-1]
        volume = ext.prod(axis=1)
        near = ext[volume <= volume.min() * (1.0 + _BOX_TIE)]
        best = near if best is None else np.vstack([best, near])
    volume = best.prod(axis=1)
    near = best[volume <= volume.min() * (1.0 + _BOX_TIE)]
    return near[np.argmin(near[:, 1])]


def sieve_size(vertices):
    """Sieve size (m) of a convex body: the intermediate extent (breadth) of its bounding box.

    A square-mesh sieve passes a particle through its two smaller dimensions, so its aperture
    measures the intermediate one (Heywood's breadth): a box a >= b >= c passes at b, a cube of
    side a at a, a sphere at its diameter. The box is the smallest-volume one with a face flush
    on a face of the hull (exact for boxes; for a rounded body it tends to the diameter), so the
    size does not depend on the body's orientation. The volume-equivalent diameter would not
    do: a cube's is 1.24 a, yet the cube passes a sieve of aperture a.
    """
    points = np.asarray(vertices, dtype=float)
    return float(_flush_box_extents(points, ConvexHull(points))[1])


def convex_polyhedron(vertices):
    """The ConvexPolyhedron of the hull of `vertices` (n, 3), n >= 4 not coplanar (m)."""
    points = np.asarray(vertices, dtype=float)
    hull = ConvexHull(points)
    volume, centroid, inertia = polyhedron_mass_properties(points)
    size = float(_flush_box_extents(points, hull)[1])
    return ConvexPolyhedron(points[hull.vertices], volume, centroid, inertia, size)


def random_convex_vertices(size, rng, points=24, roughness=0.25):
    """Vertices (m) of a random convex body about `size` across: the hull of `points` random
    directions at radii size/2 (1 - roughness u), u uniform in [0, 1), centred on its centroid.
    rng: a seeded numpy Generator."""
    d = rng.normal(size=(points, 3))
    d /= np.linalg.norm(d, axis=1)[:, None]
    pts = d * (size / 2.0) * (1.0 - roughness * rng.random(points))[:, None]
    body = convex_polyhedron(pts)
    return body.vertices - body.centroid


# --------------------------------------------------------------------------- power cells
def _neighbour_pairs(seeds, weights):
    """Candidate neighbour pairs (i < j) of the power diagram: the edges of the regular
    triangulation, the lower hull of the seeds lifted to (s, |s|^2 - w). All pairs when the lift
    is degenerate or there are few seeds."""
    n = len(seeds)
    if n > 12:
        lifted = np.column_stack([seeds, (seeds ** 2).sum(axis=1) - weights])
        try:
            hull = ConvexHull(lifted)
            lower = hull.simplices[hull.equations[:, 3] < 0.0]
            pairs = np.concatenate([lower[:, [a, b]] for a in range(4) for b in range(a + 1, 4)])
            return np.unique(np.sort(pairs, axis=1), axis=0)
        except QhullError:
            pass
    i, j = np.triu_indices(n, 1)
    return np.column_stack([i, j])


def _interior_point(halfspaces, hint, scale):
    """A point strictly inside {x: A x + b <= 0}: `hint` when it is, else the Chebyshev centre
    (linprog). None when the region has no interior (an empty cell)."""
    a, b = halfspaces[:, :3], halfspaces[:, 3]
    norms = np.linalg.norm(a, axis=1)
    if hint is not None and np.min(-(a @ hint + b) / norms) > 1e-6 * scale:
        return hint
    res = linprog([0.0, 0.0, 0.0, -1.0], A_ub=np.column_stack([a, norms]), b_ub=-b,
                  bounds=[(None, None)] * 3 + [(0.0, scale)], method="highs")
    if res.status != 0 or res.x[3] <= 1e-9 * scale:
        return None
    return res.x[:3]


def _cell(halfspaces, hint, scale):
    """Vertices (k, 3) of one clipped cell, its hull, and the face area on each half-space
    (array aligned with `halfspaces`); None when the cell is empty."""
    point = _interior_point(halfspaces, hint, scale)
    if point is None:
        return None
    try:
        verts = HalfspaceIntersection(halfspaces, point).intersections
        hull = ConvexHull(verts)
    except QhullError:
        return None
    normals = halfspaces[:, :3] / np.linalg.norm(halfspaces[:, :3], axis=1)[:, None]
    tri = verts[hull.simplices]
    area = 0.5 * np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1)
    offsets = halfspaces[:, 3] / np.linalg.norm(halfspaces[:, :3], axis=1)
    # the half-space of each triangle: its plane (parallel planes are told apart by the offset)
    mismatch = (1.0 - hull.equations[:, :3] @ normals.T
                + np.abs(tri.mean(axis=1) @ normals.T + offsets) / scale)
    owner = np.argmin(mismatch, axis=1)
    return verts, hull, np.bincount(owner, weights=area, minlength=len(halfspaces))


def _power_cells(parent_hull, seeds, weights, hints=None):
    """All clipped power cells: (list of vertices or None, volumes, sparse-ready face areas as
    (i, j, area) arrays, centroids). The parent's faces close the cells at its surface."""
    n = len(seeds)
    scale = float(np.ptp(parent_hull.points, axis=0).max())
    pairs = _neighbour_pairs(seeds, weights)
    neighbours = [[] for _ in range(n)]
    for i, j in pairs:
        neighbours[i].append(j)
        neighbours[j].append(i)
    sq = (seeds ** 2).sum(axis=1)
    cells, volumes, centroids = [None] * n, np.zeros(n), np.full((n, 3), np.nan)
    rows, cols, areas = [], [], []
    for i in range(n):
        nb = np.asarray(neighbours[i], dtype=int)
        if nb.size == 0 and n > 1:
            continue                  # off the lifted lower hull: an empty power cell
        own = np.column_stack([2.0 * (seeds[nb] - seeds[i]),
                               -(sq[nb] - sq[i] - weights[nb] + weights[i])])
        halfspaces = np.vstack([own, parent_hull.equations])
        hint = None if hints is None or not np.all(np.isfinite(hints[i])) else hints[i]
        got = _cell(halfspaces, hint, scale)
        if got is None:
            continue
        verts, hull, face_area = got
        cells[i], volumes[i] = verts, hull.volume
        centroids[i] = verts[hull.vertices].mean(axis=0)
        rows.append(np.full(len(nb), i))
        cols.append(nb)
        areas.append(face_area[:len(nb)])
    cat = (lambda parts, dt: np.concatenate(parts).astype(dt) if parts else np.zeros(0, dt))
    return cells, volumes, (cat(rows, int), cat(cols, int), cat(areas, float)), centroids


def laguerre_cells(parent_vertices, seeds, weights):
    """Vertices (k, 3) of each seed's power cell clipped to the convex hull of `parent_vertices`,
    None for an empty cell. Cell i: the parent points x with |x - s_i|^2 - w_i <= |x - s_j|^2 - w_j
    for every j (seeds (n, 3) m, weights (n,) m^2). With equal weights: the Voronoi cells."""
    seeds = np.asarray(seeds, dtype=float)
    weights = np.asarray(weights, dtype=float)
    cells, _, _, _ = _power_cells(ConvexHull(np.asarray(parent_vertices, dtype=float)), seeds, weights,
                                  hints=seeds)
    return cells


# --------------------------------------------------------------------------- weights
@dataclass(frozen=True)
class WeightSolution:
    """Result of solve_weights: weights (m^2), each cell's vertices (None if empty) and volume
    (m^3), the largest relative volume error, the Newton iterations and whether the tolerance
    was reached."""

    weights: np.ndarray
    cells: list
    volumes: np.ndarray
    max_relative_error: float
    iterations: int
    converged: bool


def _hessian(faces, seeds, n):
    """The Jacobian dV_i/dw_j (minus the concave dual's Hessian): -A_ij / (2 |s_i - s_j|) off the
    diagonal, minus the row sum on it (a graph Laplacian, dense: n is at most a few hundred).
    Face areas symmetrised."""
    i, j, area = faces
    coef = area / (2.0 * np.linalg.norm(seeds[i] - seeds[j], axis=1))
    h = np.zeros((n, n))
    np.add.at(h, (i, j), -0.5 * coef)
    np.add.at(h, (j, i), -0.5 * coef)
    h[np.diag_indices(n)] = -h.sum(axis=1)
    return h


def _revive(weights, seeds, empty, radius):
    """Fallback for vanished cells: raise each empty cell's weight until its seed is in its own
    cell by (radius/2)^2 of power (w_i > max_j (w_j - |s_i - s_j|^2))."""
    w = weights.copy()
    for i in np.flatnonzero(empty):
        power = w - ((seeds - seeds[i]) ** 2).sum(axis=1)
        power[i] = -np.inf
        w[i] = power.max() + 0.25 * radius[i] ** 2
    return w


def _newton_step(h, gradient, alive):
    """Newton direction on the living cells, the first one's weight held (the Laplacian's null
    space is a common shift)."""
    idx = np.flatnonzero(alive)
    step = np.zeros(len(gradient))
    sub = h[np.ix_(idx[1:], idx[1:])]
    step[idx[1:]] = np.linalg.lstsq(sub, gradient[idx[1:]], rcond=None)[0]
    return step


#: solve_weights stops, stalled, after this many tessellations (each trial step is one):
#: measured, a breakage of a cube into 218 cells (t10' 10 %, down to 0.1 of its size) that never
#: met its tolerance spent 61 s on 600 of them, halving steps down to 1e-6; converging solves
#: take 8-60
MAX_TESSELLATIONS = 60


def solve_weights(parent_vertices, seeds, target_volumes, tol=1e-3, max_iter=60, weights=None):
    """Weights (m^2) whose clipped power cells have the target volumes (m^3, summing to the
    parent's) within `tol` relative each: damped Newton (Kitagawa, Merigot and Thibert): a step is
    halved until every cell keeps at least half the smallest of its target and present volume and
    the volume error shrinks; past MAX_TESSELLATIONS trials it stops, stalled. Empty cells at
    the start are revived (_revive). Returns a WeightSolution; `converged` is False when it
    stalled or max_iter Newton steps did not reach `tol`."""
    hull = ConvexHull(np.asarray(parent_vertices, dtype=float))
    seeds = np.asarray(seeds, dtype=float)
    target = np.asarray(target_volumes, dtype=float)
    radius = np.cbrt(3.0 * target / (4.0 * np.pi))
    w = radius ** 2 if weights is None else np.asarray(weights, dtype=float).copy()
    cells, vol, faces, cent = _power_cells(hull, seeds, w, hints=seeds)
    for _ in range(5):
        if np.all(vol > 0.0):
            break
        w = _revive(w, seeds, vol <= 0.0, radius)
        cells, vol, faces, cent = _power_cells(hull, seeds, w, hints=np.where(np.isnan(cent), seeds, cent))
    it = made = 0
    for it in range(1, max_iter + 1):
        err = np.abs(vol - target) / target
        if err.max() <= tol:
            return WeightSolution(w, cells, vol, float(err.max()), it - 1, True)
        gradient = target - vol
        step = _newton_step(_hessian(faces, seeds, len(seeds)), gradient, vol > 0.0)
        floor = 0.5 * np.minimum(target, np.where(vol > 0.0, vol, target))
        tau = 1.0
        while tau > 1e-6:
            trial = _power_cells(hull, seeds, w + tau * step, hints=cent)
            made += 1
            if (np.all(trial[1] >= floor)
                    and np.linalg.norm(target - trial[1]) <= (1.0 - 0.5 * tau) * np.linalg.norm(gradient)):
                break
            tau *= 0.5
        if made > MAX_TESSELLATIONS:       # stalled: the cells as they were
            return WeightSolution(w, cells, vol, float(err.max()), it, False)
        w = w + tau * step
        cells, vol, faces, cent = trial
    err = np.abs(vol - target) / target
    return WeightSolution(w, cells, vol, float(err.max()), it, bool(err.max() <= tol))


# --------------------------------------------------------------------------- one breakage
def progeny_law(t10, beta_params, law="incomplete_beta"):
    """Fraction (0-1) of the progeny mass passing relative size x (of the parent's sieve size),
    as a function of x, at this t10' (%).

    "incomplete_beta": Eq. 10 (model.progeny_passing). "gaudin_schuhmann": (x / 1)^lambda
    (model.fines_passing, top size the parent's) with lambda = ln(100 / t10') / ln 10, the line
    that passes t10' at x = 1/10 and 100 % at the parent's size.
    """
    if law == "incomplete_beta":
        return lambda x: progeny_passing(t10, beta_params, x) / 100.0
    if law == "gaudin_schuhmann":
        exponent = np.log(100.0 / t10) / np.log(10.0)
        return lambda x: fines_passing(x, 1.0, exponent)
    raise ValueError(f"law = {law!r}: accepted {', '.join(LAWS)}")


def cell_volume(x):
    """Volume, in units of the parent's sieve size cubed, of a cell whose sieve size is x (of the
    parent's): V = k (V^(1/3))^c x^3 solved for V (CELL_SHAPE_FACTOR, CELL_SHAPE_EXPONENT)."""
    return (CELL_SHAPE_FACTOR * np.asarray(x, dtype=float) ** 3) ** (1.0 / (1.0 - CELL_SHAPE_EXPONENT / 3.0))


def target_sizes(rng, passing, volume_of, smallest):
    """Relative sieve sizes (of the parent's) of the resolved fragments, coarse to fine, and the
    volume fraction passing(smallest) left below `smallest` (relative) for the ledger.

    The sizes are drawn one by one from the number distribution of the law above `smallest`
    (the mass in [x, x + dx] over a fragment's volume fraction v(x) = volume_of(x)), until their
    volumes reach the 1 - passing(smallest) to give out; then every volume is scaled by the
    same factor (at most 1) to close it, each size following its volume. Every piece is drawn
    alike, so the mass passing each size follows the curve on average: over 400 random convex
    parents the volumes drawn pass 1/2 and 1/4 of the parent within 1.7 and 0.2 points of Eq. 10
    at t10' 2-20 % (a walk down the curve that gave each fragment a random place in the mass
    slice it fills passed 8.9 % at 1/2 against 14.8 % at 2 %: a first fragment could take
    the parent's whole size).
    """
    grid = np.geomspace(min(smallest, 1.0), 1.0, 4000)
    curve = passing(grid)
    vol = volume_of(grid)
    ledger = float(curve[0])
    left = 1.0 - ledger
    if left <= 0.0:
        return np.zeros(0), 1.0
    mid = np.sqrt(grid[1:] * grid[:-1])
    number = np.concatenate([[0.0], np.cumsum(np.diff(curve) / volume_of(mid))])
    sizes, volumes = [], []
    while sum(volumes) < left:
        x = float(np.interp(rng.random() * number[-1], number, grid))
        sizes.append(x)
        volumes.append(float(volume_of(x)))
    scale = left / sum(volumes)
    return np.array([float(np.interp(v * scale, vol, grid)) for v in volumes]), ledger


def _inside(hull, points):
    """Points strictly inside the hull."""
    return np.all(points @ hull.equations[:, :3].T + hull.equations[:, 3] < 0.0, axis=1)


def place_seeds(rng, parent_hull, radii, candidates=8):
    """Seeds inside the parent, largest first: of `candidates` uniform points inside it, each
    takes the one farthest from the seeds placed, in units of the sum of the two cells'
    volume-equivalent radii (Mitchell's best candidate): large cells' seeds spread apart, and
    every cell starts with room near its seed."""
    lo, hi = parent_hull.min_bound, parent_hull.max_bound
    seeds = np.empty((len(radii), 3))
    for k, r in enumerate(radii):
        pts = np.empty((0, 3))
        while len(pts) < candidates:
            trial = lo + (hi - lo) * rng.random((4 * candidates, 3))
            pts = np.vstack([pts, trial[_inside(parent_hull, trial)]])
        pts = pts[:candidates]
        if k:
            gap = np.linalg.norm(pts[:, None, :] - seeds[None, :k, :], axis=2) / (r + radii[None, :k])
            pts = pts[[np.argmax(gap.min(axis=1))]]
        seeds[k] = pts[0]
    return seeds


@dataclass(frozen=True)
class Fragmentation:
    """One breakage of a convex parent into convex cells (lengths m, volumes m^3).

    Resolved cells (sieve size at least smallest_size): vertices (list of (k, 3)), volumes,
    centroids (n, 3), sieve_sizes. The ledger: cells finer than smallest_size, with the same four
    fields; their mass is spread below smallest_size by the law (ledger_passing). Resolved plus
    ledger volumes equal parent_volume to round-off. solution: the WeightSolution.
    """

    vertices: list
    volumes: np.ndarray
    centroids: np.ndarray
    sieve_sizes: np.ndarray
    ledger_vertices: list
    ledger_volumes: np.ndarray
    ledger_centroids: np.ndarray
    ledger_sieve_sizes: np.ndarray
    parent_volume: float
    parent_sieve_size: float
    smallest_size: float
    t10: float
    law: str
    beta_params: object
    solution: WeightSolution

    @property
    def ledger_volume(self):
        """Volume (m^3) of the ledger's cells."""
        return float(self.ledger_volumes.sum())

    def passing(self, sizes):
        """Volume fraction of the parent passing each sieve size (m): resolved cells at their
        sieve size, the ledger spread below smallest_size along the law (renormalised there)."""
        sizes = np.atleast_1d(np.asarray(sizes, dtype=float))
        law = progeny_law(self.t10, self.beta_params, self.law)
        x = np.minimum(sizes, self.smallest_size) / self.parent_sieve_size
        share = law(x) / law(self.smallest_size / self.parent_sieve_size)
        resolved = (self.volumes[None, :] * (self.sieve_sizes[None, :] <= sizes[:, None])).sum(axis=1)
        return (resolved + self.ledger_volume * share) / self.parent_volume


def _ledger_targets(ledger_fraction, resolved_fractions):
    """Volume fractions of the ledger's cells: the ledger split into equal cells no larger than
    the largest resolved target (they are not fragments: few cells keep the cost down)."""
    if ledger_fraction <= 0.0:
        return np.zeros(0)
    cap = resolved_fractions.max() if len(resolved_fractions) else ledger_fraction
    count = int(np.ceil(ledger_fraction / cap))
    return np.full(count, ledger_fraction / count)


#: fragment_cells places the seeds anew, up to PLACEMENTS times, while the weight solver ends
#: with a cell more than FAR_OFF off its target volume (relative): measured, 1 breakage in 10 of
#: a cube into 218 cells stalled at once with a cell 82 times its target; new seeds solved it
PLACEMENTS = 3
FAR_OFF = 0.1


def fragment_cells(rng, parent_vertices, t10, beta_params, smallest_size, law="incomplete_beta",
                   tol=1e-3, max_iter=30):
    """Break a convex parent (vertices (n, 3), m) at t10' (%) into clipped Laguerre cells.

    Target sieve sizes come from the law (progeny_law, target_sizes); a size becomes a target
    volume by cell_volume (the measured volume-to-sieve-size relation of these cells), the
    ledger's share is split by _ledger_targets, seeds are placed by place_seeds, the weights
    solved by solve_weights. Each cell is then measured: a resolved target whose cell sieves
    finer than smallest_size (m) joins the ledger. Every random draw from `rng`.
    """
    parent = convex_polyhedron(parent_vertices)
    hull = ConvexHull(parent.vertices)
    unit = parent.sieve_size ** 3 / parent.volume
    passing = progeny_law(t10, beta_params, law)
    sizes, ledger = target_sizes(rng, passing, lambda x: unit * cell_volume(x),
                                 smallest_size / parent.sieve_size)
    fractions = unit * cell_volume(sizes)
    fractions = np.concatenate([fractions, _ledger_targets(ledger, fractions)])
    fractions /= fractions.sum()          # round-off: the targets close the parent's volume
    targets = fractions * parent.volume
    sol = None
    for _ in range(PLACEMENTS):       # seeds placed anew while the solver stalls far off
        seeds = place_seeds(rng, hull, np.cbrt(3.0 * targets / (4.0 * np.pi)))
        trial = solve_weights(parent.vertices, seeds, targets, tol=tol, max_iter=max_iter)
        if sol is None or trial.max_relative_error < sol.max_relative_error:
            sol = trial
        if sol.max_relative_error <= FAR_OFF:
            break
    kept = [i for i, c in enumerate(sol.cells) if c is not None]
    props = [convex_polyhedron(sol.cells[i]) for i in kept]
    sieve = np.array([p.sieve_size for p in props])
    resolved = (np.array(kept) < len(sizes)) & (sieve >= smallest_size)

    def pick(mask):
        chosen = [p for p, keep in zip(props, mask) if keep]
        return ([p.vertices for p in chosen], np.array([p.volume for p in chosen]),
                np.array([p.centroid for p in chosen]).reshape(-1, 3),
                np.array([p.sieve_size for p in chosen]))

    return Fragmentation(*pick(resolved), *pick(~resolved), parent.volume, parent.sieve_size,
                         float(smallest_size), float(t10), law, beta_params, sol)
