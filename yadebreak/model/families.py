"""Progeny families for stochastic sphere replacement (docs/model.md Section 6; Tavares and Chagas).

A broken sphere is replaced by one family of spheres drawn at random from a small set prepared
for the t10' of the event. Convention of the paper's Table 2: relative sizes x_k = 2^(-k/4),
k = 0..9; a sphere of size x_k stands for the mass retained between x_k and x_(k-1); an extra
"dummy" class of spheres of size x_9 = 0.210 stands for all the mass passing 0.210.

How a set is generated (the paper prints only the set for t10' = 3 %):
1. Target class masses from Eq. 10 (model.progeny_passing) at the class boundaries.
2. A pool of integer candidate families around the expected counts, by randomized rounding from
   the coarsest class down (so a family never exceeds the parent's volume), the dummy count
   closing the volume to within half a dummy sphere (0.47 % of the parent); no sphere at x_0 = 1.
3. A linear programme picks probabilities over the pool minimising the absolute class-mass error
   of the mixture. The dual simplex returns a basic solution: with 11 class rows (rank 10) plus
   the normalisation, at most 11 families carry probability, which is the paper's bound.
   Many mixtures meet Eq. 10 equally well; a small cost on each family's own distance from
   Eq. 10 picks the one whose families are each nearest to it, as the paper's are (Table 2: 4-6
   dummies in every family at t10' = 3 %; "the sought size distribution is quickly approached
   after drawing only a few"). Without it the basic solution mixes extremes (at t10' = 9 % on
   copper ore, dummy shares of 1-75 % around the target's 19 %), and since a fragment's
   passing at 1/10 of its parent's size is its dummies' alone, the t10 of a few breakages
   scattered over several times its value.
Exact mass: each family's radii are scaled by (1 / V_f)^(1/3), V_f its volume in parent units
(within 1 %), so the inserted spheres carry exactly the parent's volume; this is done once, in
FamilyTable, and nowhere else.

Never imports yade.
"""
from __future__ import annotations

import bisect
import hashlib
import json
import os
import time
import zipfile
from dataclasses import dataclass, field
from functools import lru_cache

import numpy as np
from scipy.optimize import linprog

from yadebreak import model
from yadebreak.model.cache import cache_folder

#: Class sizes x_k = 2^(-k/4), k = 0..9, then the dummy class at x_9 (Table 2).
CLASS_SIZES = 2.0 ** (-np.arange(10) / 4.0)
RELATIVE_SIZES = np.append(CLASS_SIZES, CLASS_SIZES[-1])
DUMMY = 10                       # column of the dummy class in `counts`
N_CLASSES = 11
CLASS_VOLUMES = RELATIVE_SIZES ** 3
MAX_FAMILIES = 11
VOLUME_TOLERANCE = 0.01          # each family's volume within 1 % of the parent's
TABLE_RATIO = 1.08               # grid ratio of t10': nearest set within sqrt(1.08) - 1 = 3.9 %
_POOL_SIZE = 600
#: cost per unit of a family's own L1 distance from Eq. 10 (classes and markers, in %) against
#: 1 per unit of the mixture's errors: a tie-break, small enough to leave the mixture's errors as
#: they are (measured: the same to 0.01 % from 0.02 to 0.3 on Table 1 and copper ore)
OWN_DISTANCE_COST = 0.05
_FORMAT_VERSION = 2


def eq10_class_fractions(t10, beta_params):
    """Eq. 10 as class mass fractions (sum 1): retained between x_k and x_(k-1), then the dummy."""
    passing = model.progeny_passing(t10, beta_params, CLASS_SIZES) / 100.0   # at x_0 .. x_9
    retained = np.empty(N_CLASSES)
    retained[0] = 0.0                                      # nothing retained above the parent
    retained[1:10] = passing[:-1] - passing[1:]
    retained[DUMMY] = passing[-1]
    return retained / retained.sum()


def _marker_weights(n_values=(1.2, 1.5, 2.0, 4.0)):
    """Rows w with t_n = w @ passing(x_0..x_9): linear interpolation against ln x."""
    log_x = np.log(CLASS_SIZES)
    rows = np.zeros((len(n_values), 10))
    for i, n in enumerate(n_values):
        lx = np.log(1.0 / n)
        k = int(np.searchsorted(-log_x, -lx))           # first boundary with x_k <= 1/n
        if np.isclose(log_x[k], lx):
            rows[i, k] = 1.0
        else:
            w = (log_x[k - 1] - lx) / (log_x[k - 1] - log_x[k])
            rows[i, k - 1], rows[i, k] = 1.0 - w, w
    return rows


_MARKER_ROWS = _marker_weights()


