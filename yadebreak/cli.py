"""Command line: `yadebreak demo | families | materials | options | sweep | gather |
tradeoff | fit | grind | verify` (no YADE needed here but for verify, which runs YADE in its
process; the workers of a sweep or a trade-off run YADE).

Options are declared as the scripts' are (scriptargs: type, range, unit, default, help); a bad
value stops with one line naming the option, the value, the range and the unit (exit code 2)."""
from __future__ import annotations

import json
import sys
import time
from collections.abc import Callable
from contextlib import nullcontext
from pathlib import Path
from typing import NamedTuple

import numpy as np

from yadebreak.process.scheduler import FORMS
from yadebreak.model import families
from yadebreak.jobs.lifecycle import LOCK, save_figure, status, tool_run, write_atomic
from yadebreak import model
from yadebreak.model.materials import MaterialError, available_materials
from yadebreak.criteria import load_material
from yadebreak.options.flags import (COMMON, ScriptParser, add_params, fail, integer,
                                     join_negative_values, number, out_option, overwrite_option,
                                     QUIET, read_params, text)


def _plt():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


def demo(args):
    """Breakage probability and t10 curves of a material: Eqs. 1-4 and 8-10, plotted to PNG."""
    mat = load_material(args.material)
    steel = load_material("steel")
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    plt = _plt()
    fig, axes = plt.subplots(1, 3, figsize=(15, 4.5))
    energies = np.geomspace(1.0, 1e4, 300)
    for size_mm in (2.0, 5.5, 12.0, 37.5):
        p = mat.breakage_probability(energies, size_mm * 1e-3, partner=steel)
        axes[0].semilogx(energies, 100 * p, label=f"{size_mm:g} mm")
    axes[0].set(xlabel="specific impact energy Ek/mp on steel (J/kg)",
                ylabel="breakage probability (%)", title=f"{mat.name}: Eqs. 1-4")
    axes[0].legend()
    ratio = np.linspace(1.0, 60.0, 300)
    axes[1].plot(ratio, mat.t10(ratio))
    axes[1].axhline(mat.params.A, ls=":", c="k", label=f"A = {mat.params.A:g} %")
    axes[1].set(xlabel="Ek' / (mp E)", ylabel="t10' (%)", title="Eq. 8")
    axes[1].legend()
    x = np.geomspace(1e-3, 1.0, 300)
    for t in (mat.t10_min, 10.0, 20.0, 40.0):
        axes[2].semilogx(x, model.progeny_passing(t, mat.beta_params, x), label=f"t10 = {t:.3g} %")
    axes[2].set(xlabel="relative size x = d / d_parent", ylabel="cumulative passing (%)",
                title="Eq. 10 with Eqs. 11-12 below 1/75")
    axes[2].legend()
    fig.tight_layout()
    path = out / f"model_{mat.name}.png"
    save_figure(fig, path, dpi=110)
    e50 = float(mat.median_fracture_energy(5.5e-3))
    summary = {"material": mat.name, "E50_5.5mm_J_per_kg": e50,
               "energy_partition_on_steel": mat.energy_partition(steel),
               "t10_min_percent": mat.t10_min, "plot": str(path)}
    write_atomic(out / "summary.json", json.dumps(summary, indent=2))
    print(f"{mat.name}: E50(5.5 mm) = {e50:.1f} J/kg, e on steel = "
          f"{mat.energy_partition(steel):.3f}, t10' from {mat.t10_min:.2f} % to A = {mat.params.A:g} %")
    print(f"wrote {path}")


def plot_families(args):
    """Each family's cumulative distribution and the Eq. 10 target (the paper's Fig. 2)."""
    beta = model.TABLE1_BETA_PARAMS if args.material == "table1" else \
        load_material(args.material).beta_params
    fs = families.family_set(args.t10, beta, seed=args.seed)
    plt = _plt()
    fig, ax = plt.subplots(figsize=(7, 5))
    x = families.CLASS_SIZES
    for i, (frac, p) in enumerate(zip(fs.class_fractions, fs.probabilities)):
        ax.semilogx(x, families.boundary_passing(frac), "o-", ms=3, lw=0.8, alpha=0.7,
                    label=f"family {i + 1} ({100 * p:.0f} %)")
    ax.semilogx(x, families.boundary_passing(fs.mixture_fractions), "k--", lw=2,
                label="mixture (probability-weighted)")
    xs = np.geomspace(x[-1], 1.0, 200)
    ax.semilogx(xs, model.progeny_passing(args.t10, beta, xs), "r-", lw=2, label="Eq. 10")
    ax.set(xlabel="relative size x", ylabel="cumulative passing (%)",
           title=f"families for t10' = {args.t10:g} % ({args.material})")
    ax.legend(fontsize=7)
    fig.tight_layout()
    Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    save_figure(fig, args.out, dpi=110)
    print(f"{len(fs.probabilities)} families, volumes {fs.volumes.min():.4f}-{fs.volumes.max():.4f} "
          f"of the parent; t_n of the mixture "
          f"{np.round(fs.mixture_markers(), 2).tolist()} vs Eq. 10 "
          f"{np.round(model.t_markers(args.t10, beta)[:4], 2).tolist()}")
    print(f"wrote {args.out}")


