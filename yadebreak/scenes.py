"""Scene builders shared by the scripts and tests (coupling layer: imports yade)."""
from __future__ import annotations

import math

import numpy as np

# the coupling makes yade importable from Debian's python3 first
from . import placement
from .coupling import add_materials, attach, run_steps
from .coupling._yade import O, utils, wrapper as _w


def hertz_engines(ip2, gravity=(0.0, 0.0, 0.0), facets=False):
    """The standard engine list: collider, Hertz-Mindlin, undamped Newton."""
    bounds = [_w.Bo1_Sphere_Aabb(), _w.Bo1_Wall_Aabb()]
    geoms = [_w.Ig2_Sphere_Sphere_ScGeom(), _w.Ig2_Wall_Sphere_ScGeom()]
    if facets:
        bounds.append(_w.Bo1_Facet_Aabb())
        geoms.append(_w.Ig2_Facet_Sphere_ScGeom())
    return [
        _w.ForceResetter(),
        _w.InsertionSortCollider(bounds),
        _w.InteractionLoop(geoms, [ip2], [_w.Law2_ScGeom_MindlinPhys_Mindlin(label="law")]),
        _w.NewtonIntegrator(damping=0.0, gravity=gravity, label="newton"),
    ]


def impact_scene(material="copper_ore", size=5.5e-3, speeds=(5.0,), target="steel", seed=0,
                 gap_fraction=0.02, **options):
    """Particles of one size fired normally at a plate (z = 0), one per speed, far apart.

    Returns (controller, particle ids). The target is non-breakable even if it is the particle's
    own material (a separate YADE material with the same properties).
    """
    O.reset()
    labels = {"particle": material, "target": target}
    ip2, _ = add_materials(labels, stiffness_scale=options.pop("stiffness_scale", 1.0))
    O.bodies.append(utils.wall(0.0, axis=2, sense=1, material="target"))
    radius = size / 2.0
    n = len(speeds)
    side = int(math.ceil(math.sqrt(n)))
    ids = []
    for k, v in enumerate(speeds):
        x, y = (k % side) * 4 * size, (k // side) * 4 * size
        b = utils.sphere((x, y, radius * (1 + gap_fraction)), radius, material="particle")
        b.state.vel = (0.0, 0.0, -float(v))
        ids.append(O.bodies.append(b))
    O.engines = hertz_engines(ip2)
    brk = attach({"particle": material}, seed=seed, **options)
    return brk, ids


def run_until_rebound(ids, max_steps=200000, check_every=50, brk=None):
    """Run until the listed bodies have left the plate (moving away, touching nothing), or
    max_steps. With the controller `brk`, also until their fragments are done: fragments go on
    breaking while they are loaded, so the run does not stop when the original particles have
    broken (without `brk` it does: primary breakage only, as tests of Eq. 8 want; with it, the
    single-impact script measures successive breakage at high energies).

    The fragments are done (at once if nothing was fired: no impact) when none heads for the plate
    faster than 10 % of the fastest listed body's initial speed (1 % of the impact's specific
    energy), or when none has broken for five Hertz loading times of the listed bodies at that
    speed (the cascade is over; what is still flying back is slow: measured, 200,000 steps of a
    fragment cloud's tail at 1000 J/kg added no breakage)."""
    fired = [O.bodies[i] for i in ids if i < len(O.bodies) and O.bodies[i] is not None]
    speed = max((b.state.vel.norm() for b in fired), default=0.0)
    follow = brk is not None and speed > 0.0
    quiet = 5.0 * _loading_time(fired[0], speed) if follow else None
    done_steps = 0
    while done_steps < max_steps:
        run_steps(check_every)
        done_steps += check_every
        if all(_left(i) for i in ids) and (not follow or _all_away(0.1 * speed)
                                           or O.time - _last_breakage(brk) > quiet):
            break
    return done_steps


def _loading_time(b, speed):
    return float(placement.hertz_loading_time(b.shape.radius, b.material.density, b.material.young,
                                              b.material.poisson, speed))


def _last_breakage(brk):
    """Time (s) of the controller's last breakage event (0 if none)."""
    return next((e["time"] for e in reversed(brk.events) if e["kind"] == "breakage"), 0.0)


def _all_away(slow):
    """No body moves towards the plate faster than `slow` (m/s): a pass over the scene's bodies
    every check_every steps (scripts only)."""
    return all(b.state.vel[2] >= -slow for b in O.bodies if b is not None and b.dynamic)


def impact_again(brk, alive, home, speed):
    """One more impact (paper Fig. 11): the particles `alive` go back to `home` (id -> position)
    and are fired at `speed` normally at the plate, without spin; run to rebound. The ones that
    broke leave the test (erased). Returns the ids still alive."""
    for i in alive:
        state = O.bodies[i].state
        state.pos = home[i]
        state.vel = (0.0, 0.0, -speed)
        state.angVel = (0.0, 0.0, 0.0)
    run_until_rebound(alive)
    broken = {e["id"] for e in brk.breakage_events}
    for i in alive:
        if i in broken:
            O.bodies.erase(i)
    return [i for i in alive if i not in broken]


def _left(i):
    b = O.bodies[i] if i < len(O.bodies) else None
    if b is None:
        return True                # broken and replaced: its fragments fly on
    return b.state.vel[2] >= 0.0 and len(O.interactions.withBody(i)) == 0


BALL_DIAMETER = 0.088          # m, the paper's steel ball
BALL_MASS = 2.78               # kg


def hex_bed_positions(size, rings, layers=1, gap=0.01):
    """Centres of a hexagonal bed: a central particle and `rings` rings per layer (1 + 3k(k+1)
    particles), layers stacked in the hollows (ABAB), each touching the three below it, the
    bottom layer touching z = 0."""
    spacing = size * (1.0 + gap)
    radius = size / 2.0
    base = []
    for q in range(-rings, rings + 1):
        for r in range(-rings, rings + 1):
            if max(abs(q), abs(r), abs(q + r)) <= rings:
                base.append((spacing * (q + r / 2.0), spacing * r * math.sqrt(3.0) / 2.0))
    base = np.array(base)
    reach = np.max(np.linalg.norm(base, axis=1)) + 1e-9
    offset = np.array([spacing / 2.0, spacing * math.sqrt(3.0) / 6.0])
    out = []
    for layer in range(layers):
        xy = base + (offset if layer % 2 else 0.0)
        if layer % 2:
            xy = xy[np.linalg.norm(xy, axis=1) <= reach]
        z = radius + layer * math.sqrt(size ** 2 - spacing ** 2 / 3.0)
        out += [(x, y, z) for x, y in xy]
    return np.array(out)


def bed_impact_scene(material="copper_ore", size=5.5e-3, rings=3, layers=1, energy=3.05,
                     seed=1, settle_steps=3000, **options):
    """The paper's unconfined bed impact: a 88 mm steel ball on a bed resting on a steel anvil.

    The ball starts just above the bed with the speed of its drop, v = sqrt(2 E / m). Beds of
    several layers are held by a cylindrical steel holder, removed when the ball first touches a
    particle (hold_release() does that). Returns (controller, info dict).
    """
    O.reset()
    ip2, mats = add_materials({"ore": material, "steel": "steel"},
                              stiffness_scale=options.pop("stiffness_scale", 1.0))
    anvil = O.bodies.append(utils.wall(0.0, axis=2, sense=1, material="steel"))
    centers = hex_bed_positions(size, rings, layers)
    particles = [O.bodies.append(utils.sphere(tuple(c), size / 2.0, material="ore"))
                 for c in centers]
    holder = []
    if layers > 1:
        reach = np.max(np.linalg.norm(centers[:, :2], axis=1)) + size / 2.0 + 0.02 * size
        height = centers[:, 2].max() + size
        from yade import geom    # utils.facetCylinder is broken in YADE 2023.02a
        holder = O.bodies.append(geom.facetCylinder((0, 0, height / 2.0), reach, height,
                                                    segmentsNumber=24, wallMask=4,
                                                    material="steel"))
    O.engines = hertz_engines(ip2, gravity=(0.0, 0.0, -9.81), facets=bool(holder))
    if layers > 1 and settle_steps:           # settle the stack before anything is tracked
        scene_dt = O.dt                       # the settling's own step; attach() sets the run's
        O.dt = 0.2 * utils.PWaveTimeStep()
        newton = O.engines[-1]
        newton.damping = 0.4
        O.run(settle_steps, True)
        newton.damping = 0.0
        O.dt = scene_dt
        for i in particles:
            O.bodies[i].state.vel = (0, 0, 0)
            O.bodies[i].state.angVel = (0, 0, 0)
    top = max(O.bodies[i].state.pos[2] for i in particles) + size / 2.0
    ball_radius = BALL_DIAMETER / 2.0
    ball = utils.sphere((0.0, 0.0, top + ball_radius + 0.02 * size), ball_radius, material="steel")
    ball.state.mass = BALL_MASS
    inertia = 0.4 * BALL_MASS * ball_radius ** 2
    ball.state.inertia = (inertia, inertia, inertia)
    speed = math.sqrt(2.0 * energy / BALL_MASS)
    ball.state.vel = (0.0, 0.0, -speed)
    ball_id = O.bodies.append(ball)
    brk = attach({"ore": material}, seed=seed, **options)
    info = {"anvil": anvil, "particles": particles, "holder": list(holder), "ball": ball_id,
            "speed": speed, "centers": centers, "material": mats["ore"]}
    return brk, info


def hold_release(info):
    """Erase the holder once the ball touches a particle; True once released (or none)."""
    if not info["holder"]:
        return True
    if any(O.interactions.withBody(info["ball"])):
        for i in info["holder"]:
            O.bodies.erase(i)
        info["holder"] = []
        return True
    return False


def drop_weight_scene(material="copper_ore", size=5.5e-3, specific_energy=200.0, particles=50,
                      striker_mass_ratio=50.0, seed=0, **options):
    """Drop-weight tests: a steel striker (a sphere of striker_mass_ratio x the particle's mass)
    falls on each particle resting on a steel anvil, with Ek / mp = specific_energy. The energy
    of both contacts (striker-particle, particle-anvil) is counted (Eq. 14).
    Returns (controller, particle ids, striker ids)."""
    O.reset()
    ip2, mats = add_materials({"particle": material, "steel": "steel"},
                              stiffness_scale=options.pop("stiffness_scale", 1.0))
    O.bodies.append(utils.wall(0.0, axis=2, sense=1, material="steel"))
    radius = size / 2.0
    mat = mats["particle"]
    particle_mass = mat.density * 4.0 / 3.0 * math.pi * radius ** 3
    striker_mass = striker_mass_ratio * particle_mass
    striker_radius = (striker_mass / (7800.0 * 4.0 / 3.0 * math.pi)) ** (1.0 / 3.0)
    speed = math.sqrt(2.0 * specific_energy * particle_mass / striker_mass)
    pitch = 2.5 * striker_radius + size
    side = int(math.ceil(math.sqrt(particles)))
    ids, strikers = [], []
    for k in range(particles):
        x, y = (k % side) * pitch, (k // side) * pitch
        ids.append(O.bodies.append(utils.sphere((x, y, radius), radius, material="particle")))
        s = utils.sphere((x, y, size + striker_radius * 1.001 + 0.02 * radius), striker_radius,
                         material="steel")
        s.state.vel = (0.0, 0.0, -speed)
        strikers.append(O.bodies.append(s))
    O.engines = hertz_engines(ip2)
    brk = attach({"particle": material}, seed=seed, **options)
    return brk, ids, strikers
