"""The stability matrix: every input at its extremes, and what each run must satisfy.

For each case: no NaN or infinity in any body or event; mass (spheres plus ledger) conserved to
1e-9; no fragment leaving faster than its parent's rigid velocity field (|v| + 2 |w| r); no kinetic
energy created (no gravity: the contact law only stores and dissipates); and the run ending (no
collision left). Prints a table and writes extremes.md, extremes.csv and extremes.json into --out.
Exit status 1 if any case fails. tests/test_extremes.py runs a fast subset of the same cases.

    /usr/bin/python3 scripts/extremes.py [--fast] [--only "sigma"]
"""
import sys
from pathlib import Path

sys.path.insert(0, str(Path(sys.argv[0]).resolve().parent.parent))   # yade sets argv[0]

from yadebreak.jobs import options as job_options  # noqa: E402

args = job_options.read("extremes", __doc__)

from yadebreak.jobs import extremes  # noqa: E402
from yadebreak.jobs.lifecycle import run_script  # noqa: E402

sys.exit(run_script(extremes.run, args))