def list_materials(_args):
    for name in available_materials():
        mat = load_material(name)
        print(f"{name:12s} {'breakable' if mat.breakable else 'non-breakable':14s} {mat.description}")


def print_options(_args):
    """The engine's options and the scripts' overrides as Markdown (docs/options.md)."""
    from yadebreak.jobs.options import options_page
    from yadebreak.studies import verify
    from yadebreak.studies.verify.settings import PAPER
    print(options_page({"verify": {**PAPER, **verify.OVERRIDES}}), end="")


def sweep(args):
    """Run a yade-batch table's lines as Dask tasks (yadebreak.studies.sweep)."""
    from yadebreak.studies import sweep as sw
    options = _key_values(args.jobqueue, "--jobqueue")
    try:
        lines = sw.run_sweep(args.table, args.script, args.out, scheduler=args.scheduler,
                             retries=args.retries, jobqueue_options=options, jobs=args.jobs,
                             say=lambda m: print(f"[yadebreak] {m}", flush=True), tell=status)
    except sw.SchedulerError as exc:          # a SweepError too
        fail(str(exc))
    except KeyboardInterrupt:
        raise SystemExit(130) from None
    return sw.main_exit_code(lines)


def gather(args):
    """sweep.csv from the runs of a table in --out (a yade-batch sweep's out/sweep, say)."""
    from yadebreak.studies import sweep as sw
    try:
        path = sw.gather(args.out, sw.read_table(args.table))
    except sw.SweepError as exc:
        fail(str(exc))
    print(f"[yadebreak] wrote {path}")


TRADEOFF_USAGE = """yadebreak tradeoff SCRIPT [script options] --vary NAME=V1,V2,...
    [--vary ...] --seeds N --metrics KEY,KEY,... --out DIR [--reference NAME=V,...]
    [--scheduler SPEC] [--retries N] [--quiet 0|1]

Runs SCRIPT over the grid of the varied options x seeds 1..N (the same seeds for every variant),
one Dask task per run (as `sweep`), reads each run's summary.json and writes DIR/tradeoff.csv,
tradeoff.md and pareto.png: per variant the wall time, the speed-up against the reference (the
--reference variant, or the slowest) and each metric's paired difference from it with a 95 %%
interval. NAME is the script's option without its dashes (--vary time-step-fraction=0.02,0.05);
KEY a dotted summary.json key (results.0.broken_fraction); options of the script not varied
follow SCRIPT and reach every run."""


def tradeoff_command(argv):
    """`yadebreak tradeoff`: its own parser, as the script's options pass through."""
    from yadebreak.studies import tradeoff as to
    from yadebreak.process.scheduler import SchedulerError
    parser = ScriptParser(prog="yadebreak tradeoff", usage=TRADEOFF_USAGE,
                          allow_abbrev=False)
    parser.add_argument("script", help="the YADE script (takes --seed, --out and the options)")
    parser.add_argument("--vary", action="append", default=[], help="NAME=V1,V2,... (repeatable)")
    parser.add_argument("--seeds", default="5", help="seeds 1..N per variant; default 5")
    parser.add_argument("--metrics", default="", help="dotted summary.json keys, comma-separated")
    parser.add_argument("--out", default="out/tradeoff", help="output folder; default "
                        "out/tradeoff")
    parser.add_argument("--reference", default="", help="NAME=V,... (default: the slowest)")
    parser.add_argument("--scheduler", default="local", help="as for sweep; default local")
    parser.add_argument("--retries", default="1", help="as for sweep; default 1")
    parser.add_argument(QUIET.flag, dest=QUIET.name, default="0", help=QUIET.help_line)
    args, script_args = parser.parse_known_args(argv)
    numbers = {}
    for name in ("seeds", "retries"):
        text_value = getattr(args, name)
        if not text_value.isdigit() or (name == "seeds" and int(text_value) < 1):
            fail(f"--{name} = {text_value}: must be an integer >= {1 if name == 'seeds' else 0}")
        numbers[name] = int(text_value)
    read_params(args, [out_option("out/tradeoff")])
    try:
        varied = to.parse_vary(args.vary)
        to.run(args.script, script_args, varied, numbers["seeds"],
               [m.strip() for m in args.metrics.split(",") if m.strip()], args.out,
               reference_text=args.reference, scheduler=args.scheduler,
               retries=numbers["retries"], say=lambda m: print(f"[yadebreak] {m}", flush=True),
               tell=status)
    except (to.TradeoffError, SchedulerError) as exc:
        fail(str(exc))
    except KeyboardInterrupt:
        raise SystemExit(130) from None
    return 0


