"""Scene builders shared by the scripts and tests (coupling layer: imports yade)."""
from __future__ import annotations

import dataclasses
import json
import math
from pathlib import Path

import numpy as np

# the coupling makes yade importable from Debian's python3 first
from . import placement
from .coupling import add_materials, attach, run_steps
from .coupling.rolling import rolling_engine
from .coupling.scene_materials import rolling_friction
from .coupling._yade import O, utils, wrapper as _w
from .scriptargs import stop_point, stop_points


def hertz_engines(ip2, gravity=(0.0, 0.0, 0.0), facets=False, rolling=None):
    """The standard engine list: collider, Hertz-Mindlin, undamped Newton; with `rolling`
    ({(material id, id): mu_r}, scene_materials.rolling_friction), the law's contact moment and
    the part that gives each contact its pair's rolling friction (coupling/rolling.py)."""
    bounds = [_w.Bo1_Sphere_Aabb(), _w.Bo1_Wall_Aabb()]
    geoms = [_w.Ig2_Sphere_Sphere_ScGeom(), _w.Ig2_Wall_Sphere_ScGeom()]
    if facets:
        bounds.append(_w.Bo1_Facet_Aabb())
        geoms.append(_w.Ig2_Facet_Sphere_ScGeom())
    law = _w.Law2_ScGeom_MindlinPhys_Mindlin(includeMoment=rolling is not None, label="law")
    engines = [
        _w.ForceResetter(),
        _w.InsertionSortCollider(bounds),
        _w.InteractionLoop(geoms, [ip2], [law]),
        _w.NewtonIntegrator(damping=0.0, gravity=gravity, label="newton"),
    ]
    if rolling is not None:
        engines.append(rolling_engine(rolling))
    return engines


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


def scene_seed(seed, scene):
    """The seed of scene `scene` of a run seeded `seed`: `seed` itself for scene 0 (a run in one
    scene is the run it always was), independent streams for the others."""
    if scene == 0:
        return int(seed)
    return int(np.random.SeedSequence([int(seed), int(scene)]).generate_state(1)[0])


def single_impacts(material, size, speed, particles, per_scene, seed, target="steel",
                   event_log=None, on_scene=None, max_steps=200000, jobs=1, **options):
    """`particles` particles fired at `speed` (m/s) normally at a plate, `per_scene` at a time in
    independent scenes, each run to its own end (run_until_rebound with its controller).

    Why scenes of a few: in one scene every particle waits for the slowest cascade, at the time
    step of the finest fragment of any (200 ab_t10_ore particles of 12 mm at 160 J/kg: 470 s in
    one scene; docs/high_energy.md). The particles are independent either way: nothing touches
    across the 4-diameter spacing during an impact. Scene k is seeded scene_seed(seed, k), so
    the result does not depend on `jobs`: with jobs > 1 the scenes are shared among that many
    YADE processes (yadebreak/impact_worker.py), each running every jobs-th scene.

    Events go to `event_log` (each with its `scene`), the running scene's to `<log>.scene.jsonl`
    until it ends (with workers: each worker's to `<log>.workers/<worker>.jsonl`, joined at the
    end; a failed run leaves them there). on_scene(scenes done, scenes, tally) after each scene
    (progress lines). A scene stops after max_steps at the latest (counted in
    tally.scenes_at_step_limit). `material`: a name or path (workers get it as text). Returns
    (reports.ImpactTally, with the steps of every scene; the last scene's controller, None with
    workers)."""
    counts = [per_scene] * (particles // per_scene) + ([particles % per_scene]
                                                        if particles % per_scene else [])
    spec = {"material": str(material), "size": size, "speed": speed, "seed": seed,
            "target": target, "max_steps": max_steps, "options": options, "counts": counts}
    if jobs > 1 and len(counts) > 1:
        return _in_workers(spec, min(jobs, len(counts)), event_log, on_scene)
    if event_log is not None:
        Path(event_log).write_text("")
    return run_scenes(spec, range(len(counts)), event_log, on_scene)


def run_scenes(spec, which, event_log=None, on_scene=None):
    """The scenes `which` of a single_impacts `spec`, one after the other, their events appended
    to `event_log`: (tally, the last scene's controller)."""
    from .reports import ImpactTally
    tally = ImpactTally(spec["size"])
    log = None if event_log is None else Path(event_log)
    live = None if log is None else log.with_suffix(".scene.jsonl")
    brk, counts = None, spec["counts"]
    for done, k in enumerate(which, start=1):
        brk, ids = impact_scene(spec["material"], spec["size"], [spec["speed"]] * counts[k],
                                target=spec["target"], seed=scene_seed(spec["seed"], k),
                                event_log=None if live is None else str(live), **spec["options"])
        initial_mass = brk.total_mass()
        ran = run_until_rebound(ids, max_steps=spec["max_steps"], brk=brk)
        tally.steps += ran
        tally.scenes_at_step_limit += ran >= spec["max_steps"]
        tally.add(brk, ids, initial_mass)
        if log is not None:
            with open(log, "a") as f:
                f.writelines(json.dumps({"scene": k, **e}) + "\n" for e in brk.events)
            brk.close()                       # the scene's log file, merged
            live.unlink(missing_ok=True)
        if on_scene is not None:
            on_scene(done, len(which), tally)
    return tally, brk


