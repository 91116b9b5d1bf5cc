"""Scenes of the stability matrix (jobs/extremes.py) beyond the impact scenes: touching pairs
fired at each other, and particles in a corner of a wall and two facets."""
from __future__ import annotations

from yadebreak.engine import add_materials
from yadebreak.adapter.yade_api import O, utils
from yadebreak.scenes.impacts import hertz_engines


def _ore_scene(ore):
    """A fresh scene with `ore` (a Material, YADE label "ore") and steel; returns the Ip2."""
    O.reset()
    ip2, _ = add_materials({"ore": ore, "steel": "steel"})
    return ip2


def head_on_pairs(ore, size, n, speed):
    """n pairs of touching spheres of diameter `size` (m) fired at each other at `speed` (m/s)
    each, along x; returns their ids (attach next)."""
    ip2 = _ore_scene(ore)
    r = size / 2.0
    ids = []
    for k in range(n):
        y = 4 * size * k
        for sign in (-1.0, 1.0):
            b = utils.sphere((sign * r * 1.001, y, 0.0), r, material="ore")
            b.state.vel = (-sign * speed, 0.0, 0.0)
            ids.append(O.bodies.append(b))
    O.engines = hertz_engines(ip2)
    return ids


def in_facet_corner(ore, size, n):
    """n spheres of diameter `size` (m) resting on a facet floor against a facet side, the first
    also against a wall; returns their ids (attach next)."""
    ip2 = _ore_scene(ore)
    r = size / 2.0
    ids = []
    for k in range(n):
        x0 = 4 * size * k
        floor = utils.facet([(x0 - size, -size, 0), (x0 + size, -size, 0), (x0, size, 0)],
                            material="steel")
        side = utils.facet([(x0 - size, -r, -size), (x0 + size, -r, -size), (x0, -r, 2 * size)],
                           material="steel")
        O.bodies.append([floor, side])
        ids.append(O.bodies.append(utils.sphere((x0, 0.0, r), r, material="ore")))
    O.bodies.append(utils.wall(-4 * size, axis=0, sense=1, material="steel"))
    b = O.bodies[ids[0]]
    b.state.pos = (-4 * size + r, 0.0, r)          # the first one touches the wall as well
    O.engines = hertz_engines(ip2, facets=True)
    return ids
