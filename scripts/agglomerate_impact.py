"""A bonded agglomerate's normal impact on a rigid plane: the Timoshenko beam bond model.

The bonded-agglomerate study's case (docs/bonded.md): 4,104 glass ballotini of 1.4-1.7 mm in a
30 mm sphere, bonded by epoxy beams (17,414 in the document, 8.5 per sphere), at 4 m/s on a rigid
plane. --particles builds a smaller agglomerate by the same rules (same sizes and packing
density). Bonds fail in tension, shear or compression (Eqs. B7-B8), once.

    yade -n -x scripts/agglomerate_impact.py                       # the document's case, 1 ms
    yade -n -x scripts/agglomerate_impact.py --particles 500 --duration 5e-4 --out out/small
    yade -n -x scripts/agglomerate_impact.py --radius-multiplier 0.4 --speed 6

Writes into --out: summary.json, timeseries.csv (every --sample-interval: damage ratio, bonds
broken by mode, bonds at >= 80 % of a strength, kinetic energy, debris), bonds_broken.csv (a line
per bond as it breaks), agglomerate_impact.png (those against the document's reported times),
damage_section.png and a ParaView series coloured by damage ratio (paraview/spheres.pvd).
A checkpoint every --checkpoint-every s of wall time; a run that died goes on with --resume 1.
"""
import sys
from pathlib import Path

sys.path.insert(0, str(Path(sys.argv[0]).resolve().parent.parent))   # yade sets argv[0]

from yadebreak.tools.options import (checkpointed_run_options, integer, number,  # noqa: E402
                                  script_params, text)

args = script_params([
    text("material", "glass_epoxy", "the spheres and binder: a bonded-agglomerate material "
         "name of the library or a .toml file"),
    integer("particles", 4104, "primary spheres (the document's 4,104; fewer: a smaller "
            "agglomerate of the same sizes and packing density)", lo=2, hi=200000),
    number("speed", 4.0, "m/s", "impact speed, normal to the plane", lo=0, lo_open=True, hi=100),
    number("duration", 1e-3, "s", "simulated time after the first touch", lo=0, lo_open=True,
           hi=1.0),
    number("radius_multiplier", 0.0, "-", "bond radius over the smaller sphere's, lambda "
           "(0: the material file's)", lo=0, hi=1),
    number("time_step_fraction", 0.2, "-", "time step as a fraction of the shorter of the bonds' "
           "time scale and the smallest sphere's Rayleigh time", lo=0, lo_open=True, hi=1),
    integer("check_period", 1, "steps between two evaluations of the failure criterion over the "
            "intact bonds (1: every step, exact)", lo=1, hi=100000),
    number("sample_interval", 5e-6, "s", "simulated time between rows of timeseries.csv",
           lo=0, lo_open=True),
    integer("seed", 1, "random seed (packing and bond strengths)", lo=0),
    *checkpointed_run_options(5e-5, "out/agglomerate_impact"),
], __doc__)

from yadebreak.runs import agglomerate  # noqa: E402
from yadebreak.tools.options import run_script  # noqa: E402

summary = run_script(agglomerate.run, args)
