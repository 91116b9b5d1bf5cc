"""`yadebreak verify [--quick 1]`: the paper's Section 4.1 verification at the paper's
settings, as a Markdown report with one plot per figure (model lines and simulated points side by
side, each figure's settings printed under it).

The paper's settings (its Section 3; docs/verification.md), but for the outcome of a breakage
(Figs. 13-19 run outcome='model' with kappa='batch': single impacts on Eq. 7 and Eq. 10;
--outcome paper runs the paper's convention with its kappa 1): Emax/E50 = 4 in every
single-particle run; 5 % of the Rayleigh time (RT) for the probabilities, 2 % for the
fragmentation, 1 % in the cs and damping studies (its Figs. 18-19 captions); dmin = top size / 20, emin = 1e-4 J, kappa = 1, cs = 0;
global damping from each material file (0.3 copper ore, 0 otherwise); 5.5 mm particles for the
probabilities, 29 mm for the size distributions and t10.

Figures (--figures, comma-separated):
  probability  Fig. 8: broken fraction against energy, each material at 5.5 mm, single impacts
               on steel and drop-weight tests (steel striker and anvil), at the energies where
               the model gives 10-90 %, with binomial 3 sigma bands.
  targets      Fig. 9: copper ore at 5.5 mm on steel at two restitutions (the file's 0.39,
               0.8), on rubber and on a target as stiff as the ore (written to <out>/targets).
  sizes        Fig. 10: copper ore at 2.8, 5.5, 11 and 22 mm on steel.
  repeated     Fig. 11: 37.5 mm copper ore at 94.7 J/kg on steel, 10 impacts, gamma 2.5, 5
               (the file's) and 10; the broken leave the test.
               In Figs. 8-11 the particles are not replaced (replace=False): the probability is
               that of the first impact, which replacement cannot change, and the run is
               10-100x cheaper.
  progeny      Figs. 13-14: 29 mm copper ore, single impacts at --energies, the progeny as the
               spheres stand (no fines) and with the fines, against Eq. 10 at Eq. 7's t10.
  drop_weight  Fig. 15: the same in drop-weight tests (steel striker of 50 particle masses on
               a steel anvil), each particle its own scene.
  t10          Fig. 16: t10 against energy for each material at 29 mm (and copper ore at 5.5 mm),
               single impacts on steel (the paper's Fig. 16 is drop-weight; Fig. 15 runs it).
  time_step    Fig. 17: 29 mm copper ore at 300 and 3000 J/kg, 1-5 % of the Rayleigh time.
  cs           Fig. 18: the same with cs 0, 0.5, 1 (1 % RT, no damping; the paper's are drop
               weight).
  damping      Fig. 19: the same, single impacts with global damping 0 ... 0.3 (1 % RT).
               Figures share runs with the same settings (each runs once).
  energy       Where the energy of a cascade goes: each material at 29 mm, 150 and 1000
               J/kg where Eq. 7 is at most 20 % (--audit-energies), 1 particle each
               (quick: copper ore, 1000 J/kg, 1), the impact's
               kinetic energy split into where it ends, per breakage generation and in total
               (energy_audit.py; YADE's energy tracking on, in this process).

Each point of Figs. 13-19 pools the scenes of every seed (--seeds), its particles per seed sized
from the model's probability so that --broken particles break (fragmentation.particles_per_seed).

--quick 1: copper ore only, the first seed, few particles, 2-3 energies (Figs. 9-10: one level,
the 50 %; Fig. 11: 5 impacts, gamma 5 and 10; Figs. 13-19: 2 particles at 1000 J/kg, 2 % RT, 1
in Fig. 15) (tests/test_verify.py). The whole command: docs/verification.md.
Every run is a set of scenes (scenes.run_scenes of an impact_spec or, for the drop weight, a
drop_weight_spec; Fig. 11 and the energy audit: a Task's calls); the results are
model.reports.breakage_result_of dicts, written to <out>/results.json with their settings. With
--scheduler local:1 (--jobs 1) YADE runs in this process (the coupling makes it importable);
otherwise the scenes are Dask tasks of one scenes.SceneQueue kept for the whole command, every
figure's runs queued at the start, the costliest first.
"""
from __future__ import annotations

import time
from pathlib import Path