def _key_values(text_value, option):
    """'cores=1,memory=2GB' as {cores: 1, memory: '2GB'} (numbers as numbers)."""
    out = {}
    for item in filter(None, text_value.split(",")):
        key, sep, value = item.partition("=")
        if not sep or not key:
            fail(f"{option} = {text_value!r}: accepted key=value pairs separated by commas")
        try:
            out[key] = json.loads(value)
        except json.JSONDecodeError:
            out[key] = value
    return out


def _grind(args):
    """`grind`: the mechanistic mill model (yadebreak.studies.grinding); its input errors as one line."""
    from yadebreak.studies.grinding import cli
    try:
        return cli.grind(args)
    except (cli.SpectraError, cli.FeedError, cli.GrindingError) as exc:
        if args.debug:
            raise
        fail(str(exc))


class Command(NamedTuple):
    """A command of `python3 -m yadebreak` made from the option table's parameters."""
    run: Callable           # run(args) -> exit code or None
    help: str
    params: list            # its options (options.flags parameters)
    positional: tuple = ()  # its positional arguments: (name, help)


COMMANDS = {
    "demo": Command(demo, "plot breakage probability and t10 curves of a material", [
        text("material", "copper_ore", "a material name or a .toml file"),
        out_option("out/demo"), overwrite_option()]),
    "families": Command(plot_families, "plot the family set of a t10' (paper Fig. 2)", [
        text("material", "table1", "a material name, or table1"),
        number("t10", 3.0, "%", "t10' of the family set", lo=0, lo_open=True, hi=100),
        integer("seed", 0, "seed of the family generation", lo=0),
        out_option("out/families.png", "the plot (PNG)")]),
    "materials": Command(list_materials, "list the material library", []),
    "options": Command(print_options, "the engine's options as Markdown (docs/options.md)", []),
    "sweep": Command(sweep, "run a yade-batch table's lines as Dask tasks, on this machine or a cluster", [
        out_option("out/sweep", "folder of the sweep: <out>/<description>/ per line, "
                   "sweep.json, sweep.csv"),
        text("scheduler", "local", FORMS),
        integer("retries", 1, "further attempts of a failing line in this call", lo=0),
        integer("jobs", 1, "slurm/pbs without :N: batch jobs to start (each one worker)", lo=1),
        text("jobqueue", "", "slurm/pbs: the cluster's options as key=value,... (e.g. "
             "queue=short,walltime=02:00:00,memory=4GB,cores=1)")],
        (("table", "the yade-batch table"), ("script", "the YADE script each line runs"))),
    "gather": Command(gather, "flatten every line's summary.json of a sweep into <out>/sweep.csv", [
        out_option("out/sweep", "the folder holding <description>/summary.json per line")],
        (("table", "the yade-batch table"),)),
    "grind": Command(_grind, "minutes of batch grinding from a mill's collision "
              "spectra (docs/grinding.md)", [
        text("material", "copper_ore", "a material name or a .toml file"),
        text("feed", "5.5", "a single feed size (plain numbers in mm; a length unit may follow: "
             "8mm, '0.008 m') or a CSV file size_mm,passing_percent", empty=False),
        number("minutes", 10.0, "min", "grinding time", lo=0, lo_open=True, hi=1e4),
        number("interval", 0.5, "min", "time between outputs", lo=0, lo_open=True),
        integer("classes", 16, "root-2 size classes below the feed's top size", lo=2, hi=60),
        integer("cells", 120, "fracture-energy cells per class", lo=20, hi=2000),
        integer("damage", 1, "1: survivors weakened by Eqs. 5-6; 0: no damage", lo=0, hi=1),
        number("holdup", 0.0, "kg", "ore in the mill (0: the spectra's ore mass)", lo=0),
        number("residence", 0.0, "min", "mean residence time of a continuous mill (0: batch)",
               lo=0),
        out_option("out/grind"), overwrite_option()],
        (("spectra", "a spectra file, a mill run's --out folder (converted) or "
          "synthetic:BALL_MM (docs/grinding.md)"),)),
}


