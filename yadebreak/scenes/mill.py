"""The laboratory batch ball mill's scene (scripts/ball_mill.py; its job: jobs/mill.py): a drum
of steel facets with lifter bars, turned about the x axis by YADE's RotationEngine; steel balls
and a breakable ore charge; gravity along -z. And what the job reads of it: the drum's torque, the
charge's centre of mass, the mill's time."""
from __future__ import annotations

import math

import numpy as np

from yadebreak import engine
from yadebreak.model import milling
from yadebreak.model.intervals import InputError
from yadebreak.adapter.yade_api import O, utils, wrapper as _w
from yadebreak.engine.stepping import smallest_rayleigh_time
from yadebreak.scenes.impacts import hertz_engines

SETTLE_TIME = 0.25               # s of settling under gravity, drum still, before the engine


# -- geometry ---------------------------------------------------------------------------------------
def drum_profile(radius, lifters, lifter_height, lifter_width, segments=48):
    """The drum's cross-section (y, z points, m): a circle of `segments` chords with `lifters`
    rectangular bars (height and width in m) standing inward, evenly spaced, closed."""
    half = 0.5 * lifter_width / radius              # half the angle a lifter's foot spans
    points = []
    for k in range(segments):
        theta0, theta1 = 2 * math.pi * k / segments, 2 * math.pi * (k + 1) / segments
        points.append((radius * math.cos(theta0), radius * math.sin(theta0)))
        for j in range(lifters):
            at = 2 * math.pi * (j + 0.5) / lifters
            if theta0 <= at < theta1:
                inner = radius - lifter_height
                for angle, r in ((at - half, radius), (at - half, inner), (at + half, inner),
                                 (at + half, radius)):
                    points.append((r * math.cos(angle), r * math.sin(angle)))
    return points + [points[0]]


def drum_facets(profile, length, material):
    """Facets of the drum's shell: two per chord of the profile, between x = -length/2 and
    length/2. The end walls are planes (end_walls): a fan of thin facets from the axis gave NaN
    contacts with YADE 2023.02's facet geometry (measured: a ball at the end wall's centre)."""
    x0, x1 = -0.5 * length, 0.5 * length
    facets = []
    for (ya, za), (yb, zb) in zip(profile[:-1], profile[1:]):
        a0, b0, a1, b1 = (x0, ya, za), (x0, yb, zb), (x1, ya, za), (x1, yb, zb)
        facets += [utils.facet((a0, b0, b1), material=material),
                   utils.facet((a0, b1, a1), material=material)]
    return facets


def end_walls(length, material):
    """The drum's two end walls, planes x = -length/2 and x = length/2, still (their friction on
    the charge is the only difference from walls that turn with the shell)."""
    return [utils.wall(-0.5 * length, axis=0, sense=1, material=material),
            utils.wall(0.5 * length, axis=0, sense=-1, material=material)]


def charge_positions(radius, length, clearance, ball_size, balls, ore_size, ores, rng):
    """Centres (m) of `balls` balls and `ores` ore particles, as low in the drum as they go: the
    lowest points of a jittered lattice inside the drum (at least `clearance` from the shell), the
    balls first, then the ore among them without overlap. Raises ScriptError if they do not fit."""
    def lattice(size):
        step = 1.02 * size
        reach = radius - clearance - 0.5 * size
        xs = np.arange(-0.5 * length + 0.51 * size, 0.5 * length - 0.51 * size + 1e-12, step)
        ys = np.arange(-reach, reach + 1e-12, step)
        grid = np.array(np.meshgrid(xs, ys, ys, indexing="ij")).reshape(3, -1).T
        inside = np.hypot(grid[:, 1], grid[:, 2]) <= reach
        grid = grid[inside]
        return grid[np.lexsort((rng.random(len(grid)), grid[:, 2]))]     # lowest first
    ball_at = lattice(ball_size)[:balls]
    ore_at = lattice(ore_size)
    if len(ore_at) and len(ball_at):
        gap = np.min(np.linalg.norm(ore_at[:, None, :] - ball_at[None, :, :], axis=2), axis=1)
        ore_at = ore_at[gap > 0.51 * (ball_size + ore_size)]
    ore_at = ore_at[:ores]
    if len(ball_at) < balls or len(ore_at) < ores:
        raise InputError(f"the charge does not fit: {len(ball_at)} of {balls} balls and "
                          f"{len(ore_at)} of {ores} ore particles placed; lower --ball-filling or "
                          "--ore-filling, or use a larger drum")
    return ball_at, ore_at


