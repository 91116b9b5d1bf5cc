"""`python3 -m yadebreak verify [--quick 1]`: the paper's Section 4.1 verification at the paper's
settings, as a Markdown report with one plot per figure (model lines and simulated points side by
side, each figure's settings printed under it).

The paper's settings (its Section 3; docs/high_energy.md): Emax/E50 = 4 in every single-particle
run; 5 % of the Rayleigh time (RT) for the probabilities, 2 % for the fragmentation, 1 % in the
damping study (its Fig. 19 caption); dmin = top size / 20, emin = 1e-4 J, kappa = 1, cs = 0;
global damping from each material file (0.3 copper ore, 0 otherwise); 5.5 mm particles for the
probabilities, 29 mm for the size distributions and t10.

Figures (--figures, comma-separated):
  probability  Figs. 8-10: broken fraction against energy, each material at 5.5 mm on steel,
               at the energies where the model gives 10-90 %, with binomial 3 sigma bands.
               The particles are not replaced (replace=False): the probability is that of the
               first impact, which replacement cannot change, and the run is 10-100x cheaper.
  t10          Fig. 16: t10 against energy for each material at 29 mm (and copper ore at 5.5 mm),
               single impacts on steel (the paper's Fig. 16 is drop-weight; see the report).
  damping      Fig. 19: copper ore at 29 mm, t10 and progeny with global damping 0 ... 0.3.

--quick 1: copper ore only, few particles, 2-3 energies (tests/test_verify.py; under 3 minutes).
Every run is a scenes.single_impacts call; the results are model.reports.breakage_result_of
dicts, written to <out>/results.json with their settings. YADE runs in this process (the
coupling makes it importable); --jobs > 1 shares each run's scenes among YADE processes.
"""
from __future__ import annotations

import dataclasses
import json
import time
from pathlib import Path

import numpy as np

from yadebreak.model.materials import load_material
from yadebreak.model import reports
from yadebreak.tools.options import integer, number, numbers, progress, text

#: the paper's single-particle verification (its Section 3)
EMAX_RATIO = 4.0
PROBABILITY_SIZE = 5.5e-3
FRAGMENT_SIZE = 29e-3
RT_PROBABILITY, RT_FRAGMENTATION, RT_DAMPING = 0.05, 0.02, 0.01
PAPER_MATERIALS = ("copper_ore", "granulite", "limestone")
#: the model probabilities at which Figs. 8-10 are sampled
PROBABILITY_LEVELS = (0.1, 0.3, 0.5, 0.7, 0.9)
QUICK_LEVELS = (0.2, 0.5, 0.8)
FIGURES = ("probability", "t10", "damping")

PARAMS = [
    integer("quick", 0, "1: the quick subset (copper ore, few particles, 2-3 energies; under 3 "
            "minutes)", lo=0, hi=1),
    text("figures", ",".join(FIGURES), "figures to run, comma-separated: " + ", ".join(FIGURES)),
    text("materials", ",".join(PAPER_MATERIALS), "materials of Figs. 8 and 16 (names or files)"),
    numbers("energies", "150,300,1000,3000", "J/kg",
            "specific energies Ek/mp of Figs. 16 and 19 (quick: 1000)", lo=0, lo_open=True),
    numbers("dampings", "0,0.1,0.3", "-", "global damping values of Fig. 19 (each < 1)", lo=0),
    integer("particles", 16, "particles per energy in Figs. 16 and 19 (quick: 2)", lo=1),
    integer("probability_particles", 250, "particles per energy in Figs. 8-10 (the paper's "
            "250; quick: 40)", lo=1),
    integer("seed", 3, "seed of every run (scene k of a run: scenes.scene_seed)", lo=0),
    number("time_step_fraction", 0.0, "-", "overrides every figure's time step (fraction of "
           "the Rayleigh time); 0: the paper's (5 %, 2 %, 1 %)", lo=0, hi=1),
    integer("jobs", 1, "YADE processes sharing each run's scenes", lo=1, unit="processes"),
    text("out", "out/verify", "output folder"),
]


