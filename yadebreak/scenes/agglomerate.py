"""A bonded agglomerate's scene (docs/bonded.md): its spheres, a rigid plane, the engines of YADE's
cohesive law beside Hertz-Mindlin, and its bonds watched by the engine's BondWatch part
(engine/parts/bonds.py).

    built = agglomerate_scene(material, packing, seed=1)          # after O.reset()
    watch = built.watch                                           # a BondWatch, in O.engines
    O.run(1000, True); watch.broken_count(), watch.damage_ratios()
    renew_contacts(); save_checkpoint(path, built, script_state)  # later, perhaps elsewhere:
    built, script_state = load_checkpoint(path)                   # goes on exactly as it would
"""
from __future__ import annotations

import json
import math
from dataclasses import dataclass

import numpy as np

from yadebreak.model import bonds, placement
from yadebreak.options.table import AttachError
from yadebreak.engine import scene as engine_scene
from yadebreak.engine.parts.bonds import (LABEL, MAX_STEPS, TAG, TIME_STEP, BondWatch,  # noqa: F401
                                          attach_bonds, watch_of)
from yadebreak.adapter.yade_api import O, utils, wrapper as _w


@dataclass
class AgglomerateScene:
    """What agglomerate_scene() built: YADE ids and the BondWatch engine."""

    sphere_ids: np.ndarray   # (n,) YADE body id of packing sphere k
    target_id: int           # the rigid plane
    watch: "BondWatch"
    masses: np.ndarray       # (n,) kg
    time_scale: float        # Eq. B11, s
    rayleigh_time: float     # of the smallest sphere, s
    impact_seconds: float = 0.0   # wall time of the run from the first touch (set by the run)


def agglomerate_scene(material, packing, seed, speed=4.0, gap=1e-5, gravity=9.81,
                      time_step_fraction=0.2, check_period=1, duration=0.0):
    """The agglomerate of `packing` (a bonds.Packing, centred at the origin) bonded by
    `material` (a bonds.AgglomerateMaterial) in the current, empty YADE scene, its lowest point
    `gap` (m) above a rigid steel plane z = 0 and moving down at `speed` (m/s). Bond strengths
    are drawn from numpy's Generator seeded by `seed`. O.dt = time_step_fraction x the shorter of
    the bonds' time scale (Eq. B11) and the smallest sphere's Rayleigh time; AttachError (one
    line) if that step is out of TIME_STEP or the steps to the touch and through `duration` (s)
    after it exceed YADE's step counter."""
    sp, binder = material.spheres, material.binder
    rng = np.random.default_rng(seed)
    sphere_mat = O.materials.append(_w.FrictMat(
        young=sp.young_modulus, poisson=sp.poisson_ratio, density=sp.density,
        frictionAngle=math.atan(sp.friction), label="spheres"))
    steel = O.materials.append(_w.FrictMat(young=210e9, poisson=0.3, density=7800,
                                           frictionAngle=math.atan(sp.friction), label="target"))
    pos = packing.positions.copy()
    pos[:, 2] += gap - float((pos[:, 2] - packing.radii).min())     # lowest point `gap` above
    ids = np.array(O.bodies.append([utils.sphere(tuple(p), float(r), material=sphere_mat)
                                    for p, r in zip(pos, packing.radii)]))
    target = O.bodies.append(utils.wall(0.0, axis=2, sense=1, material=steel))
    masses = np.array([O.bodies[int(i)].state.mass for i in ids])
    inertia = 0.4 * masses * packing.radii**2
    for i in ids:
        O.bodies[int(i)].state.vel = (0.0, 0.0, -speed)

    pairs, lengths = bonds.bond_pairs(pos, packing.radii, binder.contact_radius_multiplier)
    rayleigh = float(placement.rayleigh_time(packing.radii.min(), sp.density, sp.young_modulus,
                                             sp.poisson_ratio))
    O.engines = bonded_engines(sp, gravity)
    watch, time_scale = attach_bonds(ids, pairs, lengths, packing.radii, binder, rng, target,
                                     check_period)
    dt = time_step_fraction * min(time_scale, rayleigh)
    steps = (gap / speed + duration) / dt if dt > 0 else math.inf
    if dt not in TIME_STEP or not steps <= MAX_STEPS:
        raise AttachError(
            f"time_step_fraction = {time_step_fraction:g}: the time step {dt:.3g} s (that fraction "
            f"of the shorter of the bonds' time scale, {time_scale:.3g} s, and the smallest "
            f"sphere's Rayleigh time, {rayleigh:.3g} s, of {material.source}) needs {steps:.3g} "
            f"steps for {duration:g} s after the touch: accepted a time step {TIME_STEP} s and "
            f"at most {MAX_STEPS:.3g} steps (YADE's step counter)")
    O.dt = dt
    set_rolling_stiffness(inertia.min())
    return AgglomerateScene(ids, target, watch, masses, time_scale, rayleigh)


