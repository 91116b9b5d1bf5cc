"""The contact laws whose contacts the engine reads, one class each: what a read, a row's held
energy and a parent's contacts mean under that law. A scene runs one law (chosen once, at attach,
from its InteractionLoop); adding a law to the package is a module with such a class and one
line here."""
from __future__ import annotations

from yadebreak.engine.contacts.hertz import HertzMindlin
from yadebreak.engine.contacts.volumetric import Volumetric

#: the laws read, in the order they are looked for in a scene's InteractionLoop
LAWS = (HertzMindlin, Volumetric)


def laws_in(functor_names):
    """A fresh instance of each law whose YADE functor is among `functor_names` (the class
    names of an InteractionLoop's Law2 functors), in the order of LAWS."""
    return [law() for law in LAWS if law.yade_law in functor_names]

