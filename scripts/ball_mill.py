"""A laboratory batch ball mill: steel balls and a breakable ore charge in a drum with lifters.

The drum (steel facets, lifter bars) turns about its axis at a fraction of its critical speed,
driven by YADE's RotationEngine; the charge settles with the drum still, then yadebreak tracks
the ore for --duration seconds of simulated time. Default: 108 steel balls of 25 mm and 1,099
limestone particles of 8 mm in a 250 x 100 mm drum with 8 lifters at 75 % of critical speed
(1,369 bodies with the drum), 1 s.

    yade -n scripts/ball_mill.py                          # run, then the YADE prompt
    yade -n -x scripts/ball_mill.py --duration 1 --speed 0.75 --material limestone
    yade -n -x scripts/ball_mill.py --drum-length 0.4     # four times the charge
Writes summary.json, size_distribution.csv, breakage_rate.csv, power.csv, mill.png (size
distribution against time, breakage rate of the feed size, mill power beside the torque-arm model
and Bond's equation), charge.png (the charge along the axis), events.jsonl and a ParaView series
into --out; checkpoint.yade.gz every --checkpoint-every seconds: `--resume 1` continues a run that
died. Mill DEM scales stiffness down to afford its time step (--stiffness-scale).
"""
import sys
from pathlib import Path

sys.path.insert(0, str(Path(sys.argv[0]).resolve().parent.parent))   # yade sets argv[0]

from yadebreak.jobs import options as job_options  # noqa: E402

args = job_options.read("ball_mill", __doc__)

from yadebreak.jobs import mill  # noqa: E402
from yadebreak.jobs.lifecycle import run_script  # noqa: E402

brk, summary = run_script(mill.run, args) or (None, None)   # None: resumed a finished run
