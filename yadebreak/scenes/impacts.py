"""Impact scenes: particles shot at a target (single and repeated impacts) and the drop weight;
the Hertz-Mindlin engine list every scene shares. YADE layer."""
from __future__ import annotations

import json
import math
import time
from pathlib import Path

import numpy as np

# the coupling makes yade importable from Debian's python3 first
from yadebreak.model import placement
from yadebreak.engine import add_materials, attach, run_steps
from yadebreak.engine.materials import as_material
from yadebreak.engine.parts.rolling import install_rolling
from yadebreak.engine.shapes.polyhedron import body_kinetic_energy
from yadebreak.scenes.polyhedra import volumetric_impact_scene
from yadebreak.adapter.yade_api import O, engine_time, utils, wrapper as _w
from yadebreak.process.files import append_whole
from yadebreak.process.signals import stop_point, stop_points


def hertz_engines(ip2, gravity=(0.0, 0.0, 0.0), facets=False, rolling=None):
    """The standard engine list: collider, Hertz-Mindlin, undamped Newton; with `rolling`
    ({(material id, id): mu_r}, scene_materials.rolling_friction), the law's contact moment and
    the part that gives each contact its pair's rolling friction (engine/parts/rolling.py)."""
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
        install_rolling(rolling, engines)
    return engines


def impact_scene(material="copper_ore", size=5.5e-3, speeds=(5.0,), target="steel", seed=0,
                 gap_fraction=0.02, stiffness_scale=1.0, **options):
    """Particles of one size fired normally at a plate (z = 0), one per speed, far apart.

    Returns (controller, particle ids). The target is non-breakable even if it is the particle's
    own material (a separate YADE material with the same properties). Every Young's modulus of
    the scene times `stiffness_scale`; `options` are attach()'s.
    """
    O.reset()
    labels = {"particle": material, "target": target}
    ip2, _ = add_materials(labels, stiffness_scale=stiffness_scale)
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
                   event_log=None, on_scene=None, max_steps=200000, scheduler=None,
                   wait_for_arrivals=False, queue=None, shape="sphere", watch=None,
                   **options):
    """`particles` particles fired at `speed` (m/s) normally at a plate, `per_scene` at a time in
    independent scenes, each run to its own end (run_until_rebound with its controller).

    Why scenes of a few: in one scene every particle waits for the slowest cascade, at the time
    step of the finest fragment of any (200 ab_t10_ore particles of 12 mm at 160 J/kg: 470 s in
    one scene; docs/high_energy.md). The particles are independent either way: nothing touches
    across the 4-diameter spacing during an impact. Scene k is seeded scene_seed(seed, k), so
    the result does not depend on where they run: on a `scheduler` (process.scheduler; None or
    local:1: this process), or a queue.SceneQueue `queue` that a job keeps for all its runs, the
    scenes are Dask tasks, each worker taking the next scene when it is free, and their tallies
    are merged in scene order.

    Events go to `event_log` (each with its `scene`), the running scene's to `<log>.scene.jsonl`
    until it ends (on workers: each scene's to `<log>.workers/<scene>.jsonl` as it arrives,
    joined at the end; a failed run leaves them there). on_scene(scenes done, scenes, tally)
    after each scene (progress lines). A scene stops after max_steps at the latest (counted in
    tally.scenes_at_step_limit). `material`, `target`: Materials, or names or paths (workers get
    them as text, the file a Material was read from). Returns
    (reports.ImpactTally, with the steps of every scene; the last scene's controller, None with
    workers). wait_for_arrivals: see run_until_rebound. shape: "sphere" (impact_scene) or
    "polyhedra" (random convex polyhedra of sieve size `size` on YADE's volumetric law:
    scenes.polyhedra.volumetric_impact_scene). watch(scene, controller): a callable to call
    between checks of that scene's run and close() at its end, or None (in this process only:
    with workers it is not called)."""
    spec = impact_spec(_named(material), size, speed, particles, per_scene, seed, _named(target),
                       max_steps, wait_for_arrivals, shape, **options)
    if queue is not None:
        return queue.collect(queue.submit(spec, event_log), on_scene), None
    if on_workers(scheduler, spec["counts"]):
        from yadebreak.scenes.queue import SceneQueue
        with SceneQueue(scheduler) as own:
            return own.collect(own.submit(spec, event_log), on_scene), None
    if event_log is not None:
        Path(event_log).write_text("")
    return run_scenes(spec, range(len(spec["counts"])), event_log, on_scene, watch,
                      (as_material(material), as_material(target)))


