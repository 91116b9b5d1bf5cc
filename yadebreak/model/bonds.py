"""Bonded agglomerates: the Timoshenko beam bond model (TBBM) as plain, vectorised functions.

The second breakage model of yadebreak: an agglomerate of primary spheres held by beam bonds that
fail once, permanently, when a stress criterion is met (docs/bonded.md: equations, parameters and
the impact case of a 30 mm glass-ballotini agglomerate). Equation numbers "B1"... are those of
docs/bonded.md. SI units throughout: m, kg, s, N, Pa; moments in N m.

Here: the binder material file, the bond's geometry and beam stiffnesses, bond strengths drawn
bond to bond, the failure criterion, building an agglomerate in a spherical mould (collective
rearrangement), finding the bonds, porosity, per-sphere damage ratio and the fragments (connected
components of the surviving bond graph). Never imports yade.
"""
from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy import sparse, stats
from scipy.sparse import csgraph
from scipy.spatial import cKDTree

from yadebreak.model.intervals import DENSITY, PARTICLE_SIZE, POISSON_RATIO, YOUNG_MODULUS
from yadebreak.model.materials import (Key, MaterialError, available_materials, check_keys,
                                       find_material_file, read_keys, read_table)

#: failure modes, as stored per bond (index) and written in outputs (name)
MODES = ("intact", "tension", "shear", "compression")
INTACT, TENSION, SHEAR, COMPRESSION = range(4)

#: Timoshenko shear coefficient of a circular section implied by Eq. B5 (Phi = 20 R^2 (1 + nu) /
#: (3 L^2) = 12 E I / (kappa G A L^2) with kappa = 0.9)
SHEAR_COEFFICIENT = 0.9


# -- the material file ----------------------------------------------------------------------------
@dataclass(frozen=True)
class Spheres:
    """The primary spheres: glass ballotini in the paper's case. SI units."""

    density: float            # kg/m3
    young_modulus: float      # Pa
    poisson_ratio: float
    friction: float           # sphere-sphere and sphere-target sliding friction
    rolling_friction: float   # mu_r of Eq. B10: the rolling torque's limit mu_r F_n R
    restitution: float        # of non-bonded contacts (Hertz-Mindlin damping)
    diameter_mean: float      # m, truncated Gaussian
    diameter_sd: float        # m
    diameter_min: float       # m
    diameter_max: float       # m


@dataclass(frozen=True)
class Binder:
    """The bonds (beams of binder). SI units: Pa."""

    young_modulus: float
    poisson_ratio: float
    tensile_strength: float
    shear_strength: float
    compressive_strength: float
    strength_cv: float               # coefficient of variation of each strength, bond to bond
    radius_multiplier: float         # lambda of Eq. B2: bond radius over the smaller sphere's
    contact_radius_multiplier: float  # spheres closer than this x (R_a + R_b) are bonded


@dataclass(frozen=True)
class AgglomerateMaterial:
    name: str
    source: str
    description: str
    spheres: Spheres
    binder: Binder

    def with_binder(self, **changes):
        """The same material with binder fields changed (e.g. radius_multiplier=0.5)."""
        fields = {**self.binder.__dict__, **changes}
        return AgglomerateMaterial(self.name, self.source, self.description, self.spheres,
                                   Binder(**fields))


_SPHERE_KEYS = (
    Key.of("density", DENSITY, "kg/m3"),
    Key.of("young_modulus", YOUNG_MODULUS, "GPa", 1e9),
    Key.of("poisson_ratio", POISSON_RATIO, "-"),
    Key("friction", 0.0, True, 10.0, True, "-"),
    Key("rolling_friction", 0.0, True, 1.0, True, "-"),
    Key("restitution", 0.0, False, 1.0, True, "-"),
    Key.of("diameter_mean", PARTICLE_SIZE, "mm", 1e-3),
    Key("diameter_sd", 0.0, True, 1000.0, True, "mm", 1e-3),
    Key.of("diameter_min", PARTICLE_SIZE, "mm", 1e-3),
    Key.of("diameter_max", PARTICLE_SIZE, "mm", 1e-3),
)
_BINDER_KEYS = (
    Key.of("young_modulus", YOUNG_MODULUS, "GPa", 1e9),
    Key.of("poisson_ratio", POISSON_RATIO, "-"),
    Key("tensile_strength", 0.0, False, 1e5, True, "MPa", 1e6),
    Key("shear_strength", 0.0, False, 1e5, True, "MPa", 1e6),
    Key("compressive_strength", 0.0, False, 1e6, True, "MPa", 1e6),
    Key("strength_cv", 0.0, True, 0.5, True, "-"),
    Key("radius_multiplier", 0.0, False, 1.0, True, "-"),
    Key("contact_radius_multiplier", 1.0, True, 2.0, True, "-"),
)