def bonded_engines(spheres, gravity=9.81):
    """The scene's engines: Hertz-Mindlin with damping (restitution) and rolling resistance for
    the non-bonded contacts (the scene's only physics functor: a broken bond's spheres that touch
    again get it), YADE's cohesive law integrating the bonds' beams, undamped Newton with gravity
    along -z. The rolling stiffness is set by set_rolling_stiffness once O.dt is known."""
    return [
        _w.ForceResetter(),
        _w.InsertionSortCollider([_w.Bo1_Sphere_Aabb(), _w.Bo1_Wall_Aabb()]),
        _w.InteractionLoop(
            # the real levers (centre to contact point) in the shear increment: the beam mapping
            # of Eq. B6 needs them (YADE by default takes the radii, which gap bonds exceed)
            [_w.Ig2_Sphere_Sphere_ScGeom6D(avoidGranularRatcheting=False),
             _w.Ig2_Wall_Sphere_ScGeom()],
            [_w.Ip2_FrictMat_FrictMat_MindlinPhys(en=spheres.restitution, es=spheres.restitution,
                                                   eta=spheres.rolling_friction, krot=0.0,
                                                   label="hertz")],
            [_w.Law2_ScGeom6D_CohFrictPhys_CohesionMoment(label="beams"),
             _w.Law2_ScGeom_MindlinPhys_Mindlin(includeMoment=True, label="law")]),
        _w.NewtonIntegrator(damping=0.0, gravity=(0.0, 0.0, -gravity), label="newton"),
    ]


def set_rolling_stiffness(smallest_inertia):
    """Rolling resistance (Eq. B10) as YADE's elastic-plastic contact moment, limited at
    mu_r F_n R: a stiffness (N m/rad) that reaches the limit within a few steps yet keeps the
    rotation of the smallest sphere (moment of inertia, kg m2) stable: 0.1 I / dt^2."""
    hertz = next(f for e in O.engines if isinstance(e, _w.InteractionLoop)
                 for f in e.physDispatcher.functors if f.label == "hertz")
    hertz.krot = 0.1 * float(smallest_inertia) / O.dt**2


def save_checkpoint(path, scene, script_state):
    """engine.save_checkpoint (the scene to `path` atomically, with a script's loop state and
    every part's state, the BondWatch's included) with the record of `scene` (an
    AgglomerateScene: its ids and time scales) in O.tags."""
    O.tags[TAG] = json.dumps({
        "iter": O.iter, "label": LABEL,
        "sphere_ids": scene.sphere_ids.tolist(), "target_id": int(scene.target_id),
        "time_scale": scene.time_scale, "rayleigh_time": scene.rayleigh_time})
    engine_scene.save_checkpoint(path, script_state)


def renew_contacts():
    """Put the scene in the state an O.load of it gives, so that a run resumed from a checkpoint
    saved right after this goes on exactly as the run that saved it. YADE's save keeps the
    interactions but not its collider's candidate pairs (non-real interactions): a loaded scene's
    collider finds them again in its own order, contacts made later sit elsewhere in the list of
    interactions, and the forces on their spheres are summed in another order (last-bit
    differences that the flow amplifies). Here the candidates are dropped and the collider
    replaced by a fresh one with the same settings, as a load does; called at the same steps of
    every run, resumed or not. Cost: one full sort of the bounds (0.1 s at 4,104 spheres)."""
    O.interactions.eraseNonReal()
    engines = list(O.engines)
    k = next(i for i, e in enumerate(engines) if isinstance(e, _w.InsertionSortCollider))
    old = engines[k]
    fresh = _w.InsertionSortCollider(list(old.boundDispatcher.functors))
    for key, value in old.dict().items():
        if key not in ("boundDispatcher", "newton", "numReinit"):   # set by YADE, or read-only
            setattr(fresh, key, value)
    engines[k] = fresh
    O.engines = engines


def load_checkpoint(path):
    """O.load a checkpoint written by save_checkpoint: (AgglomerateScene, script state)."""
    _, script_state = engine_scene.load_checkpoint(path, label=None)
    return restore_scene(), script_state


def restore_scene():
    """The AgglomerateScene of a scene loaded from save_checkpoint's file, its BondWatch
    restored (engine.parts.bonds.watch_of). RuntimeError if the scene has no such record."""
    if TAG not in O.tags.keys() or not O.tags[TAG]:
        raise RuntimeError("this bonded scene has no BondWatch state: its bonds are watched by "
                           "the process that built it, or saved with "
                           "scenes.agglomerate.save_checkpoint")
    data = json.loads(O.tags[TAG])
    watch = watch_of(data["label"])
    ids = np.array(data["sphere_ids"], np.int64)
    masses = np.array([O.bodies[int(i)].state.mass for i in ids])
    return AgglomerateScene(ids, data["target_id"], watch, masses, data["time_scale"],
                            data["rayleigh_time"])
