"""The criteria a material file may name (its breakage.model), and the material files read with
them. Adding a criterion to the package is one line of CRITERIA (docs/architecture.md, "A new
criterion")."""
from __future__ import annotations

from yadebreak.criteria.ab_t10 import AbT10
from yadebreak.criteria.base import registry
from yadebreak.criteria.tavares import Tavares
from yadebreak.model import materials
# what `from yadebreak import materials` (version 0.2's module) gave besides load_material
from yadebreak.model.materials import (Material, MaterialError,  # noqa: F401
                                       available_materials, material_search_path)

#: breakage.model -> its criterion class
CRITERIA = registry(
    Tavares,
    AbT10,
)


def criterion_class(name):
    """The criterion class named `name` (a file's breakage.model)."""
    if name not in CRITERIA:
        raise ValueError(f"criterion = {name!r}: accepted {', '.join(map(repr, CRITERIA))}")
    return CRITERIA[name]


def load_material(name_or_path):
    """Load and validate a material: a name ('copper_ore', looked for along
    yadebreak.material_search_path()) or a path to a .toml file. Every problem is reported at
    once in a MaterialError naming the file, the field and the accepted range; an unknown name
    lists the available materials."""
    return materials.load_material(name_or_path, CRITERIA)


def parse_material(doc, source):
    """The Material of a TOML document `doc` (a dict) read from `source`."""
    return materials.parse(doc, source, CRITERIA)
