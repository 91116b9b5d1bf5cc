"""What a breakable shape is to the engine (Shape), what its replacement may use of the engine
(Breaking, the narrow context the Replacer hands it) and what it returns (Progeny)."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, NamedTuple

import numpy as np


@dataclass
class Progeny:
    """What a replacement made: fragment ids (bodies in the scene), the family's t10' (%), the
    largest fragment speed beyond the parent's rigid field (m/s), the smallest fragment of each
    YADE material among them as [(radius (m), material)] (empty if every fragment went to the
    ledger; what the time step needs), and the energy audit (J): kinetic and elastic energy of
    the parent just before, of the progeny just after."""

    ids: list
    family_t10: float
    speed_excess: float
    smallest: list
    audit: dict


@dataclass(frozen=True)
class Breaking:
    """What a shape's replacement of one parent may use of the engine, and no more."""

    label: str              # the parent's material label
    recipe: object          # replacement.Recipe of that material
    options: object         # config.Replacement
    rng: object             # the engine's numpy Generator
    table: object           # the body table (state.BodyTable): the parent's mass, size, ...
    ledger: object          # the fines ledger (state.Ledger)
    zeroing: object         # zeroing.OverlapZeroing: drop_body, zero_pair
    reader: object          # contacts.ContactReader: stiffness, inherit
    open_events: set        # bodies whose event is open (judged at the next read)
    neighbours: Callable    # (bid, each=None) -> (neighbour ids, elastic energy (J) of their
    #                         contacts as the scene's law holds it)
    add_rows: Callable      # Replacer.new_rows: the fragments' rows in the body table


class Frame(NamedTuple):
    """A shape's bodies as ParaView draws them (jobs/paraview.py), in body order: ids,
    velocities, and either a point per body (`faces` None: its centre) or polygons over the
    points (`faces`, lists of point indices; `owner`, the index into ids of each polygon's
    body); `arrays`, the shape's own per-body values [(name, values, VTK type)] written after
    the id (a sphere's radius, a polyhedron's volume)."""
    ids: np.ndarray         # (n,) int64
    vel: np.ndarray         # (n, 3) m/s
    points: np.ndarray      # (m, 3) m
    faces: list = None
    owner: np.ndarray = None
    arrays: list = ()


class Shape:
    """A particle shape that can break: its size for Eq. 3 and the t10 sieves, its
    replacement by progeny, and its bodies as ParaView draws them. One instance per shape (no
    state); SHAPES (shapes/__init__.py) lists them by YADE's shape class."""

    #: its name in jobs and docs, and of many of its bodies
    name = ""
    plural = ""
    #: the YADE Shape class (its name) of its bodies
    yade_shape = ""
    #: its ParaView series is written from the first frame even with no body of it (the
    #: spheres': a scene's ball is one); else from the first frame that has one
    paraview_from_start = False

    def size(self, body):
        """The body's size (m): Eq. 3's, and the sieve it passes (2 radius for a sphere)."""
        raise NotImplementedError

    def replace(self, breaking, body, bid, t10, direction, dmin):
        """Erase body `bid` (`body`) and insert its progeny for t10' (%); `direction`: the
        normal of its most energetic contact; `dmin` (m): progeny finer than it cannot break.
        Returns a Progeny."""
        raise NotImplementedError

    def frame(self, bodies):
        """Its bodies among `bodies` (YADE's O.bodies) now, as a Frame; None: the shape is not
        drawn in ParaView."""
        return None