from yadebreak.model.materials import MaterialError
from yadebreak.criteria import load_material
from yadebreak.jobs.lifecycle import progress, tool_run
from yadebreak.options.engine_flags import Derived, Override, engine_flag, options_from_flags
from yadebreak.options.flags import (flag, integer, numbers, out_option, overwrite_option,
                                     scheduler_of, scheduler_options, text)
from yadebreak.studies.verify import energy_audit, fragmentation, probability
from yadebreak.studies.verify.report import write_report
from yadebreak.studies.verify.settings import (PAPER_MATERIALS, Runner,  # noqa: F401
                                               paper_material, plan, probability_energies)

#: figure name -> the function that runs it and returns its report entry, in report order
FIGURES = {"probability": probability.figure_probability,
           "targets": probability.figure_targets, "sizes": probability.figure_sizes,
           "repeated": probability.figure_repeated,
           "progeny": fragmentation.figure_progeny,
           "drop_weight": fragmentation.figure_drop_weight, "t10": fragmentation.figure_t10,
           "time_step": fragmentation.figure_time_step, "cs": fragmentation.figure_cs,
           "damping": fragmentation.figure_damping, "energy": energy_audit.figure_energy}

#: the figures run unless --figures says otherwise: all
DEFAULT_FIGURES = list(FIGURES)

#: attach() options the command exposes for the fragmentation figures (Figs. 13-19), beyond
#: the paper's settings (studies.verify.settings.PAPER)
FRAGMENTATION = ("read_period", "outcome", "kappa", "kappa_successive", "break_at",
                 "t10_energy", "dummy_stiffness", "contact_energy_at_break")
#: the command's defaults that differ from attach()'s
OVERRIDES = {
    "time_step_fraction": Override(
        Derived("the paper's per figure: 5 % (Figs. 8-11), 2 % (13-16), 1 % (17-19)", token=0.0),
        "the paper's Section 3 and the captions of its Figs. 18-19"),
    "outcome": Override("model", "with it and the batch kappa single impacts meet Eq. 7 and "
                                 "Eq. 10 at every point of Figs. 13-16 (docs/verification.md); "
                                 "'paper' runs the paper's convention"),
    "kappa": Override(Derived("'batch' with --outcome model, 1 (the paper's Section 3) with "
                              "--outcome paper",
                              lambda args: "batch" if args.outcome == "model" else 1.0,
                              token="outcome"),
                      "the paper defines kappa as what makes Eq. 8's mean over the broken "
                      "particles Eq. 7 (its Section 2.2) and ran kappa = 1")}


def fragmentation_options(args):
    """attach() options of the fragmentation figures from the command's flags."""
    return options_from_flags(args, FRAGMENTATION,
                              {k: o for k, o in OVERRIDES.items() if k in FRAGMENTATION})


PARAMS = [
    flag("quick", False, "the quick subset (copper ore, few particles, 2-3 energies; under 3 "
         "minutes)"),
    text("figures", ",".join(DEFAULT_FIGURES),
         "figures to run, comma-separated: " + ", ".join(FIGURES), empty=False),
    text("materials", ",".join(PAPER_MATERIALS), "materials of Figs. 8 and 16 (names or files)",
         empty=False),
    numbers("energies", "150,300,1000,3000", "J/kg",
            "specific energies Ek/mp of Figs. 13-16 (quick: 1000; Figs. 17-19: 300 and 3000)",
            lo=0, lo_open=True),
    numbers("dampings", "0,0.1,0.3", "-", "global damping values of Fig. 19 (each < 1)", lo=0),
    text("audit_energies", "target", "the energy audit's energies: 'target', 150 and 1000 J/kg "
         "where Eq. 7 is at most 20 % (the cases of docs/verification.md's target); or J/kg, "
         "comma-separated, every material at each", empty=False),
    integer("particles", 8, "the least particles per point and seed in Figs. 13-19 (quick: 2)",
            lo=1),
    integer("broken", 20, "Figs. 13-19: each point's particles per seed are sized from the "
            "model's breakage probability so that this many break over the seeds (expected, less "
            "two binomial standard deviations; at most 500 per seed; quick: not sized)", lo=1),
    integer("probability_particles", 250, "particles per point in Figs. 8-11 (the paper's "
            "250; quick: 40)", lo=1),
    text("seeds", "3,4,5", "seeds, comma-separated: Figs. 13-19 pool the scenes of each (scene "
         "k of seed s: scenes.scene_seed(s, k)); Figs. 8-11, the energy audit and --quick 1 "
         "take the first", empty=False),
    *(engine_flag(name, OVERRIDES, "Figs. 13-19: " if name in FRAGMENTATION else "")
      for name in ("time_step_fraction", *FRAGMENTATION)),
    *scheduler_options("scenes"),
    out_option("out/verify"),
    overwrite_option(),
]