def environment_error(exc, out, began):
    """A command's end on a folder it cannot write (read-only, no permission, a full disk or
    quota): one line naming the path and what was kept of `out`, exit code 1 (every file is
    written whole or not at all: write_atomic). Returns (the caller re-raises) for other errors."""
    import errno
    if not isinstance(exc, OSError) or exc.errno not in (
            errno.EROFS, errno.EACCES, errno.EPERM, errno.ENOSPC, errno.EDQUOT):
        return
    where = f" {exc.filename}" if exc.filename else ""
    verb = "access" if exc.errno in (errno.EACCES, errno.EPERM) else "write"   # may be a read
    print(f"[yadebreak] error: cannot {verb}{where}: {exc.strerror or exc}; {_kept(out, began)}",
          file=sys.stderr, flush=True)
    raise SystemExit(1) from None


def _kept(out, since):
    """The files of `out` written since `since` (time.time()), each whole, in a few words."""
    folder = Path(out) if out else None
    if folder is None or not folder.is_dir():
        return f"nothing was written in {out}" if out else "nothing was written"
    new = sorted(str(p.relative_to(folder)) for p in folder.rglob("*")
                 if p.is_file() and p.name != LOCK and p.stat().st_mtime >= since - 1.0)
    if not new:
        return f"nothing was written in {folder}"
    shown = ", ".join(new[:6]) + (f" and {len(new) - 6} more" if len(new) > 6 else "")
    return f"kept in {folder}: {shown}"


def _value_of(argv, option, default):
    """`option`'s value in `argv` (`--out DIR` or `--out=DIR`), or `default`."""
    for k, a in enumerate(argv):
        if a == option and k + 1 < len(argv):
            return argv[k + 1]
        if a.startswith(option + "="):
            return a.partition("=")[2]
    return default


def main(argv=None):
    argv = sys.argv[1:] if argv is None else list(argv)
    began = time.time()
    if argv[:1] in (["tradeoff"], ["verify"], ["fit"]):     # each has its own parser
        if argv[0] == "tradeoff":
            run, out = tradeoff_command, "out/tradeoff"
        elif argv[0] == "verify":          # runs YADE in this process: imported only here
            from yadebreak.studies.verify import main as run
            out = "out/verify"
        else:                              # DATA... takes several files
            from yadebreak.studies.calibration.cli import main as run
            out = None
        try:
            return run(argv[1:])
        except OSError as exc:
            if _value_of(argv, "--debug", "0") not in ("1", "true", "yes", "on"):
                environment_error(exc, _value_of(argv[1:], "--out", out), began)
            raise
    parser = ScriptParser(prog="yadebreak")
    sub = parser.add_subparsers(dest="command", required=True)
    sub.add_parser("tradeoff", help="speed against accuracy of a script's options, over seeds "
                   "(yadebreak tradeoff --help)")     # parsed by tradeoff_command
    sub.add_parser("fit", help="a material file from laboratory data, with 95 %% intervals "
                   "(yadebreak fit --help; docs/calibration.md)")
    sub.add_parser("verify", help="the paper's Section 4.1 figures at its settings, a report "
                   "with plots (yadebreak verify --help; --quick 1: under 3 minutes)")
    for name, command in COMMANDS.items():
        p = sub.add_parser(name, help=command.help, description=command.help)
        for arg, arg_help in command.positional:
            p.add_argument(arg, help=arg_help)
        add_params(p, command.params + COMMON)
        p.set_defaults(func=command.run, params=command.params + COMMON)
    every = [p for command in COMMANDS.values() for p in command.params]
    args = parser.parse_args(join_negative_values(argv, every))
    read_params(args, args.params)
    owns_out = any(p.name == "overwrite" for p in args.params)     # a run folder of its own
    try:
        with tool_run(args.out, args) if owns_out else nullcontext():
            return args.func(args) or 0
    except MaterialError as exc:
        if args.debug:
            raise
        fail(f"{exc.source}: " + "; ".join(exc.problems))
    except OSError as exc:
        if not args.debug:
            environment_error(exc, getattr(args, "out", None), began)
        raise
    return 0