def _section(doc, name, keys, problems):
    return read_keys(read_table(doc, name, "", problems), keys, name, problems)


def load_agglomerate_material(name_or_path):
    """Load and validate an agglomerate material (spheres and binder): a name looked for along
    yadebreak.material_search_path() ('glass_epoxy') or a path to a .toml file. Every problem is
    reported at once in a MaterialError naming the field, the value and the accepted range."""
    text = str(name_or_path)
    path = Path(text)
    if not (text.endswith(".toml") or path.exists()):
        path = find_material_file(text)
        if path is None:
            names = ", ".join(available_materials(kind="bonded_agglomerate"))
            raise MaterialError(text, [f"unknown material '{text}': available are {names} (or a "
                                       ".toml path)"])
    if not path.is_file():
        raise MaterialError(path, ["file not found"])
    try:
        doc = tomllib.loads(path.read_text(encoding="utf-8"))
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise MaterialError(path, [f"not valid TOML: {exc}"]) from None
    if doc.get("kind") != "bonded_agglomerate":        # one line, not one per foreign key
        names = ", ".join(available_materials(kind="bonded_agglomerate"))
        what = ("a particle material (for the other scripts)" if "breakage" in doc
                else f"kind = {doc.get('kind')!r}")
        raise MaterialError(path, [f"{what}, not a bonded agglomerate: accepted a file with "
                                   f"kind = \"bonded_agglomerate\" ({names}, or a .toml path)"])
    problems = []
    check_keys(doc, {"name", "description", "kind", "spheres", "binder"}, "(top level)", problems)
    spheres = _section(doc, "spheres", _SPHERE_KEYS, problems)
    binder = _section(doc, "binder", _BINDER_KEYS, problems)
    if None not in (spheres["diameter_min"], spheres["diameter_max"], spheres["diameter_mean"]):
        if not spheres["diameter_min"] <= spheres["diameter_mean"] <= spheres["diameter_max"]:
            problems.append(f"spheres.diameter_mean = {spheres['diameter_mean'] * 1e3:g} mm: "
                            f"accepted within [diameter_min, diameter_max] = "
                            f"[{spheres['diameter_min'] * 1e3:g}, "
                            f"{spheres['diameter_max'] * 1e3:g}] mm")
    if problems:
        raise MaterialError(path, problems)
    return AgglomerateMaterial(name=str(doc.get("name", path.stem)), source=str(path),
                               description=str(doc.get("description", "")),
                               spheres=Spheres(**spheres), binder=Binder(**binder))


# -- one bond: geometry, stiffness, strength, stresses --------------------------------------------
def bond_radius(radius_a, radius_b, multiplier):
    """Eq. B2: R_B = lambda min(R_a, R_b) (m)."""
    return multiplier * np.minimum(radius_a, radius_b)


def section(bond_radius_m):
    """Eqs. B3-B4 and the polar moment: (area A = pi R^2 (m2), second moment I = pi R^4 / 4 (m4),
    polar moment J = 2 I (m4)) of a circular bond of radius R (m)."""
    r = np.asarray(bond_radius_m, float)
    area = math.pi * r**2
    inertia = math.pi * r**4 / 4.0
    return area, inertia, 2.0 * inertia


def timoshenko_phi(bond_radius_m, length_m, poisson_ratio):
    """Eq. B5: Phi = 20 R_B^2 (1 + nu_B) / (3 L_B^2), the shear-deformation term."""
    return 20.0 * np.asarray(bond_radius_m) ** 2 * (1.0 + poisson_ratio) / (3.0 * np.asarray(
        length_m) ** 2)


