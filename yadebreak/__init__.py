"""yadebreak: the Tavares UFRJ particle-breakage model for YADE.

The package by concern (docs/architecture.md):

    model/     the breakage model in numpy/scipy (equations, materials, families, placement, ...)
    criteria/  when a body breaks and what it leaves: one class per criterion
    options/   the engine's option table and the flags of scripts and tools
    analysis/  results against the model, and their plots
    adapter/   yade_api.py, the one module that imports yade
    engine/    the engine and its parts in YADE's loop
    scenes/    every builder of a YADE scene
    jobs/      the jobs behind scripts/ and their lifecycle
    studies/   verify, calibration, grinding, sweeps, the trade-off
    cli.py     python3 -m yadebreak

`import yadebreak` needs only numpy and scipy: `attach` and `save` import the engine (and YADE)
on first use.
"""
import os
from importlib import import_module

# YADE's OpenMP loops in one thread, as the `yade` launcher runs them, unless the user chose: set
# before anything loads libgomp (pyplot does), which reads it once (yadebreak.adapter.yadepath)
os.environ.setdefault("OMP_NUM_THREADS", "1")

from yadebreak.model.materials import (Material, MaterialError, available_materials,
                                       material_search_path)
from yadebreak.criteria import load_material
from yadebreak.options.table import AttachError
from yadebreak import model
from yadebreak import criteria
from yadebreak._moved import install as _install_moved

_install_moved()

__version__ = "0.3.0"

__all__ = ["AttachError", "Material", "MaterialError", "available_materials", "load_material",
           "material_search_path", "model", "criteria", "attach", "save"]

# where the modules of version 0.2 went: `from yadebreak import families` keeps working
_MOVED = {"materials": "criteria.registry", "families": "model.families",
          "placement": "model.placement", "bonds": "model.bonds", "milling": "model.milling",
          "intervals": "model.intervals", "reports": "analysis.reports",
          "scenes": "scenes", "poured_bed": "scenes.poured_bed",
          "bed": "jobs.bed", "mill": "jobs.mill", "agglomerate": "jobs.agglomerate",
          "extremes": "jobs.extremes", "paraview": "jobs.paraview",
          "scriptargs": "options.flags", "sweep": "studies.sweep", "tradeoff": "studies.tradeoff",
          "calibration": "studies.calibration", "grinding": "studies.grinding",
          "yadepath": "adapter.yadepath"}


def __getattr__(name):
    if name in _MOVED:
        return import_module(f"yadebreak.{_MOVED[name]}")
    raise AttributeError(f"module 'yadebreak' has no attribute {name!r}")


def attach(*args, **kwargs):
    """Register the breakage engine in the current YADE scene (see yadebreak.engine.attach)."""
    from yadebreak.engine import attach as _attach
    return _attach(*args, **kwargs)


def save(path):
    """O.save the scene with yadebreak's state (see yadebreak.engine.save)."""
    from yadebreak.engine import save as _save
    return _save(path)