# -- the scene ----------------------------------------------------------------------------------------
def mill_scene(args, options, ore_material):
    """Build the mill of the job's `args`, its ore of `ore_material` (a Material), settle the
    charge with the drum still, attach yadebreak and start the drum. Returns (controller,
    info)."""
    O.reset()
    ip2, mats = engine.add_materials({"ore": ore_material, "steel": "steel"},
                                       stiffness_scale=args.stiffness_scale)
    radius = 0.5 * args.drum_diameter
    profile = drum_profile(radius, args.lifters, args.lifter_height, args.lifter_width)
    drum = O.bodies.append(drum_facets(profile, args.drum_length, "steel"))
    ends = O.bodies.append(end_walls(args.drum_length, "steel"))
    n_balls, n_ore = milling.charge_counts(args)
    rng = np.random.default_rng(args.seed)
    ball_at, ore_at = charge_positions(radius, args.drum_length, args.lifter_height,
                                       args.ball_size, n_balls, args.size, n_ore, rng)
    balls = [O.bodies.append(utils.sphere(tuple(c), 0.5 * args.ball_size, material="steel"))
             for c in ball_at]
    ore = [O.bodies.append(utils.sphere(tuple(c), 0.5 * args.size, material="ore"))
           for c in ore_at]
    speed = args.speed * milling.critical_speed(args.drum_diameter, args.ball_size)  # rev/s
    omega = 2 * math.pi * speed
    O.engines = hertz_engines(ip2, gravity=(0.0, 0.0, -9.81), facets=True) + [
        _w.RotationEngine(rotationAxis=(1, 0, 0), rotateAroundZero=True, zeroPoint=(0, 0, 0),
                          angularVelocity=0.0, ids=list(drum), label="drum")]
    # settle with the drum still, damped, before anything is tracked (the fill is not milling)
    O.dt = args.time_step_fraction * smallest_rayleigh_time()
    newton = O.engines[-2]
    newton.damping = 0.5
    O.run(int(SETTLE_TIME / O.dt), True)
    newton.damping = 0.0
    for i in balls + ore:
        O.bodies[i].state.vel = (0, 0, 0)
        O.bodies[i].state.angVel = (0, 0, 0)
    brk = engine.attach({"ore": ore_material}, seed=args.seed, **options)
    next(e for e in O.engines if isinstance(e, _w.RotationEngine)).angularVelocity = omega
    info = {"drum": list(drum), "ends": list(ends), "balls": balls, "ore": ore, "omega": omega, "speed_rps": speed,
            "start_time": O.time,                 # the settling's end: the mill's t = 0
            "profile": profile, "ball_mass": sum(O.bodies[i].state.mass for i in balls)}
    return brk, info


def drum_torque(drum):
    """Torque (N m) of the charge on the drum about its axis (x): sum over the drum's facets of
    (position x force + torque), from the last step's forces."""
    total = 0.0
    for i in drum:
        f, t, p = O.forces.f(i), O.forces.t(i), O.bodies[i].state.pos
        total += p[1] * f[2] - p[2] * f[1] + t[0]
    return total


def mill_time(info):
    """Simulated time (s) since the drum started (the settling before it is not milling)."""
    return O.time - info["start_time"]


def charge_state(info):
    """(mass (kg), horizontal lever arm y of its centre of mass (m)) of every sphere in the drum:
    balls, ore and fragments (a pass over the bodies, once per sample)."""
    mass = moment = 0.0
    for b in O.bodies:
        if b is not None and b.dynamic:
            mass += b.state.mass
            moment += b.state.mass * b.state.pos[1]
    return mass, (moment / mass if mass else 0.0)
