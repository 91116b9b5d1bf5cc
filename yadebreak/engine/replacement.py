"""Replacing a broken body by its progeny, whatever its shape: the Replacer hands the parent's
shape (engine/shapes/: a sphere by a family of spheres, a convex polyhedron by its cells) a
narrow context (shapes.Breaking) and writes the fragments' rows in the body table
(new_rows). The work is proportional to the progeny and the parent's neighbours, never to the
scene.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from yadebreak import model
from yadebreak.adapter.yade_api import O
from yadebreak.engine.shapes import Breaking, shape_of
from yadebreak.engine.state import BREAKABLE, DUMMY, UNBREAKABLE


@dataclass(frozen=True)
class Recipe:
    """How the progeny of one breakable material are made."""

    criterion: object      # draws the fragments' fracture energies (criteria.Criterion)
    families: object       # model.families.FamilyTable: the family of an event's t10'
    pause_steps: int       # steps a fresh fragment is not judged (0: none)
    damped: object         # True/False: fragments start damped (global damping); None: no
    #                        material of the scene is damped (YADE's default is left alone)
    dummy_material: object  # YADE material of its dummies (a softer one), None: its own


class Replacer:
    """Replaces broken bodies, each by its shape's strategy (engine/shapes/); one per
    engine."""

    def __init__(self, options, state, recipes, zeroing, reader):
        self.options = options         # config.Replacement
        self.state = state
        self.table = state.table
        self.rng = state.rng
        self.ledger = state.ledger
        self.recipes = recipes         # material label -> Recipe
        self.zeroing = zeroing
        self.reader = reader           # told which contacts the fragments inherit

    def replace(self, bid, t10, direction, dmin):
        """Erase body `bid` and insert its progeny for t10' (%), as its shape does it
        (Shape.replace); `direction`: the normal of its most energetic contact. Returns a
        Progeny."""
        body = O.bodies[bid]
        label = self.table.label_of(bid)
        breaking = Breaking(label, self.recipes[label], self.options, self.rng, self.table,
                            self.ledger, self.zeroing, self.reader, self.state.open_events,
                            self.neighbours, self.new_rows)
        return shape_of(body).replace(breaking, body, bid, t10, direction, dmin)

    def neighbours(self, bid, each=None):
        """The parent's neighbours (ids) and the elastic energy (J) of its contacts with them,
        as the scene's contact law holds it (contacts/laws.py); `each` (a dict), if given,
        receives the energy of each neighbour's contact (Hertz-Mindlin)."""
        reader = self.reader
        return reader.contact_law.neighbour_energy(reader, bid, O.interactions.withBody(bid),
                                                   self.zeroing.pairs, each)

    def new_rows(self, ids, label, is_dummy, radii, masses, t10, parent_size, generation, dmin):
        """The fragments' state: dummy, unbreakable (its own progeny would be finer than dmin)
        or breakable, with fracture energies drawn at their own sizes (unbreakable ones too:
        their first would-be breakage gives the t10' they keep)."""
        if not ids:
            return
        kinds = np.where(is_dummy, DUMMY,
                         np.where(model.X_MIN * 2.0 * radii < dmin, UNBREAKABLE, BREAKABLE))
        values = {"generation": generation}
        recipe = self.recipes[label]
        pause = recipe.pause_steps
        if pause:
            values["pause_until"] = O.iter + pause
        self.table.add(ids, kinds, label, masses, radii, **values)
        ids = np.asarray(ids)
        dummies = ids[is_dummy]
        self.table.columns["t10"][dummies] = t10
        self.table.columns["parent_size"][dummies] = parent_size
        need = np.nonzero(~is_dummy)[0]
        if len(need):
            energies, extra = recipe.criterion.sample(self.rng, 2.0 * radii[need])
            c = self.table.columns
            c["fracture_energy"][ids[need]] = energies
            c["fracture_energy_initial"][ids[need]] = energies
            for name, value in extra.items():
                c[name][ids[need]] = value