def _in_workers(spec, jobs, event_log, on_scene):
    """single_impacts in `jobs` YADE processes; their tallies merged, their logs joined in scene
    order. A worker that fails stops the others and raises with its last words."""
    import shutil
    import subprocess
    import tempfile
    import time
    if event_log is None:
        folder = Path(tempfile.mkdtemp(prefix="yadebreak-impacts-"))
    else:                                 # beside the log: a failed run leaves its events there
        folder = Path(event_log).with_suffix(".workers")
        shutil.rmtree(folder, ignore_errors=True)
        folder.mkdir(parents=True)
    spec = {**spec, "package": str(Path(__file__).resolve().parent.parent)}
    (folder / "spec.json").write_text(json.dumps(spec))
    worker = str(Path(__file__).resolve().parent / "impact_worker.py")
    errors = [open(folder / f"{j}.err", "w") for j in range(jobs)]
    from .sweep import _die_with_parent       # a parent killed (even -9) takes them along
    procs = [subprocess.Popen(["yade", "-n", "-x", worker, str(folder), str(j), str(jobs)],
                              stdout=subprocess.DEVNULL, stderr=errors[j],
                              preexec_fn=_die_with_parent) for j in range(jobs)]
    try:
        reported = 0
        while True:
            running = any(p.poll() is None for p in procs)
            _check_workers(procs, folder)
            tally = _merged(folder, jobs, spec["size"])
            if on_scene is not None and tally.scenes > reported:
                reported = tally.scenes
                on_scene(reported, len(spec["counts"]), tally)
            if not running:
                break
            time.sleep(0.5)
        if tally.scenes != len(spec["counts"]):
            raise RuntimeError(f"impact workers ran {tally.scenes} of {len(spec['counts'])} "
                               f"scenes; their messages are in {folder}")
        if event_log is not None:
            events = [line for j in range(jobs) if (folder / f"{j}.jsonl").exists()
                      for line in (folder / f"{j}.jsonl").read_text().splitlines()]
            events.sort(key=lambda line: json.loads(line)["scene"])       # stable: in-scene order
            Path(event_log).write_text("".join(line + "\n" for line in events))
        shutil.rmtree(folder)
        return tally, None
    finally:
        for p in procs:
            if p.poll() is None:
                p.kill()
                p.wait()
        for f in errors:
            f.close()


def _check_workers(procs, folder):
    """Raise if a worker has failed, with its last words."""
    failed = [j for j, p in enumerate(procs) if p.poll() not in (None, 0)]
    if failed:
        raise RuntimeError(f"impact worker {failed[0]} failed (its events so far in {folder}): "
                           + (folder / f"{failed[0]}.err").read_text()[-1500:])


def _merged(folder, jobs, size):
    from .reports import ImpactTally
    tally = ImpactTally(size)
    for j in range(jobs):
        path = folder / f"{j}.tally.json"
        if path.exists():
            tally.merge(ImpactTally.from_dict(json.loads(path.read_text())))
    return tally


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
    with stop_points():                  # a script's SIGINT, SIGTERM: stop between the checks
        while done_steps < max_steps:
            run_steps(check_every)
            done_steps += check_every
            stop_point()
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


#: the seed stream of the pour, apart from attach()'s (fracture energies, progeny)
POUR_STREAM = 7