@dataclasses.dataclass
class Run:
    """One set of impacts: `particles` particles of `material` (name) and `size` (m) at each
    energy, with attach() options."""

    material: str
    size: float
    energies: list
    particles: int
    seed: int
    options: dict
    per_scene: int = 1
    target: str = "steel"

    def key(self, energy):
        return json.dumps([self.material, self.size, energy, self.particles, self.seed,
                           self.target, sorted(self.options.items())])


def paper_material(name):
    """The material as the paper's single-particle verification ran it (Emax/E50 = 4)."""
    return dataclasses.replace(load_material(name), emax_ratio=EMAX_RATIO)


def probability_energies(material, size, levels, partner):
    """Specific energies (J/kg, rounded to 2 digits) at which the model's probability is each of
    `levels`."""
    grid = np.geomspace(1.0, 1e5, 4000)
    p = material.breakage_probability(grid, size, partner=partner)
    return [float(f"{np.interp(level, p, grid):.2g}") for level in levels]


def _options(time_step, **more):
    return {"time_step_fraction": time_step, "emax_ratio": EMAX_RATIO, "kappa": 1.0, "cs": 0.0,
            "emin": 1e-4, "dmin": None, "read_period": "every_step", **more}


class Runner:
    """Runs impacts once per key (figures share runs) and keeps every result."""

    def __init__(self, jobs):
        self.jobs = jobs
        self.results = {}
        self.wall = {}

    def run(self, run):
        from yadebreak import scenes
        mat, steel = paper_material(run.material), load_material(run.target)
        out = []
        for energy in run.energies:
            key = run.key(energy)
            if key not in self.results:
                began = time.time()
                tally, _ = scenes.single_impacts(
                    run.material, run.size, float(np.sqrt(2.0 * energy)), run.particles,
                    run.per_scene, run.seed, target=run.target, jobs=self.jobs,
                    wait_for_arrivals=True, **run.options)
                result = reports.breakage_result_of(tally, mat, energy, steel)
                if run.options.get("replace") is False:      # no progeny: no t10 to show
                    for key in ("t10_simulated", "t10_primary_events", "progeny_markers",
                                "relative_sizes", "progeny_passing_simulated",
                                "progeny_passing_model"):
                        result.pop(key, None)
                    result["t10_note"] = "broken particles not replaced (probability only)"
                result.update(steps=tally.steps, scenes_at_step_limit=tally.scenes_at_step_limit,
                              wall_s=time.time() - began, material=mat.name, size=run.size,
                              options=run.options, seed=run.seed)
                self.results[key] = result
                progress(f"{mat.name} {1e3 * run.size:g} mm {_settings_short(run.options)}: "
                         f"{reports.result_line(result)} ({result['wall_s']:.0f} s)")
            out.append(self.results[key])
        return out


def _settings_short(options):
    gd = options.get("global_damping")
    return (f"dt {100 * options['time_step_fraction']:g} % RT, global damping "
            f"{'file' if gd is None else f'{gd:g}'}")


def settings_text(options, material_names, size, particles, seed, extra="", damping=None):
    """One line of a figure's settings; `damping` (text) replaces the files' global damping."""
    gd = options.get("global_damping")
    if damping is None:
        damping = ("each material file's (" + ", ".join(
            f"{n} {load_material(n).global_damping:g}" for n in material_names) + ")"
                   if gd is None else f"{gd:g}")
    return (f"{1e3 * size:g} mm on steel, {particles} particles per point, seed {seed}; "
            f"Emax/E50 {EMAX_RATIO:g}, time step {100 * options['time_step_fraction']:g} % of "
            f"the Rayleigh time, dmin = top size / 20, emin 1e-4 J, kappa 1, cs 0, global "
            f"damping {damping}, contacts read every step"
            + ("" if options.get("replace", True) else ", broken particles not replaced")
            + (f"; {extra}" if extra else ""))


