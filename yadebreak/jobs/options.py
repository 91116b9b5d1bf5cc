"""The options of every job behind scripts/, each declared once, with the checks between options
that one range cannot say. Pure (imports no yade): the tests read a script's options in-process.

    args = job_options.read("bed_impact", __doc__)        # sys.argv, or a yade-batch row
    options = job_options.attach_options("bed_impact", args, event_log=...)   # for attach()

A job declares its own options (the scene's, the run's) and the attach() options it exposes as
flags by name: those are made from the option table (yadebreak.options.table) with the table's
default, unless the job overrides it in its `overrides`, with the reason.

A bad value stops with one line naming the option, the value, the accepted range and the unit
(exit code 2), before anything is built or written.
"""
import math
from dataclasses import dataclass, field
from typing import Callable

from yadebreak.model.intervals import BALL_MASS, elastic_wave_speed
from yadebreak.model.milling import charge_counts
from yadebreak.options.engine_flags import (OPTION, Derived, Override, engine_flag,
                                            overrides_markdown)
from yadebreak.options.engine_flags import options_from_flags
from yadebreak.options.table import options_markdown
from yadebreak.options.flags import (checkpointed_run_options, choice, fail, flag, integer,
                                     material_option, number, numbers, out_option,
                                     overwrite_option, scheduler_of, scheduler_options,
                                     script_params, size_option, text)


@dataclass(frozen=True)
class JobOptions:
    """A job's options: its own (`own`, then `run`: the output folder, checkpoints, ...), the
    attach() options it exposes as flags (`engine`, names of the option table), its defaults
    that differ from the table's (`overrides`, exposed or fixed, each with its reason) and the
    checks between options (`check`, of the parsed args). `materials`: its options that name a
    material (of the library, or a .toml file), loaded once by read() into args.materials."""

    own: Callable
    engine: tuple = ()
    overrides: dict = field(default_factory=dict)
    run: Callable = list
    check: Callable | None = None
    materials: tuple = ()

    def params(self):
        return [*self.own(), *(engine_flag(n, self.overrides) for n in self.engine), *self.run()]

    def engine_options(self, args, **more):
        """attach()'s options from the parsed `args`, then `more` (the run's own)."""
        return options_from_flags(args, self.engine, self.overrides, **more)


# -- blocks that several jobs share (besides flags' material, size, out, ...) ------------------
#: the laboratory tests read every contact every step
EXACT_READS = {"read_period": Override(
    "every_step", "a laboratory test is the reference the paper's figures are checked against: "
                  "every contact read every step, exact")}


def laboratory_test(size, middle, out, resume_help, what, engine=(), overrides=None, check=None,
                    materials=("material",)):
    """A laboratory test (single, repeated, drop-weight impacts): the material and size, the
    job's own `middle` options, the time step and the read period (every step: EXACT_READS)
    with its `engine` options, the output folder, --resume and --stop-after counted in `what`
    (energies or impacts)."""
    return JobOptions(
        own=lambda: [material_option(), size_option(size), *middle],
        engine=(*engine, "time_step_fraction", "read_period", "outcome", "kappa"),
        overrides={**EXACT_READS, **(overrides or {})},
        run=lambda: [
            out_option(out),
            flag("resume", False, resume_help),
            overwrite_option(),
            integer("stop_after", 0, f"(tests) end as if killed after this many {what} (0: "
                    "never)", lo=0, unit=what)],
        check=check, materials=materials)


_KEEPING_ENERGIES = "continue the run in --out, keeping the energies it finished"


def _target_option():
    return text("target", "steel", "the plate: steel, rubber or a material")


def _seed_per_energy():
    return integer("seed", 1, "random seed of the first energy (the next ones: +1, +2, ...)", lo=0)


