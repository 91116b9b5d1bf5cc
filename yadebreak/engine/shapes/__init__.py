"""The particle shapes that can break, one module each (a Shape: its size, its replacement by
progeny), listed in SHAPES by YADE's shape class. Adding a shape to the package is a module
with such a class and one line here (docs/architecture.md, "A new shape")."""
from __future__ import annotations

from yadebreak.engine.shapes.base import Breaking, Frame, Progeny, Shape
from yadebreak.engine.shapes.polyhedron import Polyhedron
from yadebreak.engine.shapes.sphere import Sphere

#: YADE shape class name -> its Shape
SHAPES = {shape.yade_shape: shape for shape in (
    Sphere(),
    Polyhedron(),
)}


def shape_of(body):
    """The Shape of a YADE body, None if its shape cannot break."""
    return SHAPES.get(type(body.shape).__name__)


__all__ = ["Breaking", "Frame", "Progeny", "SHAPES", "Shape", "shape_of"]