@dataclass(frozen=True)
class BeamStiffness:
    """Eq. B6: a Timoshenko beam's stiffnesses in the form of YADE's bonded contact (arrays, one
    value per bond). axial N/m on the change of length; shear N/m on the relative transverse
    displacement of the two ends less the rigid rotation of the chord (the displacement at the
    contact point, which YADE integrates); bending N m/rad on the relative rotation; twist
    N m/rad on the relative twist."""

    axial: np.ndarray
    shear: np.ndarray
    bending: np.ndarray
    twist: np.ndarray


def beam_stiffness(young_modulus, poisson_ratio, bond_radius_m, length_m):
    """Eq. B6 (docs/bonded.md derives it from the two-node Timoshenko element):
    k_n = E A / L, k_s = 12 E I / (L^3 (1 + Phi)), k_b = E I / L, k_t = G J / L."""
    area, inertia, polar = section(bond_radius_m)
    length = np.asarray(length_m, float)
    shear_modulus = young_modulus / (2.0 * (1.0 + poisson_ratio))
    phi = timoshenko_phi(bond_radius_m, length, poisson_ratio)
    return BeamStiffness(axial=young_modulus * area / length,
                         shear=12.0 * young_modulus * inertia / (length**3 * (1.0 + phi)),
                         bending=young_modulus * inertia / length,
                         twist=shear_modulus * polar / length)


def draw_strengths(mean, cv, n, rng):
    """n bond strengths (Pa): normal with mean `mean` and coefficient of variation `cv`, truncated
    at mean +- 3 sd and at zero (a strength is positive). rng: numpy Generator."""
    if cv == 0:
        return np.full(n, float(mean))
    sd = cv * mean
    lo = max(-3.0, -mean / sd)
    return stats.truncnorm.rvs(lo, 3.0, loc=mean, scale=sd, size=n, random_state=rng)


def bond_stresses(axial_force, shear_force, bending_moment, twisting_moment, bond_radius_m):
    """Eq. B7: the beam's largest stresses (Pa), arrays over bonds.

    axial_force: N, positive in tension; shear_force: |F_s| N; bending_moment: the larger of the
    two end moments |M_b| N m; twisting_moment: |M_t| N m.
    Returns (tensile, shear, compressive):
      tensile     = F_x / A + |M_b| R_B / I          (largest tensile stress of the section)
      shear       = |F_s| / A + |M_t| R_B / J
      compressive = -F_x / A + |M_b| R_B / I         (largest compressive stress)
    """
    area, inertia, polar = section(bond_radius_m)
    r = np.asarray(bond_radius_m, float)
    axial = np.asarray(axial_force, float) / area
    bending = np.abs(bending_moment) * r / inertia
    return (axial + bending, np.abs(shear_force) / area + np.abs(twisting_moment) * r / polar,
            -axial + bending)


def failure_modes(tensile, shear, compressive, strengths):
    """Eq. B8: the mode each bond fails in now (INTACT where none). strengths: (tensile, shear,
    compressive) arrays (Pa). A bond over several strengths at once fails in the mode it exceeds
    by the largest ratio."""
    ratios = np.stack([np.asarray(tensile) / strengths[0], np.asarray(shear) / strengths[1],
                       np.asarray(compressive) / strengths[2]])
    worst = np.argmax(ratios, axis=0)
    return np.where(ratios.max(axis=0) > 1.0, worst + 1, INTACT)


# -- building an agglomerate ----------------------------------------------------------------------
def diameter_law(spheres):
    """The spheres' size law (a Spheres): scipy's truncated Gaussian of their mean, sd and
    bounds (m), frozen; None where sd = 0 (every sphere of the mean size)."""
    if spheres.diameter_sd == 0:
        return None
    sd, mean = spheres.diameter_sd, spheres.diameter_mean
    return stats.truncnorm((spheres.diameter_min - mean) / sd, (spheres.diameter_max - mean) / sd,
                           loc=mean, scale=sd)


def sphere_diameters(n, spheres, rng):
    """n diameters (m) from the truncated Gaussian of `spheres` (a Spheres), seeded by rng."""
    law = diameter_law(spheres)
    if law is None:
        return np.full(n, spheres.diameter_mean)
    return law.rvs(size=n, random_state=rng)