def boundary_passing(class_fractions):
    """Cumulative % passing each class boundary x_0..x_9 for class fractions (..., 11)."""
    f = np.asarray(class_fractions, dtype=float)
    # passing x_k = classes finer than k (k+1 .. 9) plus the dummy class
    tail = np.cumsum(f[..., ::-1], axis=-1)[..., ::-1]      # tail[j] = sum of f[j:]
    return 100.0 * tail[..., 1:N_CLASSES]


def markers_from_classes(class_fractions, n_values=(1.2, 1.5, 2.0, 4.0)):
    """t_n (%) read from a class distribution, interpolated against ln x between boundaries."""
    passing = boundary_passing(class_fractions)
    log_x = np.log(CLASS_SIZES)[::-1]
    flat = passing.reshape(-1, 10)
    out = np.array([[np.interp(np.log(1.0 / n), log_x, row[::-1]) for n in n_values]
                    for row in flat])
    return out.reshape(passing.shape[:-1] + (len(n_values),))


@dataclass(frozen=True)
class FamilySet:
    """The families prepared for one t10' (%).

    relative_sizes: the 11 class sizes (x_0..x_9, then the dummy class at 0.210);
    counts: integers, families x classes; probabilities: one per family, summing to 1.
    """

    t10: float
    relative_sizes: np.ndarray
    counts: np.ndarray
    probabilities: np.ndarray
    target: np.ndarray = field(repr=False)   # Eq. 10 class mass fractions

    @property
    def volumes(self):
        """Each family's volume in units of the parent's."""
        return self.counts @ CLASS_VOLUMES

    @property
    def class_fractions(self):
        """Mass fraction per class of each family (rows sum to 1)."""
        v = self.counts * CLASS_VOLUMES
        return v / v.sum(axis=1, keepdims=True)

    @property
    def mixture_fractions(self):
        """Probability-weighted class mass fractions."""
        return self.probabilities @ self.class_fractions

    def mixture_markers(self, n_values=(1.2, 1.5, 2.0, 4.0)):
        """t_n (%) of the probability-weighted mixture."""
        return markers_from_classes(self.mixture_fractions, n_values)

    def sample(self, rng, size=None):
        """Indices of families drawn with their probabilities."""
        return rng.choice(len(self.probabilities), size=size, p=self.probabilities)


def _fill(counts, expected, start, rng):
    """Randomized rounding of expected counts for classes start..9 within the remaining volume,
    coarse to fine; the dummy count then closes the volume. Returns None if not within 1 %."""
    v = CLASS_VOLUMES
    remaining = 1.0 - counts[:start] @ v[:start]
    for k in range(start, 10):
        mean = min(expected[k], remaining / v[k])
        n = min(int(np.floor(mean + rng.random())), int(np.floor(remaining / v[k] + 1e-12)))
        counts[k] = max(n, 0)
        remaining -= counts[k] * v[k]
    counts[DUMMY] = max(int(np.rint(remaining / v[DUMMY])), 0)
    return tuple(counts) if abs(counts @ v - 1.0) <= VOLUME_TOLERANCE else None


def _candidate_pool(target, rng, pool_size):
    """Integer families near the target; volume within 1 % of the parent's, nothing at x_0.

    Every combination of the four coarse classes (x_1..x_4) that fits in the parent, each filled
    with finer spheres in the target's proportions; then families around the expected counts
    with random jitter, for diversity.
    """
    rows = set()
    v = CLASS_VOLUMES
    fine_share = target[5:] / max(target[5:].sum(), 1e-300)
    for c1 in range(2):
        for c2 in range(3):
            for c3 in range(5):
                for c4 in range(9):
                    counts = np.zeros(N_CLASSES, dtype=np.int64)
                    counts[1:5] = (c1, c2, c3, c4)
                    room = 1.0 - counts[1:5] @ v[1:5]
                    if room < -VOLUME_TOLERANCE:
                        continue
                    expected = np.zeros(N_CLASSES)
                    expected[5:] = max(room, 0.0) * fine_share / v[5:]
                    for _ in range(3):
                        row = _fill(counts.copy(), expected, 5, rng)
                        if row is not None:
                            rows.add(row)
    expected = target / v
    for i in range(pool_size):
        jitter = expected * (np.exp(rng.normal(0.0, 0.4, N_CLASSES)) if i % 3 else 1.0)
        row = _fill(np.zeros(N_CLASSES, dtype=np.int64), jitter, 1, rng)
        if row is not None:
            rows.add(row)
    return np.array(sorted(rows), dtype=np.int64)


