"""Scene builders shared by the scripts and tests (coupling layer: imports yade)."""
from __future__ import annotations

import math

import numpy as np

# the coupling makes yade importable from Debian's python3 first
from .coupling import O, _wrapper as _w, add_materials, attach, utils


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


def run_until_rebound(ids, max_steps=200000, check_every=50):
    """Run until every listed body (or its fragments) moves away from the plate (vz >= 0) and
    touches nothing, or max_steps."""
    done_steps = 0
    while done_steps < max_steps:
        O.run(check_every, True)
        done_steps += check_every
        if all(_left(i) for i in ids):
            break
    return done_steps


def _left(i):
    b = O.bodies[i] if i < len(O.bodies) else None
    if b is None:
        return True                # broken and replaced: its fragments fly on
    return b.state.vel[2] >= 0.0 and len(O.interactions.withBody(i)) == 0
