"""What a job reads of the scene it runs, and what it asks of the YADE process: jobs reach YADE
only through the scenes and the engine (docs/architecture.md), so these few reads are named here
rather than spelled with YADE's objects in every job."""
from __future__ import annotations

from typing import NamedTuple

import numpy as np

from yadebreak.adapter import yade_api as _yade
from yadebreak.adapter.yade_api import O, utils, wrapper
from yadebreak.engine.shapes import SHAPES


# -- the clock -----------------------------------------------------------------------------------
def now():
    """Simulated time (s)."""
    return O.time


def iteration():
    """Steps run since the scene began."""
    return O.iter


def time_step():
    """The time step (s)."""
    return O.dt


def reset():
    """An empty scene (O.reset)."""
    O.reset()


# -- bodies ----------------------------------------------------------------------------------------
def position(i):
    """Body i's position (m), a tuple."""
    return tuple(O.bodies[i].state.pos)


def velocity(i):
    """Body i's velocity (m/s), a tuple."""
    return tuple(O.bodies[i].state.vel)


def touching(i):
    """True if body i has an interaction (real or potential: its bounds overlap another's)."""
    return any(O.interactions.withBody(i))


def in_contact(i):
    """True if body i has a real interaction (its geometry overlaps another body's)."""
    return any(j.isReal for j in O.interactions.withBody(i))


def body_count():
    """Bodies in the scene (erased ones not counted)."""
    return sum(1 for b in O.bodies if b is not None)


def kinetic_energy():
    """Kinetic energy (J) of every body, rotation included (utils.kineticEnergy)."""
    return float(utils.kineticEnergy())


def moving_kinetic_energy():
    """Kinetic energy (J) of the dynamic bodies, their rotation taken about inertia[0] (spheres)."""
    total = 0.0
    for b in O.bodies:
        if b is not None and b.dynamic:
            total += 0.5 * b.state.mass * b.state.vel.squaredNorm()
            total += 0.5 * b.state.inertia[0] * b.state.angVel.squaredNorm()
    return total


def all_finite():
    """True if every body's position, velocity and spin are finite."""
    for b in O.bodies:
        if b is not None:
            s = b.state
            if not (np.all(np.isfinite(s.pos)) and np.all(np.isfinite(s.vel))
                    and np.all(np.isfinite(s.angVel))):
                return False
    return True


def real_contacts():
    """How many real interactions the scene has."""
    return O.interactions.countReal()


class Spheres(NamedTuple):
    """Every sphere of the scene, one row each (one pass over YADE's bodies)."""
    ids: np.ndarray         # (n,) int64
    pos: np.ndarray         # (n, 3) m
    vel: np.ndarray         # (n, 3) m/s
    radius: np.ndarray      # (n,) m


def bodies():
    """YADE's bodies of the scene (O.bodies), for the engine's shapes to draw
    (engine/shapes/: Shape.frame)."""
    return O.bodies


def spheres():
    """The scene's spheres (Spheres): their shape's ParaView frame (engine/shapes/sphere.py)."""
    frame = SHAPES["Sphere"].frame(O.bodies)
    return Spheres(frame.ids, frame.points, frame.vel, frame.arrays[0][1])


def finest_sphere_size():
    """Diameter (m) of the smallest sphere in the scene (nan if none)."""
    radius = spheres().radius
    return float(2.0 * radius.min()) if len(radius) else float("nan")


class Surface(NamedTuple):
    """A facet (its corners) or a wall (its axis and position along it) of the scene."""
    id: int
    corners: list           # a facet's corners [(x, y, z)] (m); None for a wall
    axis: int               # a wall's normal axis (0, 1, 2); -1 for a facet
    offset: float           # a wall's position along its axis (m)


def surfaces():
    """The scene's facets and walls (Surface), in body order."""
    found = []
    for b in O.bodies:
        if b is None:
            continue
        if isinstance(b.shape, wrapper.Facet):
            found.append(Surface(b.id, [tuple(b.state.pos + b.state.ori * v)
                                        for v in b.shape.vertices], -1, 0.0))
        elif isinstance(b.shape, wrapper.Wall):
            axis = b.shape.axis
            found.append(Surface(b.id, None, axis, float(b.state.pos[axis])))
    return found


# -- the YADE process ------------------------------------------------------------------------------
def batch_row(defaults):
    """A yade-batch table row's values for these options ({name: default}) and the row's
    description (None outside a batch)."""
    return _yade.table_row(defaults)


def close_remote_access():
    """Close the Python prompt and info servers the `yade` launcher opens (their ports)."""
    return _yade.close_remote_access()