def _named(material):
    """A material as a worker process finds it: a name or path as given, a Material's file."""
    return material if isinstance(material, str) else material.source


def impact_scenes():
    """The particle shapes of single impacts, each with its scene builder (a new shape's
    builder is one more entry)."""
    return {"sphere": impact_scene, "polyhedra": volumetric_impact_scene}


#: the particle shapes of single impacts (impact_scenes)
SHAPES = tuple(impact_scenes())


def impact_spec(material, size, speed, particles, per_scene, seed, target="steel",
                max_steps=200000, wait_for_arrivals=False, shape="sphere", **options):
    """single_impacts' arguments as plain JSON (what a worker process runs scenes from)."""
    if shape not in SHAPES:
        raise ValueError(f"shape = {shape!r}: accepted {SHAPES}")
    return {"material": str(material), "size": size, "speed": speed, "seed": seed,
            "target": target, "max_steps": max_steps, "options": options,
            "counts": scene_counts(particles, per_scene), "wait_for_arrivals": wait_for_arrivals,
            "shape": shape}


def drop_weight_spec(material, size, specific_energy, particles, per_scene, seed, max_time,
                     **options):
    """Drop-weight tests as plain JSON, run like single impacts (run_scenes, a SceneQueue):
    `per_scene` strikers side by side in each scene (drop_weight_scene), each scene run until
    its strikers are done or `max_time` (s) of simulated time (run_drop_weight)."""
    return {"test": "drop_weight", "material": str(material), "size": size,
            "specific_energy": specific_energy, "seed": seed, "max_time": max_time,
            "options": options, "counts": scene_counts(particles, per_scene)}


def scene_counts(particles, per_scene):
    """The particles of each scene: per_scene each, the rest in the last."""
    return [per_scene] * (particles // per_scene) + ([particles % per_scene]
                                                     if particles % per_scene else [])


def on_workers(scheduler, counts):
    """Whether scenes of `counts` (scene_counts) go to the workers of `scheduler` (a
    process.scheduler.Scheduler, None: this process): not on local:1, nor one scene on this
    machine (a worker would only add its start)."""
    return (scheduler is not None and not scheduler.in_process
            and not (len(counts) == 1 and scheduler.kind == "local"))


def run_scenes(spec, which, event_log=None, on_scene=None, watch=None, materials=None):
    """The scenes `which` of an impact_spec or drop_weight_spec, one after the other, their
    events appended to `event_log`: (tally, the last scene's controller). watch: see
    single_impacts. materials: the (particles', target's) Materials when the caller has them;
    None: those the spec names, loaded once here."""
    from yadebreak.analysis.reports import ImpactTally
    tally = ImpactTally(spec["size"])
    log = None if event_log is None else Path(event_log)
    live = None if log is None else log.with_suffix(".scene.jsonl")
    brk, counts = None, spec["counts"]
    drop_weight = spec.get("test") == "drop_weight"
    material, target = materials or (as_material(spec["material"]),
                                     as_material(spec.get("target", "steel")))
    for done, k in enumerate(which, start=1):
        began = time.perf_counter()
        seed, log_here = scene_seed(spec["seed"], k), None if live is None else str(live)
        if drop_weight:
            brk, ids, strikers = drop_weight_scene(
                material, spec["size"], spec["specific_energy"], counts[k], seed=seed,
                event_log=log_here, **spec["options"])
            initial_mass = brk.total_mass()
            with engine_time() as yade:
                ran, limited = run_drop_weight(brk, ids, strikers, spec["max_time"])
            brk.finish()
        else:
            build = impact_scenes()[spec.get("shape", "sphere")]
            brk, ids = build(material, spec["size"], [spec["speed"]] * counts[k],
                             target=target, seed=seed, event_log=log_here,
                             **spec["options"])
            initial_mass = brk.total_mass()
            watcher = watch(k, brk) if watch is not None else None
            with engine_time() as yade:
                ran = run_until_rebound(ids, max_steps=spec["max_steps"], brk=brk,
                                        wait_for_arrivals=spec.get("wait_for_arrivals", False),
                                        on_check=watcher)
            if watcher is not None:
                watcher.close()
            limited = ran >= spec["max_steps"]
        tally.steps += ran
        tally.scenes_at_step_limit += int(limited)
        tally.add(brk, ids, initial_mass)
        wall = time.perf_counter() - began
        tally.scene_wall_s += wall
        tally.scene_walls.append(wall)
        tally.yade_engines_s += yade.seconds
        if log is not None:
            append_whole(log, "".join(json.dumps({"scene": k, **e}) + "\n" for e in brk.events))
            brk.close()                       # the scene's log file, merged
            live.unlink(missing_ok=True)
        if on_scene is not None:
            on_scene(done, len(which), tally)
    return tally, brk