# -- each job's options ----------------------------------------------------------------------------
def _bed_own():
    return [
        material_option("the bed"),
        size_option(5.5e-3),
        integer("rings", 3, "hexagonal rings around the central particle", lo=0),
        integer("layers", 1, "layers of particles (more than one: held by a holder until the "
                "touch)", lo=1),
        choice("packing", "auto", ("auto", "poured", "lattice"), "how the bed is built: poured "
               "into the holder and settled, or hexagonal layers stacked (auto: poured for "
               "several layers, a lattice for one)"),
        flag("rolling_friction", True, "apply the material files' rolling friction per contact "
             "pair (0: none)"),
        number("steel_rolling_friction", -1.0, "-", "the particle-steel rolling friction instead "
               "of the material file's (-1: the file's; the paper's Fig. 22 tried 0.33)", lo=-1,
               hi=10),
        text("bed_cache", "", "folder of settled poured beds ('': ~/.cache/yadebreak/beds or "
             "$YADEBREAK_CACHE; off: settle every time)"),
        number("energy", 3.05, "J", "impact energy of the ball (not per kg)", lo=0, lo_open=True),
        number("speed", 0.0, "m/s", "the ball's speed instead of --energy (0: from --energy)",
               lo=0),
        integer("seed", 1, "random seed", lo=0),
        number("stiffness_scale", 1.0, "-", "factor on every Young's modulus of the scene (a "
               "speed knob; the paper's is 1)", lo=0, hi=1, lo_open=True),
        number("max_time", 0.1, "s", "simulated time at which the run stops at the latest", lo=0,
               lo_open=True),
    ]


LEDGER = Override("ledger", "the fines as a mass ledger: the broken mass within the noise of "
                            "dummy spheres' and the run several times faster "
                            "(docs/speed_accuracy.md)")

BED_IMPACT = JobOptions(
    own=_bed_own,
    engine=("time_step_fraction", "dmin", "global_damping", "global_damping_time", "dummies",
            "dummy_stiffness", "read_period", "outcome", "break_at"),
    overrides={"dummies": LEDGER},
    run=lambda: checkpointed_run_options(1e-4, "out/bed_impact"),
    check=lambda args: _check_bed_impact(args), materials=("material",))


def check_impact_speed(option, value, speed, material, unit):
    """Refuse an impact at or above the elastic wave speed of the particles' material (a
    Material), where Hertz contact means nothing: one line naming the option and its largest
    accepted value (in `unit`, the option's; the value's speed in m/s)."""
    limit, name = elastic_wave_speed(material.young_modulus, material.density), material.name
    if speed < limit:
        return
    bound = {"m/s": limit, "J/kg": 0.5 * limit ** 2, "J": 0.5 * BALL_MASS * limit ** 2}[unit]
    value = f"{value:g}" if isinstance(value, float) else value
    fail(f"{option} = {value}: must be < {bound:.4g} ({unit}): it means {speed:.4g} m/s, not below "
         f"the elastic wave speed sqrt(E/rho) of {name}, {limit:.4g} m/s, where Hertz contact "
         "means nothing")


def _check_specific_energies(args, option):
    """The particles' speed sqrt(2e) at each specific energy of `option` (J/kg) against their
    material's wave speed."""
    value = getattr(args, option)
    energies = [float(e) for e in str(value).split(",")]
    e = max(energies)
    check_impact_speed("--" + option.replace("_", "-"), value, math.sqrt(2.0 * e),
                       material_of(args), "J/kg")


#: the largest bed a script builds (particles): the scale of a process-scale scene; each takes
#: about 13 kB at build (measured: 21 MB for 1,639 particles, 75 MB for 6,289), fragments more
MOST_BED_PARTICLES = 100_000
BED_BYTES_PER_PARTICLE = 13e3
#: the largest mill charge a script builds (balls and ore particles), at the bed's memory a body
MOST_MILL_BODIES = 100_000


def _check_bed_size(args):
    """Refuse a bed past MOST_BED_PARTICLES in one line, with its count and memory."""
    per_layer = 1 + 3 * args.rings * (args.rings + 1)
    count = args.layers * per_layer
    if count <= MOST_BED_PARTICLES:
        return
    rings = int((math.sqrt(9 + 12 * (MOST_BED_PARTICLES / args.layers - 1)) - 3) / 6)
    fail(f"--rings = {args.rings} with --layers = {args.layers}: {count:,} particles (about "
         f"{count * BED_BYTES_PER_PARTICLE / 1e9:.3g} GB at build, "
         f"{BED_BYTES_PER_PARTICLE / 1e3:g} kB each); accepted at most "
         f"{MOST_BED_PARTICLES:,} particles (--rings <= {rings} with {args.layers} layer(s))")