def verify(args):
    """`python3 -m yadebreak verify`: the figures asked for, report.md, results.json, plots."""
    from yadebreak.options.flags import fail
    import sys
    began = time.time()
    out = Path(args.out)
    wanted = [f.strip() for f in args.figures.split(",") if f.strip()]
    unknown = [f for f in wanted if f not in FIGURES]
    if unknown or not wanted:
        fail(f"--figures = {args.figures!r}: " + (f"unknown {unknown}" if unknown else
             "names no figure") + f"; accepted {', '.join(FIGURES)}")
    args.material_list = (["copper_ore"] if args.quick else
                          [m.strip() for m in args.materials.split(",") if m.strip()])
    args.energy_list = [float(e) for e in args.energies.split(",")]
    args.damping_list = [float(d) for d in args.dampings.split(",")]
    bad = [d for d in args.damping_list if d >= 1.0]
    if bad:
        fail(f"--dampings = {args.dampings}: each global damping must be in [0, 1), got {bad}")
    if args.audit_energies != "target":
        try:
            bad = [e for e in args.audit_energies.split(",") if not float(e) > 0]
        except ValueError:
            bad = [args.audit_energies]
        if bad:
            fail(f"--audit-energies = {args.audit_energies}: accepted 'target' or specific "
                 "energies > 0 J/kg, comma-separated")
    scheduler = scheduler_of(args)
    if args.read_period not in ("every_step", "fast"):
        fail(f"--read-period = {args.read_period}: accepted every_step or fast")
    given = args.seeds
    try:
        args.seeds = tuple(int(v) for v in str(given).split(",") if v.strip())
    except ValueError:
        args.seeds = ()
    if not args.seeds or min(args.seeds) < 0 or len(set(args.seeds)) < len(args.seeds):
        fail(f"--seeds = {given}: accepted distinct integers >= 0, comma-separated")
    if args.quick:
        args.seeds = args.seeds[:1]
    args.seed = args.seeds[0]                 # Figs. 8-11 and the energy audit
    args.argv = getattr(args, "argv", None) or sys.argv[2:]
    for name in args.material_list:           # a bad name stops here, before any run
        try:
            load_material(name)
        except MaterialError as exc:
            if getattr(args, "debug", False):
                raise
            fail(f"--materials = {args.materials}: " + "; ".join(exc.problems))
    earlier = _earlier_walls(out / "results.json")
    with tool_run(out, args):
        runner = Runner(scheduler, args.retries)
        makers = [make for name, make in FIGURES.items() if name in wanted]
        try:
            runner.queue(plan(makers, args, out))     # every figure's runs, the costliest first
            predicted = runner.wall_time(f"an earlier run's scene wall times in "
                                         f"{out / 'results.json'}", earlier)
            if predicted is not None:
                progress(f"wall time, predicted: {predicted.line()}")
            figures = [make(args, runner, out) for make in makers]
        finally:
            runner.close()
        told = runner.wall_time("this run's scenes")
        write_report(out, figures, runner, args, time.time() - began, told)
    if told is not None:
        progress(f"wall time: {told.line()}")
    progress(f"wrote {out / 'report.md'} ({time.time() - began:.0f} s)")
    return 0


def _earlier_walls(path):
    """{run key: scene wall times} of an earlier verify's results.json (--overwrite 1), or {}."""
    import json
    try:
        return json.loads(Path(path).read_text())["scene_walls"]
    except (OSError, ValueError, KeyError, TypeError):
        return {}


def main(argv):
    """Parse `argv` (after `verify`) and run; bad values stop with one line (exit 2)."""
    from yadebreak.options.flags import COMMON, ScriptParser, add_params, read_params
    parser = ScriptParser(prog="yadebreak verify", description=__doc__.split("\n\n")[0])
    add_params(parser, PARAMS + COMMON)
    args = read_params(parser.parse_args(argv), PARAMS + COMMON)
    args.argv = list(argv)
    return verify(args)