def run_until_rebound(ids, max_steps=200000, check_every=50, brk=None, wait_for_arrivals=False,
                      on_check=None):
    """Run until the listed bodies have left the plate (moving away, touching nothing), or
    max_steps. With the controller `brk`, also until their fragments are done: fragments go on
    breaking while they are loaded, so the run does not stop when the original particles have
    broken (without `brk` it does: primary breakage only, as tests of Eq. 8 want; with it, the
    single-impact script measures successive breakage at high energies).

    The fragments are done (at once if nothing was fired: no impact) when none heads for the plate
    faster than 10 % of the fastest listed body's initial speed (1 % of the impact's specific
    energy), or when none has broken for five Hertz loading times of the listed bodies at that
    speed (the cascade is over; what is still flying back is slow: measured, 200,000 steps of a
    fragment cloud's tail at 1000 J/kg added no breakage).

    wait_for_arrivals: the quiet rule waits also while a body that the plate could break heads
    for it faster than that 10 % (_arrival_pending). Without it a fragment thrown from the top of
    a broken parent, still in flight towards the plate, is cut off: measured, 29 mm copper ore
    at 1000 J/kg (seed 3), the run stopped at 121 us with a fragment heading down at 33 m/s;
    20,000 more steps gave 4 breakages instead of 1. on_check(): called after every check_every
    steps (a ParaView series)."""
    fired = [O.bodies[i] for i in ids if i < len(O.bodies) and O.bodies[i] is not None]
    speed = max((b.state.vel.norm() for b in fired), default=0.0)
    follow = brk is not None and speed > 0.0
    quiet = 5.0 * _loading_time(fired[0], speed, brk) if follow else None
    done_steps = 0
    with stop_points():                  # a script's SIGINT, SIGTERM: stop between the checks
        while done_steps < max_steps:
            run_steps(check_every)
            done_steps += check_every
            if on_check is not None:
                on_check()
            stop_point()
            if all(_left(i) for i in ids) and (
                    not follow or _all_away(0.1 * speed)
                    or (O.time - _last_breakage(brk) > quiet
                        and not (wait_for_arrivals and _arrival_pending(0.1 * speed, brk)))):
                break
    return done_steps


def _loading_time(b, speed, brk):
    """The Hertz loading time (s) of body b at `speed`; a polyhedron's as the sphere of its
    tracked size and its material file's (a volumetric contact is shorter: a longer wait)."""
    if isinstance(b.shape, _w.Sphere):
        return float(placement.hertz_loading_time(b.shape.radius, b.material.density,
                                                  b.material.young, b.material.poisson, speed))
    mat = brk.material[brk.bodies.label_of(b.id)]
    return float(placement.hertz_loading_time(brk.bodies[b.id].radius, mat.density,
                                              mat.young_modulus, mat.poisson_ratio, speed))


def _last_breakage(brk):
    """Time (s) of the controller's last breakage event (0 if none)."""
    return next((e["time"] for e in reversed(brk.events) if e["kind"] == "breakage"), 0.0)