def mould_diameter_for(n, spheres, solid_fraction):
    """The diameter (m) of the spherical mould that n spheres (mean volume of the truncated
    Gaussian) fill to `solid_fraction` (= 1 - porosity over the mould)."""
    law = diameter_law(spheres)
    mean_cube = spheres.diameter_mean**3 if law is None else law.moment(3)
    solids = n * math.pi / 6.0 * mean_cube
    return (6.0 * solids / (math.pi * solid_fraction)) ** (1.0 / 3.0)


@dataclass(frozen=True)
class Packing:
    """Spheres in a spherical mould centred at the origin. SI units."""

    positions: np.ndarray    # (n, 3) m
    radii: np.ndarray        # (n,) m
    mould_radius: float      # m
    max_overlap: float       # largest overlap left, over the mean diameter
    iterations: int          # rearrangement sweeps made


def pack_in_sphere(diameters, mould_diameter, rng, tolerance=1e-3, max_iterations=20000):
    """Collective rearrangement (after Labra et al., as the document builds its agglomerate):
    spheres of `diameters` (m) dropped at random inside a spherical mould, then moved apart
    pair by pair by their overlaps (each sphere of an overlapping pair by half the overlap) and
    back inside the mould, sweep after sweep, until no overlap exceeds `tolerance` x the mean
    diameter. Reproducible from rng (numpy Generator). Raises ValueError if the spheres do not
    fit (more than 64 % of the mould, or no convergence in max_iterations sweeps)."""
    d = np.asarray(diameters, float)
    radii = 0.5 * d
    n = len(d)
    big_r = 0.5 * mould_diameter
    fraction = float(np.sum(d**3)) / mould_diameter**3
    if fraction > 0.64:
        raise ValueError(f"{n} spheres fill {fraction:.3f} of the mould: accepted <= 0.64 (random "
                         "close packing)")
    # uniform in the ball of radius R - r_i
    direction = rng.normal(size=(n, 3))
    direction /= np.linalg.norm(direction, axis=1)[:, None]
    pos = direction * ((big_r - radii) * rng.random(n) ** (1.0 / 3.0))[:, None]
    tol = tolerance * float(np.mean(d))
    reach = 2.0 * float(radii.max())
    worst = math.inf
    for sweep in range(1, max_iterations + 1):
        pairs = cKDTree(pos).query_pairs(reach, output_type="ndarray")
        i, j = (pairs[:, 0], pairs[:, 1]) if len(pairs) else (np.zeros(0, int),) * 2
        branch = pos[j] - pos[i]
        dist = np.linalg.norm(branch, axis=1)
        overlap = radii[i] + radii[j] - dist
        hit = overlap > 0
        out = np.linalg.norm(pos, axis=1) + radii - big_r
        worst = max(float(overlap.max(initial=0.0)), float(out.max(initial=0.0)))
        if worst <= tol:
            return Packing(pos, radii, big_r, worst / float(np.mean(d)), sweep)
        if hit.any():
            i, j, branch, dist, overlap = i[hit], j[hit], branch[hit], dist[hit], overlap[hit]
            unit = branch / np.maximum(dist, 1e-300)[:, None]
            push = 0.5 * overlap[:, None] * unit * 1.01   # 1 %: converges, does not oscillate
            move = np.zeros_like(pos)
            np.add.at(move, i, -push)
            np.add.at(move, j, push)
            pos += move
        out = np.linalg.norm(pos, axis=1) + radii - big_r
        k = out > 0
        if k.any():
            pos[k] *= ((big_r - radii[k]) / np.linalg.norm(pos[k], axis=1))[:, None]
    raise ValueError(f"collective rearrangement did not converge in {max_iterations} sweeps "
                     f"(largest overlap {worst / np.mean(d):.2e} mean diameters)")


def bond_pairs(positions, radii, contact_radius_multiplier):
    """The bonds of Eq. B1: pairs (i < j) whose centre distance is within
    contact_radius_multiplier x (R_i + R_j). Returns (pairs (m, 2) int, lengths L_B (m, ) m)."""
    reach = contact_radius_multiplier * 2.0 * float(np.max(radii))
    pairs = cKDTree(positions).query_pairs(reach, output_type="ndarray")
    if len(pairs) == 0:
        return pairs.reshape(0, 2), np.zeros(0)
    length = np.linalg.norm(positions[pairs[:, 1]] - positions[pairs[:, 0]], axis=1)
    keep = length <= contact_radius_multiplier * (radii[pairs[:, 0]] + radii[pairs[:, 1]])
    order = np.lexsort((pairs[keep, 1], pairs[keep, 0]))
    return pairs[keep][order], length[keep][order]


