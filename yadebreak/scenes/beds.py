"""Bed-impact scenes: a ball dropped on a bed of particles in a holder, laid as a hexagonal
lattice or poured and settled (poured_bed). YADE layer."""
from __future__ import annotations

import dataclasses
import math

import numpy as np

from yadebreak.engine import add_materials, attach
from yadebreak.engine.materials import as_material, rolling_friction
from yadebreak.adapter.yade_api import O, geom, utils
from yadebreak.model.intervals import BALL_DIAMETER, BALL_MASS  # noqa: F401 (the paper's ball)
from yadebreak.scenes.impacts import hertz_engines


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


#: the seed stream of the pour, apart from attach()'s (fracture energies, progeny)
POUR_STREAM = 7


@dataclasses.dataclass(frozen=True)
class _BedPlan:
    """What _build_bed makes (bed_impact_scene's arguments, resolved)."""
    labels: dict                # YADE label -> material
    overrides: dict             # rolling friction overrides per label pair
    lattice: np.ndarray         # (n, 3) the lattice's centres (m)
    holder_radius: float        # m
    packing: str                # "poured" or "lattice"
    layers: int
    size: float                 # particle diameter (m)
    seed: int
    settle_steps: int           # lattice beds of several layers: damped settling steps
    stiffness_scale: float
    rolling: bool
    say: object                 # say(message): progress of a pour


def _build_bed(plan):
    """The anvil, the holder and the bed (poured, or a lattice settled under damping); returns
    ({anvil, particles, holder: ids}, the pour's record or None)."""
    from yadebreak.scenes import poured_bed
    size, layers, lattice, holder_radius = plan.size, plan.layers, plan.lattice, plan.holder_radius
    O.reset()
    ip2, _ = add_materials(plan.labels, stiffness_scale=plan.stiffness_scale)
    table = rolling_friction(plan.labels, plan.overrides)[0] if plan.rolling else None
    anvil = O.bodies.append(utils.wall(0.0, axis=2, sense=1, material="steel"))
    holder = []
    if layers > 1:             # poured: the loose column's height, cut to the bed after
        holder = _holder(holder_radius, lattice[:, 2].max() + size if plan.packing == "lattice"
                         else 2.5 * (lattice[:, 2].max() + size))
    O.engines = hertz_engines(ip2, gravity=(0.0, 0.0, -9.81), facets=bool(holder),
                              rolling=table)
    if plan.packing == "poured":
        rng = np.random.default_rng(np.random.SeedSequence([int(plan.seed), POUR_STREAM]))
        particles, settled = poured_bed.pour(len(lattice), size / 2.0, holder_radius, rng,
                                             "ore", plan.say)
        for i in holder:       # as the lattice's, half a size above the top particle,
            O.bodies.erase(i)  # but clear of the ball that starts just above the bed
        ball = BALL_DIAMETER / 2.0
        clear = ball - math.sqrt(ball ** 2 - holder_radius ** 2)
        holder = _holder(holder_radius, settled.height + min(size / 2.0, 0.9 * clear))
    else:
        particles = [O.bodies.append(utils.sphere(tuple(c), size / 2.0, material="ore"))
                     for c in lattice]
        settled = None
        if layers > 1 and plan.settle_steps:    # settle the stack before anything is tracked
            O.dt = 0.2 * utils.PWaveTimeStep()
            newton = O.engines[3]
            newton.damping = 0.4
            O.run(plan.settle_steps, True)
            newton.damping = 0.0
            for i in particles:
                O.bodies[i].state.vel = (0, 0, 0)
                O.bodies[i].state.angVel = (0, 0, 0)
    return {"anvil": anvil, "particles": particles, "holder": list(holder)}, settled


def _drop_ball(top, gap, energy):
    """The 88 mm steel ball (BALL_MASS) `gap` (m) above the bed's `top` (m), falling with the
    speed of its drop for `energy` (J): returns (its id, speed (m/s))."""
    ball_radius = BALL_DIAMETER / 2.0
    ball = utils.sphere((0.0, 0.0, top + ball_radius + gap), ball_radius, material="steel")
    ball.state.mass = BALL_MASS
    inertia = 0.4 * BALL_MASS * ball_radius ** 2
    ball.state.inertia = (inertia, inertia, inertia)
    speed = math.sqrt(2.0 * energy / BALL_MASS)
    ball.state.vel = (0.0, 0.0, -speed)
    return O.bodies.append(ball), speed


