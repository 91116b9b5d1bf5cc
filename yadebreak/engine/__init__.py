"""The YADE coupling: the only part of yadebreak that imports yade.

    brk = yadebreak.attach(materials={"ore": "copper_ore"}, seed=1)   # after O.engines is set
    coupling.run_steps(20000); brk.events; brk.size_distribution([1e-3])
    yadebreak.save("scene.yade.gz")                                   # O.save with the state

One step's data, in the order the engine (controller.py) moves it: contacts.py reads YADE's
interactions into per-body loading; judging.py and criteria.py decide; state.py keeps bodies,
events and the fines ledger; replacement.py and zeroing.py put the progeny in; stepping.py sets
the time step and the next read; engine.py attaches it all and saves it with the scene;
config.py holds the options. config, state, contacts, criteria and judging never import yade
(they are tested without it); the names below that need YADE import it on first use.
"""
from importlib import import_module

from yadebreak.options.table import AttachError, Config, options_markdown

_NEED_YADE = {"attach": "scene", "controller_of": "scene", "detach": "scene", "forget": "scene",
              "load_checkpoint": "scene", "reload": "scene", "run_steps": "scene",
              "save": "scene", "save_checkpoint": "scene", "Controller": "controller",
              "add_materials": "materials"}

__all__ = ["AttachError", "Config", "options_markdown", *_NEED_YADE]


def __getattr__(name):
    if name in _NEED_YADE:
        return getattr(import_module(f".{_NEED_YADE[name]}", __name__), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
