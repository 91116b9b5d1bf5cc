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

from yadebreak.tools.options import (checkpointed_run_options, integer,  # noqa: E402
                                  material_option, number, read_period_option,
                                  script_params, size_option, time_step_option)

args = script_params([
    material_option("the ore", "limestone"),     # the softest ore of the library: breaks in 1 s
    size_option(8e-3),
    number("ball_size", 25e-3, "m", "diameter of the steel balls", lo=0, lo_open=True, hi=0.5),
    number("drum_diameter", 0.25, "m", "inside diameter of the drum (to the shell)", lo=0,
           lo_open=True, hi=10),
    number("drum_length", 0.1, "m", "length of the drum (the charge scales with it)", lo=0,
           lo_open=True, hi=10),
    integer("lifters", 8, "lifter bars along the shell", lo=0, hi=64),
    number("lifter_height", 10e-3, "m", "height of a lifter bar", lo=0),
    number("lifter_width", 10e-3, "m", "width of a lifter bar", lo=0, lo_open=True),
    number("speed", 0.75, "-", "rotation speed as a fraction of the critical speed", lo=0,
           hi=1, lo_open=True, hi_open=True),
    number("ball_filling", 0.3, "-", "bulk volume of the balls over the drum's volume", lo=0,
           hi=0.5, lo_open=True),
    number("ore_filling", 0.1, "-", "bulk volume of the ore over the drum's volume", lo=0,
           hi=0.5, lo_open=True),
    number("duration", 1.0, "s", "simulated time the drum turns", lo=0, lo_open=True),
    number("stiffness_scale", 1e-3, "-", "factor on every Young's modulus (mill DEM's usual "
           "reduction, for a longer time step)", lo=0, hi=1, lo_open=True),
    time_step_option(),
    number("dmin", 0.0, "m", "smallest resolved fragment; finer progeny goes to the ledger "
           "(0: --size / 3)", lo=0),
    read_period_option("fast"),
    integer("seed", 1, "random seed", lo=0),
    number("sample_interval", 0.02, "s", "simulated time between samples of the size "
           "distribution and the charge", lo=0, lo_open=True),
    *checkpointed_run_options(0.05, "out/ball_mill"),
], __doc__)

from yadebreak.runs import mill  # noqa: E402
from yadebreak.tools.options import run_script  # noqa: E402

brk, summary = run_script(mill.run, args) or (None, None)   # None: resumed a finished run