def bed_impact_scene(material="copper_ore", size=5.5e-3, rings=3, layers=1, energy=3.05,
                     seed=1, settle_steps=3000, packing=None, rolling=True,
                     steel_rolling_friction=None, bed_cache="", say=lambda m: None, **options):
    """The paper's unconfined bed impact: a 88 mm steel ball on a bed resting on a steel anvil.

    The bed: a central particle and `rings` hexagonal rings per layer, `layers` layers. Beds of
    several layers stand in a cylindrical steel holder, removed when the ball first touches a
    particle (hold_release() does that). packing "poured" (the default for several layers): as
    many particles as the lattice holds poured into the holder and settled under gravity
    (poured_bed.py; the settled bed comes from the cache `bed_cache` when it was settled before,
    None: no cache); "lattice": the layers stacked in each other's hollows, settled 3000 damped
    steps. Rolling friction (per contact pair, from the material files; the particle-steel value
    replaced by `steel_rolling_friction` if given) unless rolling=False. The ball starts just
    above the bed with the speed of its drop, v = sqrt(2 E / m). Returns (controller, info).
    """
    from . import poured_bed
    from .coupling.engine import YADE_DEFAULT_DT
    packing = packing or ("poured" if layers > 1 else "lattice")
    if packing not in ("poured", "lattice") or (packing == "poured" and layers < 2):
        raise ValueError(f"packing {packing!r}: 'lattice', or 'poured' for beds of 2 layers or "
                         "more")
    labels = {"ore": material, "steel": "steel"}
    stiffness_scale = options.pop("stiffness_scale", 1.0)
    overrides = ({} if steel_rolling_friction is None
                 else {("ore", "steel"): float(steel_rolling_friction)})
    lattice = hex_bed_positions(size, rings, layers)
    holder_radius = float(np.max(np.linalg.norm(lattice[:, :2], axis=1)) + size / 2.0
                          + 0.02 * size)

    mats = {"ore": _material(material), "steel": _material("steel")}   # (cache key, info)

    def build():
        O.reset()
        ip2, _ = add_materials(labels, stiffness_scale=stiffness_scale)
        table = rolling_friction(labels, overrides)[0] if rolling else None
        anvil = O.bodies.append(utils.wall(0.0, axis=2, sense=1, material="steel"))
        holder = []
        if layers > 1:             # poured: the loose column's height, cut to the bed after
            holder = _holder(holder_radius, lattice[:, 2].max() + size if packing == "lattice"
                             else 2.5 * (lattice[:, 2].max() + size))
        O.engines = hertz_engines(ip2, gravity=(0.0, 0.0, -9.81), facets=bool(holder),
                                  rolling=table)
        if packing == "poured":
            rng = np.random.default_rng(np.random.SeedSequence([int(seed), POUR_STREAM]))
            particles, settled = poured_bed.pour(len(lattice), size / 2.0, holder_radius, rng,
                                                 "ore", say)
            for i in holder:       # as the lattice's, half a size above the top particle,
                O.bodies.erase(i)  # but clear of the ball that starts just above the bed
            ball = BALL_DIAMETER / 2.0
            clear = ball - math.sqrt(ball ** 2 - holder_radius ** 2)
            holder = _holder(holder_radius, settled.height + min(size / 2.0, 0.9 * clear))
        else:
            particles = [O.bodies.append(utils.sphere(tuple(c), size / 2.0, material="ore"))
                         for c in lattice]
            settled = None
            if layers > 1 and settle_steps:    # settle the stack before anything is tracked
                O.dt = 0.2 * utils.PWaveTimeStep()
                newton = O.engines[3]
                newton.damping = 0.4
                O.run(settle_steps, True)
                newton.damping = 0.0
                for i in particles:
                    O.bodies[i].state.vel = (0, 0, 0)
                    O.bodies[i].state.angVel = (0, 0, 0)
        return {"anvil": anvil, "particles": particles, "holder": list(holder)}, settled

    if packing == "poured":
        spec = {"size": size, "rings": rings, "layers": layers, "seed": int(seed),
                "stiffness_scale": stiffness_scale, "rolling": rolling, "overrides":
                sorted([list(k), v] for k, v in overrides.items()),
                "holder_radius": holder_radius}
        folder = None if bed_cache is None else poured_bed.cache_folder(bed_cache)
        bodies, settled = poured_bed.cached_scene(folder, poured_bed.cache_key(spec, mats), build)
    else:
        bodies, settled = build()
    O.dt = YADE_DEFAULT_DT                    # attach() sets the run's time step
    named = rolling_friction(labels, overrides)[1] if rolling else {}
    particles = bodies["particles"]
    centers = (lattice if packing == "lattice"
               else np.array([tuple(O.bodies[i].state.pos) for i in particles]))
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
    info = {"anvil": bodies["anvil"], "particles": particles, "holder": bodies["holder"],
            "ball": ball_id, "speed": speed, "centers": centers, "material": mats["ore"],
            "packing": packing, "rolling_friction": {
                "particle_particle": named.get("ore-ore", 0.0),
                "particle_steel": named.get("ore-steel", named.get("steel-ore", 0.0))},
            "bed_height": top, "settled": None if settled is None else dataclasses.asdict(settled)}
    return brk, info


def _holder(radius, height):
    """The cylindrical steel holder (24 facets, open at both ends) from z = 0 to `height` (m)."""
    from yade import geom    # utils.facetCylinder is broken in YADE 2023.02a
    return list(O.bodies.append(geom.facetCylinder((0, 0, height / 2.0), radius, height,
                                                   segmentsNumber=24, wallMask=4,
                                                   material="steel")))


def _material(name):
    from .coupling.scene_materials import _as_material
    return _as_material(name)


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
