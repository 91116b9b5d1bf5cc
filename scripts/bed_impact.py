"""Unconfined bed impact (paper Sections 3.1, 3.2, 4.2; Figs. 7, 20-23).

A 88 mm steel ball (2.78 kg) hits a bed of particles of one size resting on a steel anvil:
a central particle with --rings hexagonal rings, --layers layers (several layers are held by a
cylindrical holder removed at the first touch). Default: copper ore, 3 rings, 1 layer, 3.05 J.

    yade -n scripts/bed_impact.py                    # run, then the YADE prompt for inspection
    yade -n -x scripts/bed_impact.py --rings 2 --energy 2   # headless
Writes summary.json, events.jsonl, size_distribution.csv, plots and a VTK file into --out, and
checkpoint.yade.gz every --checkpoint-every seconds: `--resume 1` continues a run that died.
"""
import sys
from pathlib import Path

sys.path.insert(0, str(Path(sys.argv[0]).resolve().parent.parent))   # yade sets argv[0]

from yadebreak.scriptargs import script_params  # noqa: E402

args = script_params(dict(material="copper_ore", size=5.5e-3, rings=3, layers=1, energy=3.05,
                          speed=0.0, seed=1, time_step_fraction=0.05, dmin=0.0,
                          global_damping=0.0, dummies="ledger", read_period="fast", max_time=0.02,
                          checkpoint_every=60.0, resume=False, out="out/bed_impact"), __doc__)

from yadebreak import bed  # noqa: E402
from yadebreak.scriptargs import run_script  # noqa: E402

brk, result = run_script(bed.run, args)