# -- figures ---------------------------------------------------------------------------------
def figure_probability(args, runner, out):
    """Figs. 8-10: broken fraction against energy, per material, 5.5 mm on steel."""
    steel = load_material("steel")
    levels = QUICK_LEVELS if args.quick else PROBABILITY_LEVELS
    n = 40 if args.quick and args.probability_particles == 250 else args.probability_particles
    options = _options(args.time_step_fraction or RT_PROBABILITY, replace=False)
    series = {}
    for name in args.material_list:
        mat = paper_material(name)
        energies = probability_energies(mat, PROBABILITY_SIZE, levels, steel)
        series[name] = runner.run(Run(name, PROBABILITY_SIZE, energies, n, args.seed, options,
                                      per_scene=min(n, 50)))
    plt = _plt()
    fig, ax = plt.subplots(figsize=(7.5, 5.2))
    rows = []
    for k, (name, results) in enumerate(series.items()):
        mat = paper_material(name)
        energies = [r["specific_energy"] for r in results]
        grid = np.geomspace(min(energies) / 2, max(energies) * 2, 200)
        ax.semilogx(grid, 100 * mat.breakage_probability(grid, PROBABILITY_SIZE, partner=steel),
                    "-", c=f"C{k}", label=f"{mat.name}: model (Eqs. 1-4)")
        broken = [100 * r["broken_fraction"] for r in results]
        ax.errorbar(energies, broken, yerr=reports.bounded_errors(
            broken, [300 * r["binomial_sigma"] for r in results], 0.0, 100.0), fmt="o", c=f"C{k}",
            capsize=3, label=f"{mat.name}: simulation (3 sigma of the model's binomial)")
        for r in results:
            off = (r["broken_fraction"] - r["model_probability"]) / max(r["binomial_sigma"], 1e-12)
            rows.append([mat.name, f"{r['specific_energy']:g}", r["particles"],
                         f"{100 * r['broken_fraction']:.1f}", f"{100 * r['model_probability']:.1f}",
                         f"{off:+.2f}", "yes" if abs(off) <= 3 else "**no**"])
    ax.set(xlabel="specific impact energy Ek/mp (J/kg)", ylabel="broken (%)",
           title="Figs. 8-10: breakage probability, single impacts")
    ax.legend(fontsize=7, loc="upper left")
    text_ = settings_text(options, args.material_list, PROBABILITY_SIZE, n, args.seed)
    path = _save(fig, out / "fig08_probability.png", text_)
    table = _table(["material", "Ek/mp (J/kg)", "particles", "broken %", "model %",
                    "(sim - model) / sigma", "within 3 sigma"], rows)
    return {"name": "Figs. 8-10: breakage probability against energy", "plot": path.name,
            "settings": text_, "table": table,
            "checks": [{"what": f"{row[0]} {row[1]} J/kg within 3 sigma", "ok": row[-1] == "yes"}
                       for row in rows]}


def figure_t10(args, runner, out):
    """Fig. 16: t10 against energy per material at 29 mm, copper ore also at 5.5 mm."""
    options = _options(args.time_step_fraction or RT_FRAGMENTATION)
    energies = [1000.0] if args.quick else args.energy_list
    cases = [(name, FRAGMENT_SIZE) for name in args.material_list]
    if not args.quick and "copper_ore" in args.material_list:
        cases.append(("copper_ore", PROBABILITY_SIZE))
    n = 2 if args.quick and args.particles == 16 else args.particles
    plt = _plt()
    fig, ax = plt.subplots(figsize=(7.5, 5.2))
    steel = load_material("steel")
    rows = []
    for k, (name, size) in enumerate(cases):
        mat = paper_material(name)
        # the file's damping given explicitly: the same run as Fig. 19's point at that value
        results = runner.run(Run(name, size, energies, n, args.seed,
                                 {**options, "global_damping": mat.global_damping}))
        grid = np.geomspace(50.0, 5000.0, 200)
        ax.semilogx(grid, mat.t10_model(grid, size, steel), "-" if size == FRAGMENT_SIZE
                    else "--", c=f"C{k}", label=f"{mat.name} {1e3 * size:g} mm: model (Eq. 7)")
        done = [r for r in results if r.get("t10_simulated") is not None]
        ax.plot([r["specific_energy"] for r in done], [r["t10_simulated"] for r in done], "o",
                c=f"C{k}", label=f"{mat.name} {1e3 * size:g} mm: simulation")
        rows += [_t10_row(mat.name, size, r) for r in results]
    ax.set(xlabel="specific impact energy Ek/mp (J/kg)", ylabel="t10 (%)",
           title="Fig. 16: t10 against energy (single impacts on steel)")
    ax.legend(fontsize=7, loc="upper left")
    text_ = settings_text(options, [c[0] for c in cases], FRAGMENT_SIZE, n, args.seed,
                          "the paper's Fig. 16 is drop-weight; these are single impacts")
    path = _save(fig, out / "fig16_t10.png", text_)
    return {"name": "Fig. 16: t10 against energy", "plot": path.name, "settings": text_,
            "table": _table(T10_HEADER, rows), "checks": []}


