"""The YADE coupling: the only part of yadebreak that imports yade.

    brk = yadebreak.attach(materials={"ore": "copper_ore"}, seed=1)   # after O.engines is set
    coupling.run_steps(20000); brk.events; brk.size_distribution([1e-3])
    yadebreak.save("scene.yade.gz")                                   # O.save with the state

One step's data, in the order the engine (controller.py) moves it: contacts.py reads YADE's
interactions into per-body loading; criteria.py judges it; state.py keeps bodies, events and
the fines ledger; replacement.py and zeroing.py put the progeny in; stepping.py sets the time
step and the next read. config.py holds the options.
"""
from .config import AttachError, Config, options_markdown
from .controller import Controller
from .engine import (attach, controller, detach, forget, load_checkpoint, run_steps, save,
                     save_checkpoint)
from .scene_materials import add_materials

__all__ = ["AttachError", "Config", "Controller", "add_materials", "attach", "controller",
           "detach", "forget", "load_checkpoint", "options_markdown", "run_steps", "save",
           "save_checkpoint"]
