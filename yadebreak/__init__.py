"""yadebreak: the Tavares UFRJ particle-breakage model for YADE.

The package in layers (docs/architecture.md):

    model/     the breakage model in numpy/scipy (equations, materials, families, placement, ...)
    tools/     options, sweeps, the trade-off, calibration, grinding: plain Python
    coupling/  the engine inside YADE's loop; coupling/yade_api.py is the one module importing yade
    scenes/    builders of YADE scenes (impacts, beds, ...)
    runs/      the jobs behind scripts/ (bed, mill, agglomerate, extremes)

`import yadebreak` needs only numpy and scipy: `attach` and `save` import the coupling (and YADE)
on first use.
"""
from importlib import import_module

from yadebreak.model.materials import (Material, MaterialError, available_materials,
                                       load_material, material_search_path)
from yadebreak import model

__version__ = "0.3.0"

__all__ = ["Material", "MaterialError", "available_materials", "load_material",
           "material_search_path", "model", "attach", "save"]

# where the modules of version 0.2 went: `from yadebreak import families` keeps working
_MOVED = {"materials": "model.materials", "families": "model.families",
          "placement": "model.placement", "bonds": "model.bonds", "milling": "model.milling",
          "intervals": "model.intervals", "reports": "model.reports",
          "scenes": "scenes", "poured_bed": "scenes.poured_bed",
          "bed": "runs.bed", "mill": "runs.mill", "agglomerate": "runs.agglomerate",
          "extremes": "runs.extremes", "paraview": "runs.paraview",
          "scriptargs": "tools.options", "sweep": "tools.sweep", "tradeoff": "tools.tradeoff",
          "calibration": "tools.calibration", "grinding": "tools.grinding",
          "yadepath": "coupling.yadepath"}


def __getattr__(name):
    if name in _MOVED:
        return import_module(f"yadebreak.{_MOVED[name]}")
    raise AttributeError(f"module 'yadebreak' has no attribute {name!r}")


def attach(*args, **kwargs):
    """Register the breakage engine in the current YADE scene (see yadebreak.coupling.attach)."""
    from yadebreak.coupling import attach as _attach
    return _attach(*args, **kwargs)


def save(path):
    """O.save the scene with yadebreak's state (see yadebreak.coupling.save)."""
    from yadebreak.coupling import save as _save
    return _save(path)