def _check_bed_impact(args):
    _check_bed_size(args)
    if args.speed > 0:
        check_impact_speed("--speed", args.speed, args.speed, material_of(args), "m/s")
    else:
        check_impact_speed("--energy", args.energy, math.sqrt(2.0 * args.energy / BALL_MASS),
                           material_of(args), "J")
    if args.dummy_stiffness != 1.0 and args.dummies != "spheres":
        fail(f"--dummy-stiffness = {args.dummy_stiffness:g}: needs --dummies spheres (the "
             "ledger keeps no dummy spheres)")
    if args.packing == "poured" and args.layers < 2:
        fail(f"--packing = poured: must be with --layers >= 2 (got {args.layers}); a monolayer "
             "is laid as a lattice")


def _ball_mill_own():
    return [
        material_option("the ore", "limestone"),  # the softest ore of the library: breaks in 1 s
        size_option(8e-3),
        number("ball_size", 25e-3, "m", "diameter of the steel balls", lo=0, lo_open=True,
               hi=0.5),
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
        integer("seed", 1, "random seed", lo=0),
        number("sample_interval", 0.02, "s", "simulated time between samples of the size "
               "distribution and the charge", lo=0, lo_open=True),
    ]


BALL_MILL = JobOptions(
    own=_ball_mill_own,
    engine=("time_step_fraction", "dmin", "read_period", "outcome", "break_at", "breakage"),
    overrides={
        "dummies": Override("ledger", "thousands of breakages: dummy spheres would multiply the "
                                      "bodies and shrink the time step"),
        "dmin": Override(Derived("--size / 3", lambda args: args.size / 3.0),
                         "fragments resolved down to a third of the feed, finer progeny to the "
                         "ledger: the bodies and the time step of a mill stay bounded")},
    run=lambda: checkpointed_run_options(0.05, "out/ball_mill"),
    check=lambda args: _check_ball_mill(args), materials=("material",))


def check_mill_geometry(args):
    """The mill's cross-checks of its options that one range cannot say: the first that fails, as
    its one line (the option, its value, the bound and the unit), or None if they hold."""
    radius = 0.5 * args.drum_diameter
    if args.ball_size >= radius:
        return f"--ball-size = {args.ball_size:g}: must be < the drum's radius {radius:g} (m)"
    if args.lifter_height >= 0.5 * radius:
        return (f"--lifter-height = {args.lifter_height:g}: must be < half the drum's radius, "
                f"{0.5 * radius:g} (m)")
    if args.size >= args.ball_size * 2:
        return f"--size = {args.size:g}: must be < twice --ball-size, {2 * args.ball_size:g} (m)"
    return None


def _check_ball_mill(args):
    problem = check_mill_geometry(args)
    if problem:
        fail(problem)
    balls, ore = charge_counts(args)
    if balls + ore > MOST_MILL_BODIES:
        fail(f"--drum-diameter = {args.drum_diameter:g} m, --drum-length = {args.drum_length:g} m, "
             f"--size = {args.size:g} m, --ball-size = {args.ball_size:g} m: a charge of "
             f"{balls:,} balls and {ore:,} ore particles (about "
             f"{(balls + ore) * BED_BYTES_PER_PARTICLE / 1e9:.3g} GB at build); accepted at most "
             f"{MOST_MILL_BODIES:,} bodies (a smaller drum, coarser ore or balls, lower "
             "fillings)")


def _agglomerate_own():
    return [
        text("material", "glass_epoxy", "the spheres and binder: a bonded-agglomerate material "
             "name of the library or a .toml file"),
        integer("particles", 4104, "primary spheres (the document's 4,104; fewer: a smaller "
                "agglomerate of the same sizes and packing density)", lo=2, hi=200000),
        number("speed", 4.0, "m/s", "impact speed, normal to the plane", lo=0, lo_open=True,
               hi=100),
        number("duration", 1e-3, "s", "simulated time after the first touch", lo=0,
               lo_open=True, hi=1.0),
        number("radius_multiplier", 0.0, "-", "bond radius over the smaller sphere's, lambda "
               "(0: the material file's)", lo=0, hi=1),
        # the bonded scene's own rule (not attach()'s option of the same name)
        number("time_step_fraction", 0.2, "-", "time step as a fraction of the shorter of the "
               "bonds' time scale and the smallest sphere's Rayleigh time", lo=0, lo_open=True,
               hi=1),
        integer("check_period", 1, "steps between two evaluations of the failure criterion over "
                "the intact bonds (1: every step, exact)", lo=1, hi=100000),
        number("sample_interval", 5e-6, "s", "simulated time between rows of timeseries.csv",
               lo=0, lo_open=True),
        integer("seed", 1, "random seed (packing and bond strengths)", lo=0),
    ]