def _arrival_pending(slow, brk):
    """A body heads for the plate (z = 0) faster than `slow` (m/s), and it or a body it touches
    could break there: brk.could_break of the most its stressing event could still count, the
    kinetic energy it brings (translation and spin) plus that of the bodies touching it, per kg
    of it (no contact gives a body more than the kinetic energy of what presses on it).
    Dummies, unbreakable fragments already stressed and fragments too tough for that energy are
    not waited for: measured, in a 29 mm copper ore cascade at 3000 J/kg (cs 1, 1 % RT) the last
    breakage came at 84 us and the run went on to 1,780 us for a dummy in flight. What presses
    on a body counts, and what its event has counted: a fragment on the plate with 26 J/kg of
    its own and a dummy behind it broke at 109 J/kg (29 mm copper ore at 300 J/kg, seed 3)."""
    heading = [b for b in O.bodies if b is not None and b.dynamic and b.state.vel[2] < -slow]
    touching = {b.id: _touching(b.id) for b in heading}
    near = {b.id: b for b in heading}
    for others in list(touching.values()):
        near.update((o.id, o) for o in others)
    for i in near:
        if i not in touching:
            touching[i] = _touching(i)
    energy = [(_kinetic(b) + sum(map(_kinetic, touching[i]))) / b.state.mass
              for i, b in near.items()]
    return bool(near) and bool(brk.could_break(list(near), energy).any())


def _touching(i):
    """The dynamic bodies in real contact with body i."""
    others = (O.bodies[x.id2 if x.id1 == i else x.id1] for x in O.interactions.withBody(i)
              if x.isReal)
    return [b for b in others if b is not None and b.dynamic]


def _kinetic(b):
    """Kinetic energy (J) of a body: translation and spin (a sphere's I = 2/5 m r^2)."""
    if not isinstance(b.shape, _w.Sphere):
        return body_kinetic_energy(b)
    return b.state.mass * (0.5 * b.state.vel.squaredNorm()
                           + 0.2 * (b.shape.radius * b.state.angVel.norm()) ** 2)


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


def run_drop_weight(brk, ids, strikers, max_time):
    """Run drop-weight tests (drop_weight_scene) until every striker moves up again or has
    nothing left to meet: free of contacts, with no body in its path that it would catch (below
    it, within its radius plus the body's sideways, moving down slower than it), or at `max_time`
    (s) of simulated time. Without the second rule a striker whose particle's fragments were
    pushed aside coasts down to the anvil: measured, 29 mm copper ore broken at 1000 J/kg, the
    striker went on at 0.4 m/s for 48 ms of simulated time (2 million steps at the fragments'
    time step), meeting nothing after 1.8 ms. Returns (steps run, whether max_time stopped it)."""
    steps = 0
    with stop_points():
        while O.time < max_time:
            run_steps(200)
            steps += 200
            stop_point()
            if not any(_still_striking(s) for s in strikers):
                return steps, False
    return steps, True


def _still_striking(i):
    """The striker `i` moves down and touches a body or has one in its path."""
    striker = O.bodies[i].state
    if striker.vel[2] >= 0.0:
        return False
    if any(x.isReal for x in O.interactions.withBody(i)):
        return True
    r = O.bodies[i].shape.radius
    for b in O.bodies:
        if b is None or b.id == i or not b.dynamic:
            continue
        d = b.state.pos - striker.pos
        if (d[2] < 0.0 and d[0] ** 2 + d[1] ** 2 < (r + b.shape.radius) ** 2
                and b.state.vel[2] > striker.vel[2]):
            return True
    return False


def drop_weight_scene(material="copper_ore", size=5.5e-3, specific_energy=200.0, particles=50,
                      striker_mass_ratio=50.0, seed=0, stiffness_scale=1.0, **options):
    """Drop-weight tests: a steel striker (a sphere of striker_mass_ratio x the particle's mass)
    falls on each particle resting on a steel anvil, with Ek / mp = specific_energy. The energy
    of both contacts (striker-particle, particle-anvil) is counted (Eq. 14).
    Returns (controller, particle ids, striker ids)."""
    O.reset()
    ip2, mats = add_materials({"particle": material, "steel": "steel"},
                              stiffness_scale=stiffness_scale)
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
