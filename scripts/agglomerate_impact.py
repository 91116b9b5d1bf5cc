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

from yadebreak.jobs import options as job_options  # noqa: E402

args = job_options.read("agglomerate_impact", __doc__)

from yadebreak.jobs import agglomerate  # noqa: E402
from yadebreak.jobs.lifecycle import run_script  # noqa: E402

summary = run_script(agglomerate.run, args)
