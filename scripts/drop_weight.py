"""Drop-weight tests (paper's DWT, Figs. 8 and 15): a steel striker falls on each particle resting
on a steel anvil; breakage probability, t10 and the progeny size distribution against the model.

    yade -n -x scripts/drop_weight.py --material copper_ore --energies 150,600

An interrupted run continues with --resume 1, keeping the energies it finished (out/partial.json);
a run that fails leaves summary.json with the energies it finished and its end_reason.
"""
import sys
from pathlib import Path

sys.path.insert(0, str(Path(sys.argv[0]).resolve().parent.parent))   # yade sets argv[0]

from yadebreak.jobs import options as job_options  # noqa: E402

args = job_options.read("drop_weight", __doc__)

from yadebreak.jobs import impacts  # noqa: E402
from yadebreak.jobs.lifecycle import run_script  # noqa: E402

brk = run_script(impacts.drop_weight, args)   # the last controller, at the prompt without -x
