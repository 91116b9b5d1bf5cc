"""Repeated impacts at one specific energy: the fraction broken after each impact (paper Fig. 11).

Particles hit a steel plate again and again; the survivors carry their damage (Eqs. 5-6, or the
Ab-T10 e_cum of Eq. 9.2) into the next impact. Default: 37.5 mm copper ore at 94.7 J/kg,
20 impacts, 100 particles.

    yade -n -x scripts/repeated_impact.py --gamma 3
    yade -n -x scripts/repeated_impact.py --material ab_t10_ore --size 5.5e-3 --energy 180 --impacts 8

The scene is checkpointed after every impact (out/checkpoint.yade.gz); an interrupted run continues
with --resume 1 exactly as if it had not stopped.
"""
import sys
from pathlib import Path

sys.path.insert(0, str(Path(sys.argv[0]).resolve().parent.parent))   # yade sets argv[0]

from yadebreak.jobs import options as job_options  # noqa: E402

args = job_options.read("repeated_impact", __doc__)

from yadebreak.jobs import impacts  # noqa: E402
from yadebreak.jobs.lifecycle import run_script  # noqa: E402

brk = run_script(impacts.repeated, args)    # the controller, at the prompt without -x