def solid_fraction_within(positions, radii, radius, centre=(0.0, 0.0, 0.0)):
    """The exact volume fraction of the ball (centre, radius) (m) that the spheres fill (each
    sphere's lens with the ball counted: spheres cut by its surface count in part). 1 - this is
    the porosity over that ball."""
    dist = np.linalg.norm(np.asarray(positions) - np.asarray(centre), axis=1)
    r = np.asarray(radii, float)
    big = float(radius)
    inside = dist + r <= big
    volume = np.where(inside, 4.0 / 3.0 * math.pi * r**3, 0.0)
    cut = (~inside) & (dist < big + r)
    if cut.any():
        dd, rr = dist[cut], r[cut]
        # sphere-sphere intersection (lens) volume
        lens = (math.pi * (big + rr - dd) ** 2 * (dd**2 + 2 * dd * rr - 3 * rr**2 + 2 * dd * big
                                                  + 6 * rr * big - 3 * big**2) / (12.0 * dd))
        volume[cut] = np.minimum(lens, 4.0 / 3.0 * math.pi * rr**3)
    return float(volume.sum() / (4.0 / 3.0 * math.pi * big**3))


# -- after the impact -----------------------------------------------------------------------------
def damage_ratios(n_spheres, pairs, broken):
    """Per sphere: broken bonds over the bonds it had at the start (Eq. B9); NaN for a sphere that
    had none. pairs: (m, 2) bonds as built; broken: (m,) bool."""
    initial = np.bincount(pairs.ravel(), minlength=n_spheres).astype(float)
    lost = np.bincount(pairs[broken].ravel(), minlength=n_spheres).astype(float)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(initial > 0, lost / initial, np.nan)


def fragments(n_spheres, pairs, intact):
    """Connected components of the surviving bond graph: (label per sphere (n,), sphere count per
    label). pairs: (m, 2); intact: (m,) bool."""
    kept = pairs[intact]
    graph = sparse.coo_matrix((np.ones(len(kept)), (kept[:, 0], kept[:, 1])),
                              shape=(n_spheres, n_spheres))
    count, labels = csgraph.connected_components(graph, directed=False)
    return labels, np.bincount(labels, minlength=count)


def fragment_masses(labels, masses):
    """Mass (kg) of each fragment (index = label), from the spheres' masses (kg)."""
    return np.bincount(labels, weights=masses)


def equivalent_diameters(fragment_mass, density):
    """The diameter (m) of the sphere of each fragment's solid volume."""
    return (6.0 * np.asarray(fragment_mass) / (math.pi * density)) ** (1.0 / 3.0)


def bond_time_scale(mass, inertia, pairs, stiffness, lever_a, lever_b):
    """Eq. B11: the shortest time scale (s) of the bonded network, min over spheres of
    sqrt(m / K_t) and sqrt(I / K_r), where a sphere's K_t sums max(k_n, k_s) over its bonds and
    K_r sums k_b + k_t + k_s d^2 (d: the sphere's lever to the bond's contact point, m). mass
    (kg), inertia (kg m2): per sphere; pairs (m, 2); stiffness: a BeamStiffness; levers: (m,) m.
    inf if there are no bonds. The explicit scheme is stable below sqrt(2) times it."""
    if len(pairs) == 0:
        return math.inf
    n = len(mass)
    k_t = np.maximum(stiffness.axial, stiffness.shear)
    trans = np.bincount(pairs[:, 0], k_t, n) + np.bincount(pairs[:, 1], k_t, n)
    rot_common = stiffness.bending + stiffness.twist
    rot = (np.bincount(pairs[:, 0], rot_common + stiffness.shear * lever_a**2, n)
           + np.bincount(pairs[:, 1], rot_common + stiffness.shear * lever_b**2, n))
    bonded = trans > 0
    return float(min(np.sqrt(mass[bonded] / trans[bonded]).min(),
                     np.sqrt(inertia[bonded] / rot[bonded]).min()))
