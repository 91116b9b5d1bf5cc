"""yadebreak: the Tavares UFRJ particle-breakage model for YADE.

The model layer (model, materials, families, placement) needs only numpy and scipy. The YADE
coupling (`attach`, `save`) is imported on first use, so that `import yadebreak` works without
YADE.
"""
from .materials import (Material, MaterialError, available_materials, load_material,
                        material_search_path)
from . import model

__version__ = "0.2.0"

__all__ = ["Material", "MaterialError", "available_materials", "load_material",
           "material_search_path", "model", "attach", "save"]


def attach(*args, **kwargs):
    """Register the breakage engine in the current YADE scene (see yadebreak.coupling.attach)."""
    from .coupling import attach as _attach
    return _attach(*args, **kwargs)


def save(path):
    """O.save the scene with yadebreak's state (see yadebreak.coupling.save)."""
    from .coupling import save as _save
    return _save(path)