def bed_impact_scene(material="copper_ore", size=5.5e-3, rings=3, layers=1, energy=3.05,
                     seed=1, settle_steps=3000, packing=None, rolling=True,
                     steel_rolling_friction=None, bed_cache="", stiffness_scale=1.0,
                     say=lambda m: None, **options):
    """The paper's unconfined bed impact: a 88 mm steel ball on a bed resting on a steel anvil.

    The bed: a central particle and `rings` hexagonal rings per layer, `layers` layers. Beds of
    several layers stand in a cylindrical steel holder, removed when the ball first touches a
    particle (hold_release() does that). packing "poured" (the default for several layers): as
    many particles as the lattice holds poured into the holder and settled under gravity
    (poured_bed.py; the settled bed comes from the cache `bed_cache` when it was settled before,
    None: no cache); "lattice": the layers stacked in each other's hollows, settled 3000 damped
    steps. Rolling friction (per contact pair, from the material files; the particle-steel value
    replaced by `steel_rolling_friction` if given) unless rolling=False. Moduli x stiffness_scale.
    The ball starts just above the bed with the speed of its drop, v = sqrt(2 E / m); `options`
    are attach()'s. Returns (controller, info)."""
    from yadebreak.scenes import poured_bed
    from yadebreak.engine.scene import YADE_DEFAULT_DT
    packing = packing or ("poured" if layers > 1 else "lattice")
    if packing not in ("poured", "lattice") or (packing == "poured" and layers < 2):
        raise ValueError(f"packing {packing!r}: 'lattice', or 'poured' for beds of 2 layers or "
                         "more")
    labels = {"ore": as_material(material), "steel": as_material("steel")}   # loaded once, here
    overrides = ({} if steel_rolling_friction is None
                 else {("ore", "steel"): float(steel_rolling_friction)})
    lattice = hex_bed_positions(size, rings, layers)
    holder_radius = float(np.max(np.linalg.norm(lattice[:, :2], axis=1)) + size / 2.0
                          + 0.02 * size)

    plan = _BedPlan(labels, overrides, lattice, holder_radius, packing, layers, size, seed,
                    settle_steps, stiffness_scale, rolling, say)
    if packing == "poured":
        spec = {"size": size, "rings": rings, "layers": layers, "seed": int(seed),
                "stiffness_scale": stiffness_scale, "rolling": rolling, "overrides":
                sorted([list(k), v] for k, v in overrides.items()),
                "holder_radius": holder_radius}
        folder = None if bed_cache is None else poured_bed.cache_folder(bed_cache)
        bodies, settled = poured_bed.cached_scene(folder, poured_bed.cache_key(spec, labels),
                                                  lambda: _build_bed(plan))
    else:
        bodies, settled = _build_bed(plan)
    O.dt = YADE_DEFAULT_DT                    # attach() sets the run's time step
    named = rolling_friction(labels, overrides)[1] if rolling else {}
    particles = bodies["particles"]
    centers = (lattice if packing == "lattice"
               else np.array([tuple(O.bodies[i].state.pos) for i in particles]))
    top = max(O.bodies[i].state.pos[2] for i in particles) + size / 2.0
    ball_id, speed = _drop_ball(top, 0.02 * size, energy)
    brk = attach({"ore": labels["ore"]}, seed=seed, **options)
    info = {"anvil": bodies["anvil"], "particles": particles, "holder": bodies["holder"],
            "ball": ball_id, "speed": speed, "centers": centers, "material": labels["ore"],
            "packing": packing, "rolling_friction": {
                "particle_particle": named.get("ore-ore", 0.0),
                "particle_steel": named.get("ore-steel", named.get("steel-ore", 0.0))},
            "bed_height": top, "settled": None if settled is None else dataclasses.asdict(settled)}
    return brk, info


def _holder(radius, height):
    """The cylindrical steel holder (24 facets, open at both ends) from z = 0 to `height` (m)."""
    # geom.facetCylinder: utils.facetCylinder is broken in YADE 2023.02a
    return list(O.bodies.append(geom.facetCylinder((0, 0, height / 2.0), radius, height,
                                                   segmentsNumber=24, wallMask=4,
                                                   material="steel")))


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
