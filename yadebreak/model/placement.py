"""Where fragments go inside their parent and how they move (docs/model.md Section 8). Never imports yade.

Coarse fragments are laid side by side across the direction of the stress that broke the parent
(the normal of its most energetic contact); finer ones fill the remaining room, nearer the loaded
point. Every fragment lies inside the parent's sphere. Velocities follow the parent's rigid-body
field v + w x r, corrected so that the total linear momentum is the parent's exactly.
"""
from __future__ import annotations

import numpy as np

#: Fragments at least this large (relative to the parent) are "coarse": laid across the load.
COARSE_RELATIVE_SIZE = 0.45
_CANDIDATES = 12


def _perpendicular_basis(direction):
    n = np.asarray(direction, dtype=float)
    norm = np.linalg.norm(n)
    n = np.array([0.0, 0.0, 1.0]) if not np.isfinite(norm) or norm == 0 else n / norm
    helper = np.array([1.0, 0.0, 0.0]) if abs(n[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    u = np.cross(n, helper)
    u /= np.linalg.norm(u)
    return n, u, np.cross(n, u)


def place_fragments(center, radius, fragment_radii, load_direction, rng):
    """Centres (k x 3, metres) for fragments of the given radii inside a parent sphere.

    center, radius: the parent's; load_direction: unit vector from the parent's centre towards the
    loaded point (the most energetic contact). Fragments are handled largest first. Coarse ones
    (radius >= 0.45 R) go in the plane through the centre normal to the load, spread at equal
    angles and pushed out to touch the parent's surface; each finer one takes, among a few random
    points inside the parent, the one that overlaps the spheres already placed least, with ties
    broken towards the loaded point. Every centre satisfies |c - center| <= R - r.
    """
    center = np.asarray(center, dtype=float)
    radii = np.asarray(fragment_radii, dtype=float)
    n, u, w = _perpendicular_basis(load_direction)
    order = np.argsort(-radii, kind="stable")
    out = np.empty((len(radii), 3))
    coarse = [i for i in order if radii[i] >= COARSE_RELATIVE_SIZE * radius]
    phase = rng.uniform(0.0, 2.0 * np.pi)
    for j, i in enumerate(coarse):
        angle = phase + 2.0 * np.pi * j / len(coarse)
        reach = radius - radii[i]
        out[i] = center + reach * (np.cos(angle) * u + np.sin(angle) * w)
    fine = order[len(coarse):]
    placed_c = np.empty((len(radii), 3))           # centres placed so far, in placing order
    placed_r = np.empty(len(radii))
    m = len(coarse)
    placed_c[:m] = out[coarse] if m else placed_c[:0]
    placed_r[:m] = radii[coarse]
    if len(fine):
        # every fine fragment's candidates at once: random points in the ball of radius `reach`,
        # the first one on the loaded side (drawn fragment by fragment, in the order a loop would)
        draws = [(rng.normal(size=(_CANDIDATES, 3)), rng.random(_CANDIDATES), rng.random())
                 for _ in fine]
        dirs = np.array([d[0] for d in draws])
        dirs /= np.linalg.norm(dirs, axis=2, keepdims=True)
        reach = np.maximum(radius - radii[fine], 0.0)
        dist = reach[:, None] * np.array([d[1] for d in draws]) ** (1.0 / 3.0)
        cand = center + dirs * dist[:, :, None]
        cand[:, 0] = center + (n[None, :] * reach[:, None]) * np.array([d[2] for d in draws])[:, None]
        scale = 1e-3 * radius
        for f, i in enumerate(fine):
            bias = scale * ((cand[f] - center) @ n) / max(reach[f], 1e-300)
            if m:
                diff = cand[f][:, None, :] - placed_c[None, :m, :]
                gap = np.sqrt((diff * diff).sum(axis=2)) - (placed_r[None, :m] + radii[i])
                score = np.maximum(-gap, 0.0).sum(axis=1) - bias
            else:
                score = -bias
            out[i] = cand[f, int(np.argmin(score))]
            placed_c[m] = out[i]
            placed_r[m] = radii[i]
            m += 1
    # guard against round-off pushing a centre a hair outside the parent
    offset = out - center
    dist = np.linalg.norm(offset, axis=1)
    limit = np.maximum(radius - radii, 0.0)
    too_far = dist > limit
    if np.any(too_far):
        out[too_far] = center + offset[too_far] * (limit[too_far] / dist[too_far])[:, None]
    return out


def fragment_velocities(centers, masses, parent_center, velocity, angular_velocity):
    """Velocities (k x 3) from the parent's field v + w x (c - parent_center), shifted by a common
    vector so that sum(m_i v_i) equals M v exactly (M = sum m_i, the parent's mass)."""
    centers = np.asarray(centers, dtype=float)
    masses = np.asarray(masses, dtype=float)
    velocity = np.asarray(velocity, dtype=float)
    omega = np.asarray(angular_velocity, dtype=float)
    vel = velocity + np.cross(omega, centers - np.asarray(parent_center, dtype=float))
    total = masses.sum()
    correction = (total * velocity - masses @ vel) / total
    return vel + correction


def spin_scale(centers, masses, radii, parent_center, parent_inertia, angular_velocity):
    """The factor (<= 1) on the parent's angular velocity w that the fragments take, so that their
    rotational energy, spin plus the rigid field w x (c_i - c_cm) about their centre of mass,
    is at most the parent's I w^2 / 2 (fragments far from the centre would otherwise carry more:
    a replacement must not create energy). 1 when the field holds no more, or w = 0. SI units."""
    omega = np.asarray(angular_velocity, dtype=float)
    masses = np.asarray(masses, dtype=float)
    parent = 0.5 * parent_inertia * (omega @ omega)
    if parent == 0.0:
        return 1.0
    orbit = np.cross(omega, np.asarray(centers, dtype=float) - np.asarray(parent_center, float))
    orbit -= (masses @ orbit) / masses.sum()
    held = 0.5 * (masses @ (orbit * orbit).sum(axis=1)
                  + (0.4 * masses * np.asarray(radii, dtype=float) ** 2).sum() * (omega @ omega))
    return 1.0 if held <= parent else float(np.sqrt(parent / held))


def fragment_masses(parent_mass, fragment_radii):
    """Masses proportional to r^3 summing to the parent's mass (exact to round-off)."""
    vol = np.asarray(fragment_radii, dtype=float) ** 3
    return parent_mass * vol / vol.sum()


def overlapping_pairs(centers, radii):
    """Index pairs (i < j) and their overlaps r_i + r_j - |c_i - c_j| > 0, among the fragments."""
    centers = np.asarray(centers, dtype=float)
    radii = np.asarray(radii, dtype=float)
    i, j = np.triu_indices(len(radii), k=1)
    overlap = radii[i] + radii[j] - np.linalg.norm(centers[i] - centers[j], axis=1)
    keep = overlap > 0.0
    return i[keep], j[keep], overlap[keep]


def rayleigh_time(radius, density, young, poisson):
    """Rayleigh time T_R = pi R sqrt(rho / G) / (0.1631 nu + 0.8766), G = Y / (2 (1 + nu)); SI."""
    shear_modulus = np.asarray(young, dtype=float) / (2.0 * (1.0 + np.asarray(poisson, dtype=float)))
    return np.pi * np.asarray(radius, dtype=float) * np.sqrt(density / shear_modulus) / (
        0.1631 * np.asarray(poisson, dtype=float) + 0.8766)


def hertz_loading_time(radius, density, young, poisson, speed):
    """Duration (s) of the loading half of a Hertz impact of a sphere on a rigid wall at `speed`
    (m/s): t_c / 2, t_c = 2.868 (m^2 / (R E*^2 v))^(1/5), E* = Y / (1 - nu^2). The shortest
    loading a sphere of this size can see at that closing speed (a softer partner lengthens it)."""
    radius = np.asarray(radius, dtype=float)
    mass = density * 4.0 / 3.0 * np.pi * radius ** 3
    e_star = np.asarray(young, dtype=float) / (1.0 - np.asarray(poisson, dtype=float) ** 2)
    speed = np.maximum(np.asarray(speed, dtype=float), 1e-12)
    return 0.5 * 2.868 * (mass ** 2 / (radius * e_star ** 2 * speed)) ** 0.2


def hertz_onset_time(radius, density, young, poisson, speed, specific_energy):
    """Time (s) after first touch at which a sphere hitting a rigid wall at `speed` (m/s) has
    taken `specific_energy` (J/kg) through the contact, early in the loading (overlap = speed x
    time): W / m = 0.4 kno (v t)^2.5 / m with kno = 4/3 E* sqrt(R), i.e.
    e = 2 E* / (5 pi rho) (v t / R)^2.5, E* = Y / (1 - nu^2). A softer partner or a slower
    closing takes longer, so this is the shortest time in which a fresh contact can bring a
    sphere of this size that much energy. SI units. On floats it computes on floats (a damage
    updates one body's bound; 0-d arrays cost microseconds), with the operations numpy takes,
    so the same numbers."""
    if all(type(x) is float for x in (radius, density, young, poisson, speed, specific_energy)):
        speed = max(speed, 1e-12)
    else:
        radius, density, young, poisson, specific_energy = (
            np.asarray(x, dtype=float) for x in (radius, density, young, poisson, specific_energy))
        speed = np.maximum(np.asarray(speed, dtype=float), 1e-12)
    e_star = young / (1.0 - poisson * poisson)
    scale = 5.0 * np.pi * density / (2.0 * e_star)
    return radius / speed * (specific_energy * scale) ** 0.4


def pouring_column(count, radius, holder_radius, rng, gap=0.1):
    """Centres (count x 3, m) of `count` spheres of `radius` (m) spread loosely in a cylinder of
    `holder_radius` (m) around the z axis, above z = 0, to be poured (settled under gravity):
    levels of a triangular lattice of spacing 2 r (1 + gap) clipped to the cylinder, each level
    turned and shifted at random and its points jittered by less than half the gap, so that no
    two spheres touch and none touches the wall. Levels are 2 r (1 + gap) apart, the lowest
    r (1 + gap) above z = 0; the lowest `count` points are taken."""
    if holder_radius <= radius * (1.0 + gap):
        raise ValueError(f"holder radius {holder_radius} m leaves no room for spheres of radius "
                         f"{radius} m")
    spacing = 2.0 * radius * (1.0 + gap)
    reach = holder_radius - radius * (1.0 + gap)        # centres within: clear of the wall
    k = int(np.ceil(reach / spacing)) + 2
    q, r = np.meshgrid(np.arange(-k, k + 1), np.arange(-k, k + 1))
    lattice = np.column_stack(((q + r / 2.0).ravel(), (r * np.sqrt(3.0) / 2.0).ravel())) * spacing
    jitter = 0.45 * gap * radius
    points, z = [], radius * (1.0 + gap)
    while sum(len(p) for p in points) < count:
        angle = rng.uniform(0.0, 2.0 * np.pi)
        turn = np.array([[np.cos(angle), -np.sin(angle)], [np.sin(angle), np.cos(angle)]])
        xy = lattice @ turn.T + rng.uniform(-0.5, 0.5, 2) * spacing
        xy = xy[np.linalg.norm(xy, axis=1) <= reach - jitter]
        xy = xy + rng.uniform(-1.0, 1.0, xy.shape) * jitter / np.sqrt(2.0)
        if not len(xy):
            raise ValueError(f"holder radius {holder_radius} m too small to pour spheres of "
                             f"radius {radius} m")
        points.append(np.column_stack((xy, np.full(len(xy), z))))
        z += spacing
    return np.concatenate(points)[:count]