AGGLOMERATE_IMPACT = JobOptions(own=_agglomerate_own,
                                run=lambda: checkpointed_run_options(5e-5,
                                                                     "out/agglomerate_impact"))


SINGLE_IMPACT = laboratory_test(5.5e-3, [
    integer("particles", 250, "particles fired at each energy", lo=1),
    integer("scene_particles", 1, "particles per scene: independent scenes of at most this "
            "many, each at the time step of its own finest fragment and ending with its own "
            "cascade", lo=1),
    *scheduler_options("scenes"),
    _seed_per_energy(),
    _target_option(),
    numbers("energies", "100,200,400", "J/kg", "specific impact energies Ek/mp = v^2/2",
            lo=0, lo_open=True),
    choice("shape", "sphere", ("sphere", "polyhedra"), "particle shape: spheres, or random "
           "convex polyhedra of sieve size --size on YADE's volumetric law, broken into their "
           "cells (docs/polyhedra.md)"),
    number("vtk_interval", 0.0, "s", "simulated time between ParaView frames of the first "
           "scene of each energy, in <out>/paraview_<energy> (0: none; with --jobs 1)", lo=0),
], "out/single_impact", _KEEPING_ENERGIES, "energies", engine=("replace",),
    check=lambda args: (_check_specific_energies(args, "energies"), scheduler_of(args)),
    materials=("material", "target"))

REPEATED_IMPACT = laboratory_test(37.5e-3, [
    integer("particles", 100, "particles", lo=1),
    integer("impacts", 20, "impacts of each particle", lo=1),
    number("energy", 94.7, "J/kg", "specific impact energy Ek/mp = v^2/2 of every impact",
           lo=0, lo_open=True),
    number("gamma", 0.0, "-", "damage exponent of Eq. 5, replacing the material's (0: the "
           "material's)", lo=0),
    integer("seed", 1, "random seed", lo=0),
    _target_option(),
], "out/repeated_impact", "continue the run in --out from the checkpoint after its last "
   "impact", "impacts",
    overrides={"replace": Override(False, "the broken leave the test (the paper's Fig. 11): "
                                          "their fragments are not followed")},
    check=lambda args: _check_specific_energies(args, "energy"),
    materials=("material", "target"))

DROP_WEIGHT = laboratory_test(5.5e-3, [
    integer("particles", 60, "particles tested at each energy", lo=1),
    _seed_per_energy(),
    numbers("energies", "150,600", "J/kg", "specific energies of the striker's fall per "
            "particle mass", lo=0, lo_open=True),
    number("striker_mass_ratio", 50.0, "-", "striker mass over particle mass", lo=0,
           lo_open=True),
    number("max_time", 0.003, "s", "simulated time per energy at the most", lo=0,
           lo_open=True),
], "out/drop_weight", _KEEPING_ENERGIES, "energies",
    check=lambda args: _check_specific_energies(args, "energies"))

EXTREMES = JobOptions(own=lambda: [
    out_option("out/extremes"),
    overwrite_option(),
    flag("fast", False, "the test suite's particle counts"),
    text("only", "", "run the cases whose name contains this text ('': all cases)"),
])


#: script name -> its options (JobOptions)
JOBS = {
    "bed_impact": BED_IMPACT,
    "ball_mill": BALL_MILL,
    "agglomerate_impact": AGGLOMERATE_IMPACT,
    "single_impact": SINGLE_IMPACT,
    "repeated_impact": REPEATED_IMPACT,
    "drop_weight": DROP_WEIGHT,
    "extremes": EXTREMES,
}


def attach_options(job, args, **more):
    """attach()'s options of `job` (a key of JOBS) from its parsed `args`, then `more` (the
    run's own: event_log, ...): the one translation from flags to engine options."""
    return JOBS[job].engine_options(args, **more)