T10_HEADER = ["material", "size (mm)", "Ek/mp (J/kg)", "global damping", "broken %",
              "t10 sim (%)", "t10 model (%)", "sim / model", "breakages", "wall (s)"]


def _t10_row(name, size, r):
    gd = r["options"].get("global_damping")
    sim, mod = r.get("t10_simulated"), r.get("t10_model")
    return [name, f"{1e3 * size:g}", f"{r['specific_energy']:g}",
            "file" if gd is None else f"{gd:g}", f"{100 * r['broken_fraction']:.1f}",
            "-" if sim is None else f"{sim:.2f}", "-" if mod is None else f"{mod:.2f}",
            "-" if sim is None or not mod else f"{sim / mod:.2f}",
            r.get("breakage_events_all_generations", 0), f"{r['wall_s']:.0f}"]


def figure_damping(args, runner, out):
    """Fig. 19: copper ore at 29 mm with global damping 0 ... 0.3, t10 and the progeny."""
    ts = args.time_step_fraction or (RT_FRAGMENTATION if args.quick else RT_DAMPING)
    energies = [1000.0] if args.quick else args.energy_list
    dampings = [0.0, 0.3] if args.quick else args.damping_list
    n = 2 if args.quick and args.particles == 16 else args.particles
    mat = paper_material("copper_ore")
    by_damping = {gd: runner.run(Run("copper_ore", FRAGMENT_SIZE, energies, n, args.seed,
                                     _options(ts, global_damping=gd))) for gd in dampings}
    plt = _plt()
    fig, axes = plt.subplots(1, 2, figsize=(13, 5.2))
    grid = np.geomspace(50.0, 5000.0, 200)
    axes[0].semilogx(grid, mat.t10_model(grid, FRAGMENT_SIZE, load_material("steel")), "k-",
                     label="model (Eq. 7)")
    rows = []
    for k, (gd, results) in enumerate(by_damping.items()):
        done = [r for r in results if r.get("t10_simulated") is not None]
        axes[0].plot([r["specific_energy"] for r in done], [r["t10_simulated"] for r in done],
                     "o", c=f"C{k}", label=f"simulation, global damping {gd:g}")
        for j, r in enumerate(done):
            if k == 0:
                axes[1].semilogx(r["relative_sizes"], r["progeny_passing_model"], "-",
                                 c=f"C{j + 5}", label=f"model, {r['specific_energy']:g} J/kg")
            axes[1].semilogx(r["relative_sizes"], r["progeny_passing_simulated"],
                             "osv^D"[k % 5], ms=4, mfc="none", c=f"C{j + 5}",
                             label=f"{r['specific_energy']:g} J/kg, damping {gd:g}")
        rows += [_t10_row("copper_ore", FRAGMENT_SIZE, r) for r in results]
    axes[0].set(xlabel="specific impact energy Ek/mp (J/kg)", ylabel="t10 (%)",
                title="Fig. 19: t10 with global damping")
    axes[1].set(xlabel="relative size d / d_parent", ylabel="progeny passing (%)",
                title="progeny (fines included)")
    for ax in axes:
        ax.legend(fontsize=7, loc="upper left")
    options = _options(ts)
    text_ = settings_text(options, ["copper_ore"], FRAGMENT_SIZE, n, args.seed,
                          "the paper: damping makes the progeny finer (its Fig. 19)",
                          damping=", ".join(f"{gd:g}" for gd in dampings)
                          + " (attach's global_damping; the file's is 0.3)")
    path = _save(fig, out / "fig19_damping.png", text_)
    base = by_damping[dampings[0]]
    checks = []
    for gd in dampings[1:]:
        for r0, r in zip(base, by_damping[gd]):
            if r0.get("t10_simulated") is not None and r.get("t10_simulated") is not None:
                checks.append({"what": f"{r['specific_energy']:g} J/kg: t10 with damping {gd:g} "
                                       f"minus without", "energy": r["specific_energy"],
                               "damping": gd, "t10_0": r0["t10_simulated"],
                               "t10": r["t10_simulated"],
                               "difference": r["t10_simulated"] - r0["t10_simulated"]})
    return {"name": "Fig. 19: global damping", "plot": path.name, "settings": text_,
            "table": _table(T10_HEADER, rows), "checks": checks}


