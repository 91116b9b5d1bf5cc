"""Multi-layer beds poured into their holder and settled under gravity, as the experiment built
them (coupling layer: runs YADE), and the cache that keeps settled beds for the next run.

The particles start in loose levels inside the cylindrical holder (placement.pouring_column),
fall under gravity and come to rest on the anvil through their own contacts (Hertz-Mindlin with
the material files' restitution, friction and rolling friction) with YADE's Newton damping
SETTLE_DAMPING on the way, which only shortens the jiggling before rest (0.38 s of settling against
0.41 s without it for 3 layers x 3 rings of copper ore; measured). The bed is at rest when its
kinetic energy is below REST_FRACTION of N m g d (a mean speed of a few mm/s); the run then starts
from it with every velocity set to zero and the damping off. The settled scene (contact
history included) is saved in the cache under a key of everything that shapes it, so that a sweep
settles each bed once: the other lines with the same bed (another energy, for instance) load it.
"""
from __future__ import annotations

import contextlib
import dataclasses
import fcntl
import hashlib
import json
import math
import os
from pathlib import Path

from yadebreak.model import cache, placement
from yadebreak.engine.parts import protocol
from yadebreak.adapter.yade_api import O, utils, wrapper

#: at rest: kinetic energy (translation and rotation) below REST_FRACTION N m g d
REST_FRACTION = 1e-4
#: the settling's time step, a fraction of the particles' Rayleigh time
SETTLE_DT_FRACTION = 0.3
#: simulated time (s) after which a bed still moving is an error
MAX_SETTLE_TIME = 3.0
CHECK_EVERY = 2000
SETTLE_DAMPING = 0.4
#: part of the cache key: a change in how beds are poured makes new ones
VERSION = 2


@dataclasses.dataclass
class Settled:
    """What the pour gave: the simulated time it took (s), its steps, the kinetic energy left
    (J), the bed's height (m, the highest particle's top), and whether it came from the cache."""

    settle_time: float
    settle_steps: int
    kinetic_energy: float
    height: float
    cached: bool = False


def cache_folder(given=""):
    """The cache of settled beds: `given` (--bed-cache), else <cache>/beds (yadebreak.model.cache)."""
    return cache.cache_folder("beds", given)


def cache_key(spec, materials):
    """A name for the settled bed of `spec` (its settings, a dict of plain values) with these
    Materials (their files' contents count, not only their names)."""
    text = json.dumps({"version": VERSION, "spec": spec,
                       "materials": {k: _file_text(m) for k, m in sorted(materials.items())}},
                      sort_keys=True)
    return "bed-" + hashlib.sha1(text.encode()).hexdigest()[:20]


def _file_text(mat):
    source = getattr(mat, "source", None)
    return Path(source).read_text() if source and Path(source).is_file() else repr(mat)


def kinetic_energy(ids):
    """Kinetic energy (J) of bodies `ids`, translation and rotation (a pass over them)."""
    total = 0.0
    for i in ids:
        b = O.bodies[i]
        if b is None:
            continue
        s = b.state
        w = s.angVel
        total += 0.5 * s.mass * s.vel.squaredNorm() + 0.5 * (
            s.inertia[0] * w[0] ** 2 + s.inertia[1] * w[1] ** 2 + s.inertia[2] * w[2] ** 2)
    return total


def pour(particles, radius, holder_radius, rng, material_label, say=lambda m: None):
    """Pour `particles` spheres of `radius` (m) into the holder (already in the scene, with the
    anvil and O.engines with gravity) and run until at rest. Returns (ids, Settled)."""
    centers = placement.pouring_column(particles, radius, holder_radius, rng)
    ids = [O.bodies.append(utils.sphere(tuple(c), radius, material=material_label))
           for c in centers]
    mass = O.bodies[ids[0]].state.mass
    rest = REST_FRACTION * len(ids) * mass * 9.81 * 2.0 * radius
    m = O.bodies[ids[0]].material
    O.dt = SETTLE_DT_FRACTION * float(placement.rayleigh_time(radius, m.density, m.young,
                                                                m.poisson))
    newton = next(e for e in O.engines if isinstance(e, wrapper.NewtonIntegrator))
    newton.damping = SETTLE_DAMPING
    energy = math.inf
    while O.time < MAX_SETTLE_TIME:
        O.run(CHECK_EVERY, True)
        energy = kinetic_energy(ids)
        if energy < rest and O.time > 0.05:
            break
    else:
        raise RuntimeError(f"the poured bed of {particles} particles was still moving after "
                           f"{MAX_SETTLE_TIME} s of settling (kinetic energy {energy:.3g} J, at "
                           f"rest below {rest:.3g} J)")
    newton.damping = 0.0
    settled = Settled(O.time, O.iter, energy, max(O.bodies[i].state.pos[2] for i in ids) + radius)
    say(f"poured {particles} particles, at rest after {O.time:.3f} s ({O.iter} steps), "
        f"bed {1e3 * settled.height:.1f} mm high")
    for i in ids:
        O.bodies[i].state.vel = (0.0, 0.0, 0.0)
        O.bodies[i].state.angVel = (0.0, 0.0, 0.0)
    O.resetTime()                  # the impact starts at t = 0; periodic engines restart with it
    for e in O.engines:
        if isinstance(e, wrapper.PeriodicEngine):
            e.iterLast, e.virtLast = 0, 0.0
    return ids, settled


@contextlib.contextmanager
def _locked(path):
    """Hold an exclusive lock on `path` + '.lock' (two sweep workers settle a bed once)."""
    path.parent.mkdir(parents=True, exist_ok=True)
    with open(str(path) + ".lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(lock, fcntl.LOCK_UN)


def _cached_files(folder, key):
    """(scene, meta) of `key` in `folder`; a bed cached by version 0.2 where it kept beds
    ($YADEBREAK_CACHE itself) is moved into the default folder, so that it still loads."""
    scene, meta = folder / f"{key}.yade.gz", folder / f"{key}.json"
    if not scene.exists() and folder == cache_folder():
        for old in cache.legacy_folders("beds"):
            if (old / f"{key}.yade.gz").exists() and (old / f"{key}.json").exists():
                folder.mkdir(parents=True, exist_ok=True)
                os.replace(old / f"{key}.json", meta)
                os.replace(old / f"{key}.yade.gz", scene)
    return scene, meta


def cached_scene(folder, key, build):
    """The settled scene `key` from the cache `folder` (None: no cache), else `build()` (which
    makes it in O and returns (bodies, Settled), bodies a dict of ids) saved there. Returns
    (bodies, Settled)."""
    if folder is None:
        return build()
    scene, meta = _cached_files(Path(folder), key)
    with _locked(scene):
        cached = scene.exists() and meta.exists()
        if not cached:
            bodies, settled = build()
            tmp = scene.with_name(scene.name + ".tmp.yade.gz")
            O.save(str(tmp))
            os.replace(tmp, scene)
            meta.write_text(json.dumps({"bodies": bodies,
                                        "settled": dataclasses.asdict(settled)}))
        # every run starts from the saved bed (YADE's save keeps a scene to round-off only, and
        # an impact on a bed amplifies round-off): a run's result does not depend on whether
        # it settled the bed itself
        data = json.loads(meta.read_text())
        O.load(str(scene))
        protocol.forget()                     # rebuilt from O.tags, as in a fresh process
        return data["bodies"], Settled(**{**data["settled"], "cached": cached})
