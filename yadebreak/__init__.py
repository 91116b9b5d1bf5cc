"""yadebreak: the Tavares UFRJ particle-breakage model for YADE.

The model layer (model, materials, families) needs only numpy and scipy. The YADE coupling
(`attach`) is imported on first use, so that `import yadebreak` works without YADE.
"""
from .materials import Material, MaterialError, available_materials, load_material
from . import model

__version__ = "0.1.0"

__all__ = ["Material", "MaterialError", "available_materials", "load_material", "model", "attach"]


def attach(*args, **kwargs):
    """Register the breakage engine in the current YADE scene (see yadebreak.coupling.attach)."""
    from .coupling import attach as _attach
    return _attach(*args, **kwargs)
