"""Unconfined bed impact (paper Sections 3.1, 3.2, 4.2; Figs. 7, 20-23).

A 88 mm steel ball (2.78 kg) hits a bed of particles of one size resting on a steel anvil:
a central particle with --rings hexagonal rings, --layers layers (several layers are held by a
cylindrical holder removed at the first touch; by default they are poured into it and settled
under gravity, the settled bed kept in a cache for the next run). Rolling friction per contact
pair from the material files. Default: copper ore, 3 rings, 1 layer, 3.05 J.

    yade -n scripts/bed_impact.py                    # run, then the YADE prompt for inspection
    yade -n -x scripts/bed_impact.py --rings 2 --energy 2   # headless
Writes summary.json, events.jsonl, size_distribution.csv, plots and a ParaView time series
(paraview/spheres.pvd, surfaces.pvd) into --out, and
checkpoint.yade.gz every --checkpoint-every seconds: `--resume 1` continues a run that died.
"""
import sys
from pathlib import Path

sys.path.insert(0, str(Path(sys.argv[0]).resolve().parent.parent))   # yade sets argv[0]

from yadebreak.jobs import options as job_options  # noqa: E402

args = job_options.read("bed_impact", __doc__)

from yadebreak.jobs import bed  # noqa: E402
from yadebreak.jobs.lifecycle import run_script  # noqa: E402

brk, result = run_script(bed.run, args) or (None, None)   # None: resumed a finished run