# -- output ----------------------------------------------------------------------------------
def _plt():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


def _save(fig, path, settings):
    """The figure with its settings printed under it."""
    import textwrap
    wrapped = textwrap.fill("Settings: " + settings, 150)
    lines = wrapped.count("\n") + 1
    fig.tight_layout(rect=(0, 0.035 * lines + 0.02, 1, 1))
    fig.text(0.01, 0.01, wrapped, fontsize=7, va="bottom")
    fig.savefig(path, dpi=110)
    import matplotlib.pyplot as plt
    plt.close(fig)
    return path


def _table(header, rows):
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(str(c) for c in row) + " |" for row in rows]
    return "\n".join(lines)


def write_report(out, figures, runner, args, wall):
    lines = ["# The paper's Section 4.1 verification", "",
             f"`python3 -m yadebreak verify {' '.join(args.argv)}`: {wall:.0f} s of wall time "
             f"({'quick subset' if args.quick else 'the figures asked for'}). Model lines: "
             "docs/model.md; settings under each figure.", ""]
    for f in figures:
        lines += [f"## {f['name']}", "", f"![{f['name']}]({f['plot']})", "",
                  f"Settings: {f['settings']}.", "", f["table"], ""]
        for c in f["checks"]:
            if "ok" in c:
                continue
            lines.append(f"- {c['what']}: {c['t10']:.2f} - {c['t10_0']:.2f} = "
                         f"{c['difference']:+.2f} points of t10")
        lines.append("")
    (out / "report.md").write_text("\n".join(lines))
    (out / "results.json").write_text(json.dumps(
        {"argv": args.argv, "wall_s": wall, "figures": figures,
         "runs": list(runner.results.values())}, indent=1, default=float))


def verify(args):
    """`python3 -m yadebreak verify`: the figures asked for, report.md, results.json, plots."""
    from yadebreak.tools.options import fail
    import sys
    began = time.time()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    wanted = [f.strip() for f in args.figures.split(",") if f.strip()]
    unknown = [f for f in wanted if f not in FIGURES]
    if unknown:
        fail(f"--figures = {args.figures}: unknown {unknown}; accepted {', '.join(FIGURES)}")
    args.material_list = (["copper_ore"] if args.quick else
                          [m.strip() for m in args.materials.split(",") if m.strip()])
    args.energy_list = [float(e) for e in args.energies.split(",")]
    args.damping_list = [float(d) for d in args.dampings.split(",")]
    bad = [d for d in args.damping_list if d >= 1.0]
    if bad:
        fail(f"--dampings = {args.dampings}: each global damping must be in [0, 1), got {bad}")
    args.argv = getattr(args, "argv", None) or sys.argv[2:]
    for name in args.material_list:
        load_material(name)                   # a bad name stops here, before any run
    runner = Runner(args.jobs)
    makers = {"probability": figure_probability, "t10": figure_t10, "damping": figure_damping}
    figures = [makers[f](args, runner, out) for f in FIGURES if f in wanted]
    write_report(out, figures, runner, args, time.time() - began)
    progress(f"wrote {out / 'report.md'} ({time.time() - began:.0f} s)")
    return 0


def main(argv):
    """Parse `argv` (after `verify`) and run; bad values stop with one line (exit 2)."""
    from yadebreak.tools.options import DEBUG, ScriptParser, add_params, read_params
    parser = ScriptParser(prog="python3 -m yadebreak verify", description=__doc__.split("\n")[0])
    add_params(parser, PARAMS + [DEBUG])
    args = read_params(parser.parse_args(argv), PARAMS + [DEBUG])
    args.argv = list(argv)
    return verify(args)
