"""The model layer: the breakage model as plain numpy/scipy; nothing here imports yade.

    from yadebreak import model
    model.t10(1000.0, p.A, p.b_prime, p.kappa)   # p = material.params; the equations are re-exported here

equations   the Tavares UFRJ model, one function per equation (docs/model.md numbers them)
materials   material files (TOML) read, checked and converted to SI once
families    progeny families for sphere replacement
cells       convex cells of a broken polyhedron (clipped Laguerre tessellation)
placement   where fragments go inside their parent, and how they move
bonds       bonded agglomerates: the beam-bond model and its material files
milling     the laboratory ball mill's classical relations (critical speed, Bond, power)
reports     impact-test results against the model (probability, t10, progeny)
intervals   the accepted ranges of every number, one home for the check and its wording
"""
from yadebreak.model.equations import *  # noqa: F401,F403 (the equations are the model's public face)
from yadebreak.model.equations import __all__  # noqa: F401