#: script options added since a checkpoint could have been written, at the value that gives the
#: behaviour of the scripts before them: a checkpoint without them resumes at that value
ADDED_OPTIONS = {"break_at": "outcome", "outcome": "paper", "dummy_stiffness": 1.0,
                 "shape": "sphere", "vtk_interval": 0.0}


def arguments_of_today(saved, now):
    """A checkpoint's saved arguments as today's flags write them, for comparison with the
    arguments `now` (an option added since, at the value that was the behaviour then, is no
    difference). Before --global-damping-time, the bed's --global-damping 0 meant the material
    file's damping and a value g > 0 meant g for 5e-4 s: they are --global-damping material
    (forever) and g with --global-damping-time 5e-4. Before --outcome, --break-at threshold was
    what --break-at outcome is now."""
    if "outcome" not in saved and saved.get("break_at") == "threshold":
        saved = {**saved, "break_at": "outcome"}      # the paper's outcome's, as written now
    saved = {**{k: v for k, v in ADDED_OPTIONS.items() if k in now}, **saved}
    if "global_damping" in saved and "global_damping_time" in set(now) - set(saved):
        damping = saved["global_damping"]
        saved = {**saved, **({"global_damping": OPTION["global_damping"].token,
                              "global_damping_time": OPTION["global_damping_time"].token}
                             if damping == 0 else {"global_damping_time": 5e-4})}
    return saved


OPTIONS_PAGE = """# Options of `yadebreak.attach()`

`attach(materials, seed=0, label="yadebreak", **options)` checks every option against this table
before anything changes in the scene: a bad value raises `AttachError` naming the option, the
value, the accepted range and the unit. The scripts' flags of these options (`--read-period` for
`read_period`) are made from the same table, with the same defaults but for the overrides listed
below; on a command line None is written as the word or number the flag's `--help` names
(`--global-damping material`, `--dmin 0`). Written by `yadebreak options` from
`yadebreak/options/table.py`, `yadebreak/jobs/options.py` and the verify command's settings
(`yadebreak/studies/verify`); a test keeps this page the same as its sources.

{table}

## The scripts' own defaults

{overrides}
"""


def options_page(more=None):
    """docs/options.md: the option table, then every job's overrides with their reasons (and
    `more`: {command: {option: Override}}, the commands' beyond the scripts)."""
    jobs = {job: declared.overrides for job, declared in JOBS.items() if declared.overrides}
    return OPTIONS_PAGE.format(table=options_markdown(),
                               overrides=overrides_markdown({**jobs, **(more or {})}))


def read(job, description=None, argv=None):
    """The checked options of `job` (a script's name, a key of JOBS) from `argv` (default
    sys.argv[1:]) or a yade-batch table row: an argparse.Namespace. A bad value ends the program
    with its one line (exit code 2)."""
    declared = JOBS[job]
    args = script_params(declared.params(), description, argv, table_row=_table_row)
    for option in declared.materials:
        material_of(args, option)
    if declared.check is not None:
        declared.check(args)
    return args


def material_of(args, option="material"):
    """The Material that the material option `option` of a job's `args` names, loaded once, at
    the job's edge (read(), or a job run from code), and kept in args.materials: the job and
    its scenes take this object. A material that does not load, or a --material that does not
    break, ends the program with one line (exit code 2) before anything is written."""
    from yadebreak.criteria import load_material
    from yadebreak.model.materials import MaterialError, available_materials
    if not hasattr(args, "materials"):
        args.materials = {}
    if option not in args.materials:
        value, flag = getattr(args, option), "--" + option.replace("_", "-")
        try:
            mat = load_material(value)
        except MaterialError as exc:
            where = "" if exc.source == str(value) else f"{exc.source}: "
            fail(f"{flag} = {value}: {where}" + "; ".join(exc.problems))
        if option == "material" and not mat.breakable:
            breakable = [n for n in available_materials() if load_material(n).breakable]
            fail(f"{flag} = {value}: not breakable (breakable = false in {mat.source}): accepted "
                 f"a breakable material, e.g. {', '.join(breakable)}, or a .toml file")
        args.materials[option] = mat
    return args.materials[option]


def _table_row(defaults):
    """A yade-batch row's values (yade-batch runs the script inside YADE)."""
    from yadebreak.scenes.view import batch_row
    return batch_row(defaults)
