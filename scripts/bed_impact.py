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

from yadebreak.tools.options import (checkpointed_run_options, choice, fail,  # noqa: E402
                                  flag, integer, material_option, number, read_period_option,
                                  script_params, size_option, text, time_step_option)

args = script_params([
    material_option("the bed"),
    size_option(5.5e-3),
    integer("rings", 3, "hexagonal rings around the central particle", lo=0),
    integer("layers", 1, "layers of particles (more than one: held by a holder until the touch)",
            lo=1),
    choice("packing", "auto", ("auto", "poured", "lattice"), "how the bed is built: poured "
           "into the holder and settled, or hexagonal layers stacked (auto: poured for several "
           "layers, a lattice for one)"),
    flag("rolling_friction", True, "apply the material files' rolling friction per contact "
         "pair (0: none)"),
    number("steel_rolling_friction", -1.0, "-", "the particle-steel rolling friction instead of "
           "the material file's (-1: the file's; the paper's Fig. 22 tried 0.33)", lo=-1, hi=10),
    text("bed_cache", "", "folder of settled poured beds ('': ~/.cache/yadebreak/beds or "
         "$YADEBREAK_CACHE; off: settle every time)"),
    number("energy", 3.05, "J", "impact energy of the ball (not per kg)", lo=0, lo_open=True),
    number("speed", 0.0, "m/s", "the ball's speed instead of --energy (0: from --energy)", lo=0),
    integer("seed", 1, "random seed", lo=0),
    time_step_option(),
    number("dmin", 0.0, "m", "fragments whose progeny would be finer never break "
           "(0: particle size / 20)", lo=0),
    number("stiffness_scale", 1.0, "-", "factor on every Young's modulus (a speed knob; the "
           "paper's is 1)", lo=0, hi=1, lo_open=True),
    number("global_damping", 0.0, "-", "Newton damping of fresh fragments (0: none)", lo=0, hi=1,
           hi_open=True),
    choice("dummies", "ledger", ("ledger", "spheres"), "the unresolved fines: a mass ledger, or "
           "dummy spheres (the paper)"),
    read_period_option("fast"),
    number("max_time", 0.1, "s", "simulated time at which the run stops at the latest", lo=0,
           lo_open=True),
    *checkpointed_run_options(1e-4, "out/bed_impact"),
], __doc__)

if args.packing == "poured" and args.layers < 2:
    fail(f"--packing = poured: must be with --layers >= 2 (got {args.layers}); a monolayer is "
         "laid as a lattice")

from yadebreak.runs import bed  # noqa: E402
from yadebreak.tools.options import run_script  # noqa: E402

brk, result = run_script(bed.run, args) or (None, None)   # None: resumed a finished run