def _mixture_lp(fractions, markers, eq10, t10_markers):
    """Probabilities over candidate families minimising 20 * (largest error) + (sum of errors),
    errors being |class mass - Eq. 10| (11 classes) and |t_n - Eq. 10| (n = 1.2, 1.5, 2, 4), in %,
    plus OWN_DISTANCE_COST times the probability-weighted distance of each family from Eq. 10."""
    n_pool = len(fractions)
    values = np.hstack([fractions, markers]).T * 100.0          # rows x families
    target = np.concatenate([eq10, t10_markers / 100.0]) * 100.0
    n_rows = len(target)
    # variables: p (n_pool), a (n_rows, abs errors), z
    n_var = n_pool + n_rows + 1
    a_ub = np.zeros((3 * n_rows, n_var))
    b_ub = np.zeros(3 * n_rows)
    eye = np.eye(n_rows)
    a_ub[:n_rows, :n_pool] = values
    a_ub[:n_rows, n_pool:n_pool + n_rows] = -eye
    b_ub[:n_rows] = target
    a_ub[n_rows:2 * n_rows, :n_pool] = -values
    a_ub[n_rows:2 * n_rows, n_pool:n_pool + n_rows] = -eye
    b_ub[n_rows:2 * n_rows] = -target
    a_ub[2 * n_rows:, n_pool:n_pool + n_rows] = eye
    a_ub[2 * n_rows:, -1] = -1.0
    a_eq = np.zeros((1, n_var))
    a_eq[0, :n_pool] = 1.0
    own = np.abs(values - target[:, None]).sum(axis=0)        # each family's own distance
    c = np.concatenate([OWN_DISTANCE_COST * own, np.ones(n_rows), [20.0]])
    res = linprog(c, A_ub=a_ub, b_ub=b_ub, A_eq=a_eq, b_eq=[1.0], bounds=(0, None),
                  method="highs-ds")
    if res.status != 0:
        raise RuntimeError(res.message)
    return res.x[:n_pool]


def family_set(t10, beta_params=model.TABLE1_BETA_PARAMS, seed=0, pool_size=_POOL_SIZE):
    """Generate the family set for one t10' (%) and material (beta_params of Eq. 10).

    Deterministic for a given seed. See the module docstring for the procedure.
    """
    t10 = float(t10)
    eq10 = eq10_class_fractions(t10, beta_params)
    t10_markers = model.t_markers(t10, beta_params)[:4]
    rng = np.random.default_rng([seed, int(round(t10 * 1e6))])
    pool = _candidate_pool(eq10, rng, pool_size)
    fractions = pool * CLASS_VOLUMES
    fractions /= fractions.sum(axis=1, keepdims=True)
    markers = boundary_passing(fractions) @ _MARKER_ROWS.T / 100.0
    try:
        p = _mixture_lp(fractions, markers, eq10, t10_markers)
        if np.count_nonzero(p > 1e-9) > MAX_FAMILIES:      # keep the paper's bound of 11
            top = np.argsort(-p)[:MAX_FAMILIES]
            p_top = _mixture_lp(fractions[top], markers[top], eq10, t10_markers)
            p = np.zeros(len(pool))
            p[top] = p_top
    except RuntimeError as exc:
        raise RuntimeError(f"family generation failed at t10 = {t10:g} %: {exc}") from None
    keep = p > 1e-9
    p = p[keep] / p[keep].sum()
    counts = pool[keep]
    order = np.argsort(-p, kind="stable")
    return FamilySet(t10=t10, relative_sizes=RELATIVE_SIZES.copy(), counts=counts[order],
                     probabilities=p[order], target=eq10)


@dataclass(frozen=True)
class Family:
    """One drawn family: relative sizes of its spheres (scaled so their volume is exactly the
    parent's), which of them are dummy spheres, and the t10' (%) of the set it came from."""

    relative_sizes: np.ndarray
    is_dummy: np.ndarray
    t10: float


class FamilyTable:
    """Family sets over a geometric grid of t10' from t10_min to t10_max, ready to draw from.

    Grid ratio TABLE_RATIO: the nearest set's t10' is within 3.9 % (relative) of any event's.
    """

    def __init__(self, beta_params, t10_min, t10_max, seed=0, sets=None):
        self.beta_params = {float(k): tuple(v) for k, v in beta_params.items()}
        self.t10_min = float(t10_min)
        self.t10_max = float(t10_max)
        self.seed = seed
        steps = max(1, int(np.ceil(np.log(self.t10_max / self.t10_min) / np.log(TABLE_RATIO))))
        self.grid = np.geomspace(self.t10_min, self.t10_max, steps + 1)
        self._log_mid = list(0.5 * (np.log(self.grid[1:]) + np.log(self.grid[:-1])))
        self.sets = sets if sets is not None else [
            family_set(t, self.beta_params, seed) for t in self.grid]
        # Exact mass, in one place: radii of family f scaled by V_f^(-1/3).
        self._draw_data = []
        for fs in self.sets:
            scale = fs.volumes ** (-1.0 / 3.0)
            fams = []
            for counts, s in zip(fs.counts, scale):
                sizes = np.repeat(fs.relative_sizes, counts) * s
                dummy = np.repeat(np.arange(N_CLASSES) == DUMMY, counts)
                fams.append(Family(sizes, dummy, fs.t10))
            self._draw_data.append((np.cumsum(fs.probabilities), fams))

    def nearest(self, t10):
        """Index of the grid set nearest to t10' (in ln t10)."""
        return bisect.bisect_left(self._log_mid, np.log(max(float(t10), 1e-300)))

    def draw(self, rng, t10):
        """Draw one family for an event of this t10' (%): the nearest set, then a family by its
        probability. A few microseconds."""
        cum, fams = self._draw_data[self.nearest(t10)]
        i = bisect.bisect_right(cum, rng.random() * cum[-1])
        return fams[min(i, len(fams) - 1)]


