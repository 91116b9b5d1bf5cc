"""The engine in YADE's loop (docs/architecture.md).

    brk = yadebreak.attach(materials={"ore": "copper_ore"}, seed=1)   # after O.engines is set
    engine.run_steps(20000); brk.events; brk.size_distribution([1e-3])
    yadebreak.save("scene.yade.gz")                                   # O.save with the state

One read, in the order controller.py moves it: contacts/ reads YADE's interactions into each
tracked body's loading; judging.py asks each body's criterion (yadebreak.criteria) which break;
replacement.py (with each shape's strategy, shapes/) and zeroing.py put the progeny in;
stepping.py sets the time step, reads.py the next read; tracking.py keeps which bodies are read;
state.py holds bodies, events and the fines ledger; scene.py attaches it all and saves it with
the scene; materials.py makes YADE materials from material files; parts/ holds rolling friction
and bond watching. The names below that need
YADE import it on first use.
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