def _cache_key(beta_key, t10_min, t10_max, seed):
    """Names a table's file: everything that decides its content."""
    text = json.dumps([_FORMAT_VERSION, beta_key, t10_min, t10_max, seed, _POOL_SIZE, TABLE_RATIO])
    return hashlib.sha256(text.encode()).hexdigest()[:20]


def _beta_key(beta_params):
    return tuple(sorted((float(k), tuple(float(x) for x in v)) for k, v in beta_params.items()))


@lru_cache(maxsize=64)
def _table_cached(beta_key, t10_min, t10_max, seed):
    beta_params = dict(beta_key)
    path = cache_folder("families") / f"families-{_cache_key(beta_key, t10_min, t10_max, seed)}.npz"
    if path.exists():
        try:
            data = np.load(path)
            sets = []
            for i, t in enumerate(data["grid"]):
                sets.append(FamilySet(float(t), RELATIVE_SIZES.copy(), data[f"counts{i}"],
                                      data[f"prob{i}"], eq10_class_fractions(t, beta_params)))
            return FamilyTable(beta_params, t10_min, t10_max, seed, sets=sets)
        except (OSError, KeyError, ValueError, EOFError, zipfile.BadZipFile):
            pass                               # a damaged cache file is rebuilt, never trusted
    table = FamilyTable(beta_params, t10_min, t10_max, seed)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        arrays = {"grid": table.grid}
        for i, fs in enumerate(table.sets):
            arrays[f"counts{i}"] = fs.counts
            arrays[f"prob{i}"] = fs.probabilities
        tmp = path.with_name(f"{path.stem}.{os.getpid()}.tmp.npz")  # processes may race
        np.savez(tmp, **arrays)
        os.replace(tmp, path)
    except OSError:
        pass                                   # no writable cache: the memory cache still works
    return table


def family_passing(counts, t10, beta_params, sieves, fines):
    """Passing (%) of one family (its class counts, of a set made for `t10`') at `sieves`
    (relative to the parent's size): its resolved spheres at their class sizes, its dummies'
    mass spread by `fines` (model.dummy_fines_passing: "gaudin_schuhmann", the paper's Eqs.
    11-12, or "eq10")."""
    counts = np.asarray(counts)
    resolved = (np.repeat(RELATIVE_SIZES[:DUMMY], counts[:DUMMY]),
                np.repeat(CLASS_VOLUMES[:DUMMY], counts[:DUMMY]))
    dummies = ([counts[DUMMY] * CLASS_VOLUMES[DUMMY]], [1.0], [t10])
    sd = model.size_distribution(np.asarray(sieves, dtype=float), resolved=resolved,
                                 dummies=dummies, beta_params=beta_params, fines=fines)
    return sd.passing_percent


def family_table(beta_params, t10_min, t10_max, seed=0):
    """The FamilyTable for a material, built once per process and cached on disk
    (<cache>/families: yadebreak.model.cache)."""
    return _table_cached(_beta_key(beta_params), float(t10_min), float(t10_max), int(seed))


def table_for(material, seed=0):
    """The FamilyTable of a breakable Material: t10' from Material.t10_min (Eq. 9 for Tavares)
    up to Material.t10_ceiling (A, or Ab-T10's M)."""
    return family_table(material.beta_params, material.t10_min, material.t10_ceiling, seed)


def draw(rng, t10, beta_params=model.TABLE1_BETA_PARAMS, t10_min=None, t10_max=None, seed=0):
    """Draw one family (a Family: relative sizes, dummy mask, set t10') for an event of this t10'.

    The table spans t10_min..t10_max (default 0.5 % .. 80 %); it is built on first use and cached.
    """
    table = family_table(beta_params, 0.5 if t10_min is None else t10_min,
                         80.0 if t10_max is None else t10_max, seed)
    return table.draw(rng, t10)


def build_time(beta_params, t10_min, t10_max, seed=0):
    """Seconds to build one table without any cache (for the benchmark)."""
    start = time.perf_counter()
    FamilyTable(beta_params, t10_min, t10_max, seed)
    return time.perf_counter() - start
