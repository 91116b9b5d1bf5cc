"""Figs. 8-11: breakage probabilities (impacts without replacement: the probability is that of
the first impact, which replacement cannot change) against energy and test (single impact, drop
weight), target and restitution, size, and after repeated impacts."""
from __future__ import annotations

import json
import time

import numpy as np

from yadebreak.criteria import load_material
from yadebreak.analysis import reports
from yadebreak.jobs.lifecycle import progress
from yadebreak.studies.verify import report
from yadebreak.studies.verify.settings import (PROBABILITY_LEVELS, PROBABILITY_SIZE, QUICK_LEVELS, RT_PROBABILITY, Run,
                       paper_options, paper_material, probability_energies, settings_text)

#: Fig. 8's drop weight: the striker's mass over the particle's (scenes.drop_weight_scene's)
STRIKER_MASS_RATIO = 50.0
#: Fig. 9: the other restitution of copper ore on steel (the file's is 0.39)
OTHER_RESTITUTION = 0.8
#: Fig. 10: the sizes (m) of copper ore on steel; the quick subset's
SIZES, QUICK_SIZES = (2.8e-3, 5.5e-3, 11e-3, 22e-3), (2.8e-3, 5.5e-3, 11e-3)
#: Fig. 11: 37.5 mm copper ore at 94.7 J/kg on steel, the impacts counted, the gammas as
#: multiples of the file's
REPEATED_SIZE, REPEATED_ENERGY = 37.5e-3, 94.7
REPEATED_IMPACTS, QUICK_REPEATED_IMPACTS = 10, 5
GAMMA_FACTORS, QUICK_GAMMA_FACTORS = (0.5, 1.0, 2.0), (1.0, 2.0)
#: the material of Figs. 9-11 (the paper's)
COPPER_ORE = "copper_ore"


def _particles(args):
    """Particles per point: --probability-particles, 40 in the quick subset unless given."""
    return 40 if args.quick and args.probability_particles == 250 else args.probability_particles


def _options(args):
    return paper_options(args.time_step_fraction or RT_PROBABILITY, replace=False)


def _off(r):
    """(simulated - model) / binomial sigma of one point."""
    return (r["broken_fraction"] - r["model_probability"]) / max(r["binomial_sigma"], 1e-12)


def _row(label, r):
    off = _off(r)
    return [label, f"{r['specific_energy']:g}", r["particles"], f"{100 * r['broken_fraction']:.1f}",
            f"{100 * r['model_probability']:.1f}", f"{off:+.2f}",
            "yes" if abs(off) <= 3 else "**no**"]


_HEADER = ["case", "Ek/mp (J/kg)", "particles", "broken %", "model %", "(sim - model) / sigma",
           "within 3 sigma"]


def _checks(rows):
    return [{"what": f"{row[0]} {row[1]} J/kg within 3 sigma", "ok": row[-1] == "yes"}
            for row in rows]


def _points(ax, results, style, color, label):
    """Simulated broken % with the model's binomial 3 sigma."""
    energies = [r["specific_energy"] for r in results]
    broken = [100 * r["broken_fraction"] for r in results]
    ax.errorbar(energies, broken, yerr=reports.bounded_errors(
        broken, [300 * r["binomial_sigma"] for r in results], 0.0, 100.0), fmt=style, c=color,
        mfc="none" if style == "s" else color, capsize=3, label=label)


def _model_line(ax, mat, energies, size, partner, color, label, style="-"):
    grid = np.geomspace(min(energies) / 2, max(energies) * 2, 200)
    ax.semilogx(grid, 100 * mat.breakage_probability(grid, size, partner=partner), style,
                c=color, label=label)


def _legend(ax):
    """The legend right of the axes: the points fill the plot from corner to corner."""
    ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0)


# -- Fig. 8: single impacts and drop weight -----------------------------------------------------
def figure_probability(args, runner, out):
    """Fig. 8: broken fraction against energy, per material, 5.5 mm, single impacts on steel
    and drop-weight tests (striker and anvil of steel)."""
    steel = load_material("steel")
    levels = QUICK_LEVELS if args.quick else PROBABILITY_LEVELS
    n = _particles(args)
    options = _options(args)
    runs = []
    for name in args.material_list:
        energies = probability_energies(paper_material(name), PROBABILITY_SIZE, levels, steel)
        runs += [Run(name, PROBABILITY_SIZE, energies, n, (args.seed,), options,
                     per_scene=min(n, 50)),
                 Run(name, PROBABILITY_SIZE, energies, n, (args.seed,), options, per_scene=n,
                     test="drop_weight")]
    results = runner.run_all(runs)
    single = dict(zip(args.material_list, results[0::2]))
    dropped = dict(zip(args.material_list, results[1::2]))
    plt = report.plt_module()
    fig, ax = plt.subplots(figsize=(10, 5.2))
    rows = []
    for k, name in enumerate(single):
        mat = paper_material(name)
        energies = [r["specific_energy"] for r in single[name]]
        _model_line(ax, mat, energies, PROBABILITY_SIZE, steel, f"C{k}",
                    f"{mat.name}: model (Eqs. 1-4), both tests")
        _points(ax, single[name], "o", f"C{k}", f"{mat.name}: single impact")
        _points(ax, dropped[name], "s", f"C{k}", f"{mat.name}: drop weight")
        rows += [_row(f"{mat.name} single impact", r) for r in single[name]]
        rows += [_row(f"{mat.name} drop weight", r) for r in dropped[name]]
    ax.set(xlabel="specific impact energy Ek/mp (J/kg)", ylabel="broken (%)",
           title="Fig. 8: breakage probability, single impact and drop weight (DWT) on steel")
    _legend(ax)
    text_ = settings_text(options, args.material_list, PROBABILITY_SIZE, n, args.seed, extra=(
        f"drop weight: a steel sphere of {STRIKER_MASS_RATIO:g} x the particle's mass falls "
        "on the particle resting on a steel anvil, Ek/mp its kinetic energy over the "
        "particle's mass; model line of both tests: Eqs. 1-4 against steel (the particle "
        "absorbs the share e of each of its two steel contacts, Eq. 14)"),
        target="steel (single impact; striker and anvil of steel in the drop weight)")
    path = report.save(fig, out / "fig08_probability.png", text_)
    return {"name": "Fig. 8: breakage probability, single impact and drop weight",
            "plot": path.name, "settings": text_, "table": report.table(_HEADER, rows),
            "checks": _checks(rows)}


# -- Fig. 9: restitution and target -------------------------------------------------------------
def _target_file(out, name, description, young, poisson, contacts, contact_like=None):
    """A non-breakable target material file written to <out>/targets/<name>.toml (used by this
    report only); `contacts` {other: (friction, rolling friction, restitution)}. Returns its
    absolute path (YADE workers read it)."""
    folder = (out / "targets").resolve()
    folder.mkdir(parents=True, exist_ok=True)
    steel = load_material("steel")
    lines = [f'name = "{name}"', f'description = "{description}"', "breakable = false"]
    if contact_like:
        lines.append(f'contact_like = "{contact_like}"')
    lines += ["", "[elastic]", f"density = {steel.density:g}",
              f"young_modulus = {young / 1e9:.6g}", f"poisson_ratio = {poisson:g}"]
    for other, (mu, mu_r, cr) in contacts.items():
        lines += ["", f"[contact.{other}]", f"friction = {mu:g}", f"rolling_friction = {mu_r:g}",
                  f"restitution = {cr:g}"]
    path = folder / f"{name}.toml"
    path.write_text("\n".join(lines) + "\n")
    return str(path)


def fig9_targets(out):
    """[(label, target name or file, seed offset)]: copper ore on steel at the file's
    restitution and at OTHER_RESTITUTION, on rubber and on a target as stiff as copper ore (both
    with the particle's steel contact parameters, as the paper's Fig. 9). The second restitution
    runs with the next seed: its particles are drawn independently of the first's, so that the
    difference of the two is binomial (the same seed gives the same fracture energies)."""
    ore, steel = load_material(COPPER_ORE), load_material("steel")
    c = ore.contact_with(steel)
    self_contact = steel.contact_with(steel)
    own = (self_contact.friction, self_contact.rolling_friction, self_contact.restitution)
    other_cr = _target_file(
        out, f"steel_restitution_{OTHER_RESTITUTION:g}",
        f"steel; restitution {OTHER_RESTITUTION:g} with {ore.name}", steel.young_modulus,
        steel.poisson_ratio, {ore.name: (c.friction, c.rolling_friction, OTHER_RESTITUTION),
                              "self": own})
    as_stiff = _target_file(
        out, f"as_stiff_as_{ore.name}", f"steel with {ore.name}'s Young's modulus and Poisson "
        "ratio", ore.young_modulus, ore.poisson_ratio, {"self": own}, contact_like="steel")
    km = {t: load_material(t).hertz_stiffness / 1e9 for t in ("steel", "rubber", as_stiff)}
    return [(f"steel (km {km['steel']:.0f} GPa), Cr {c.restitution:g}", "steel", 0),
            (f"steel (km {km['steel']:.0f} GPa), Cr {OTHER_RESTITUTION:g}", other_cr, 1),
            (f"rubber (km {km['rubber']:.1f} GPa), Cr {c.restitution:g}", "rubber", 0),
            (f"as stiff as copper ore (km {km[as_stiff]:.1f} GPa), Cr {c.restitution:g}",
             as_stiff, 0)]


def figure_targets(args, runner, out):
    """Fig. 9: 5.5 mm copper ore against steel at two restitutions, rubber and a target as stiff
    as the ore; each target at the energies where the model (Eq. 4 with that target) gives the
    levels. Checks: each point within 3 sigma of its model; the two restitutions differ by no
    more than 3 sigma of the difference."""
    levels = (0.5,) if args.quick else PROBABILITY_LEVELS
    n, options = _particles(args), _options(args)
    mat = paper_material(COPPER_ORE)
    targets = [(label, target, seed_offset, load_material(target))
               for label, target, seed_offset in fig9_targets(out)]
    by_target = runner.run_all([Run(
        COPPER_ORE, PROBABILITY_SIZE, probability_energies(mat, PROBABILITY_SIZE, levels, partner),
        n, (args.seed + seed_offset,), options, per_scene=min(n, 50), target=target)
        for _, target, seed_offset, partner in targets])
    series = [(label, partner, results)
              for (label, _, _, partner), results in zip(targets, by_target)]
    plt = report.plt_module()
    fig, ax = plt.subplots(figsize=(10, 5.2))
    rows = []
    for k, (label, partner, results) in enumerate(series):
        energies = [r["specific_energy"] for r in results]
        _model_line(ax, mat, energies, PROBABILITY_SIZE, partner, f"C{k}",
                    f"model (Eqs. 1-4) on {label}", "--" if k == 1 else "-")
        _points(ax, results, "s" if k == 1 else "o", f"C{k}", f"simulation on {label}")
        rows += [_row(f"on {label}", r) for r in results]
    ax.set(xlabel="specific impact energy Ek/mp (J/kg)", ylabel="broken (%)",
           title="Fig. 9: copper ore, 5.5 mm: restitution and target stiffness")
    _legend(ax)
    checks = _checks(rows)
    diff_rows = []
    (label_a, _, first), (label_b, _, second) = series[0], series[1]
    for a, b in zip(first, second):           # same energies: restitution is not in the model
        p = a["model_probability"]
        sigma = np.sqrt(p * (1 - p) * (1 / a["particles"] + 1 / b["particles"]))
        diff = b["broken_fraction"] - a["broken_fraction"]
        ok = bool(abs(diff) <= 3 * max(sigma, 1e-12))
        checks.append({"what": f"restitution {label_b} vs {label_a} at "
                               f"{a['specific_energy']:g} J/kg: difference within 3 sigma",
                       "ok": ok})
        diff_rows.append(f"- restitution at {a['specific_energy']:g} J/kg: "
                         f"{100 * diff:+.1f} points ({diff / max(sigma, 1e-12):+.2f} sigma of "
                         f"the difference): {'yes' if ok else '**no**'}")
    text_ = settings_text(options, [COPPER_ORE], PROBABILITY_SIZE, n, args.seed, extra=(
        "targets: the file's steel; steel with restitution "
        f"{OTHER_RESTITUTION:g} against copper ore (seed {args.seed + 1}); rubber (materials "
        "rubber.toml); steel with copper ore's Young's modulus and Poisson ratio (the last "
        "two files in <out>/targets)"),
        target="each target (below)")
    path = report.save(fig, out / "fig09_targets.png", text_)
    return {"name": "Fig. 9: breakage probability against restitution and target",
            "plot": path.name, "settings": text_,
            "table": report.table(_HEADER, rows) + "\n\n" + "\n".join(diff_rows),
            "checks": checks}


# -- Fig. 10: size -------------------------------------------------------------------------------
def figure_sizes(args, runner, out):
    """Fig. 10: copper ore of several sizes on steel, each at the energies of the levels."""
    steel = load_material("steel")
    sizes = QUICK_SIZES if args.quick else SIZES
    levels = (0.5,) if args.quick else PROBABILITY_LEVELS
    n, options = _particles(args), _options(args)
    mat = paper_material(COPPER_ORE)
    runs = [Run(COPPER_ORE, size, probability_energies(
        mat, size, QUICK_LEVELS if args.quick and size == PROBABILITY_SIZE else levels, steel),
        n, (args.seed,), options, per_scene=min(n, 50)) for size in sizes]   # quick 5.5 mm: Fig. 8's
    by_size = runner.run_all(runs)
    plt = report.plt_module()
    fig, ax = plt.subplots(figsize=(10, 5.2))
    rows = []
    for k, (size, run, results) in enumerate(zip(sizes, runs, by_size)):
        energies = run.energies
        _model_line(ax, mat, energies, size, steel, f"C{k}", f"{1e3 * size:g} mm: model")
        _points(ax, results, "o", f"C{k}", f"{1e3 * size:g} mm: simulation")
        rows += [_row(f"{1e3 * size:g} mm", r) for r in results]
    ax.set(xlabel="specific impact energy Ek/mp (J/kg)", ylabel="broken (%)",
           title="Fig. 10: copper ore on steel, particle size")
    _legend(ax)
    text_ = settings_text(options, [COPPER_ORE], ", ".join(f"{1e3 * s:g}" for s in sizes) + " mm",
                          n, args.seed)
    path = report.save(fig, out / "fig10_sizes.png", text_)
    return {"name": "Fig. 10: breakage probability against size", "plot": path.name,
            "settings": text_, "table": report.table(_HEADER, rows), "checks": _checks(rows)}


# -- Fig. 11: repeated impacts -----------------------------------------------------------------
def repeated(runner, materials, size, energy, particles, impacts, seed, options):
    """`particles` particles of each of `materials` (Materials: their gammas) fired at `energy`
    (J/kg) on steel `impacts` times, each material a Task of one scene (repeated_scene: on a
    worker with the other figures' scenes, or here); the broken leave the test. Returns each
    material's broken fraction after each impact, kept in runner.results."""
    from yadebreak.studies.verify.settings import Run, Task, run_cost
    tasks = []
    for material in materials:
        key = json.dumps(["repeated", material.name, material.params.gamma, size, energy,
                          particles, impacts, seed, sorted(options.items())])
        spec = {"task": f"{__name__}:repeated_scene", "counts": [particles],
                "material": material.source, "gamma": material.params.gamma, "size": size,
                "energy": energy, "impacts": impacts, "seed": seed, "options": options}
        like = Run(material.name, size, [energy], particles, (seed,), options)
        tasks.append(Task(key, spec, impacts * run_cost(like, energy)))
    results = []
    for material, task, (done,) in zip(materials, tasks, runner.run_tasks(tasks)):
        if task.key not in runner.results:
            runner.results[task.key] = {
                "test": "repeated", "material": material.name, "gamma": material.params.gamma,
                "size": size, "specific_energy": energy, "particles": particles,
                "broken_fraction_after": done["fractions"], "scenes_at_step_limit": 0,
                "options": options, "seed": seed, "wall_s": done["wall_s"]}
            progress(f"{material.name} {1e3 * size:g} mm, gamma {material.params.gamma:g}: "
                     f"{100 * done['fractions'][-1]:.0f} % broken after {impacts} impacts "
                     f"({done['wall_s']:.0f} s)")
        results.append(runner.results[task.key])
    return results


def repeated_scene(spec, k):
    """The one scene of a repeated-impact Task (scenes.impact_again, `impacts` times): the
    broken fraction after each impact and the seconds it took."""
    from yadebreak import scenes
    from yadebreak.scenes import view
    began = time.time()
    material = paper_material(spec["material"]).with_params(gamma=spec["gamma"])
    particles, speed = spec["counts"][k], float(np.sqrt(2.0 * spec["energy"]))
    brk, ids = scenes.impact_scene(material, spec["size"], [speed] * particles,
                                   seed=spec["seed"], **spec["options"])
    home = {i: view.position(i) for i in ids}
    alive, fractions = list(ids), []
    for _ in range(spec["impacts"]):
        alive = scenes.impact_again(brk, alive, home, speed)
        fractions.append(1 - len(alive) / particles)
    return {"fractions": fractions, "wall_s": time.time() - began}


def figure_repeated(args, runner, out):
    """Fig. 11: the broken fraction of 37.5 mm copper ore after each of repeated impacts at
    94.7 J/kg on steel, for three gammas, against the model (Eqs. 1-6)."""
    steel = load_material("steel")
    impacts = QUICK_REPEATED_IMPACTS if args.quick else REPEATED_IMPACTS
    factors = QUICK_GAMMA_FACTORS if args.quick else GAMMA_FACTORS
    n, options = _particles(args), _options(args)
    base = paper_material(COPPER_ORE)
    share = base.energy_partition(steel)
    plt = report.plt_module()
    fig, ax = plt.subplots(figsize=(10, 5.2))
    rows, checks = [], []
    number = np.arange(1, impacts + 1)
    mats = [base.with_params(gamma=factor * base.params.gamma) for factor in factors]
    runs = repeated(runner, mats, REPEATED_SIZE, REPEATED_ENERGY, n, impacts, args.seed, options)
    for k, (mat, r) in enumerate(zip(mats, runs)):
        model = mat.criterion.repeated_broken_fraction(share * REPEATED_ENERGY, REPEATED_SIZE,
                                                       impacts)
        sigma = np.sqrt(model * (1 - model) / n)
        sim = np.array(r["broken_fraction_after"])
        ax.plot(number, 100 * model, "-", c=f"C{k}", label=f"gamma {mat.params.gamma:g}: model "
                "(Eqs. 1-6)")
        ax.errorbar(number, 100 * sim, yerr=reports.bounded_errors(100 * sim, 300 * sigma, 0.0,
                                                                   100.0),
                    fmt="o", c=f"C{k}", capsize=3, label=f"gamma {mat.params.gamma:g}: simulation")
        for i in range(impacts):
            off = (sim[i] - model[i]) / max(sigma[i], 1e-12)
            ok = abs(off) <= 3
            rows.append([f"{mat.params.gamma:g}", i + 1, n, f"{100 * sim[i]:.1f}",
                         f"{100 * model[i]:.1f}", f"{off:+.2f}", "yes" if ok else "**no**"])
            checks.append({"what": f"gamma {mat.params.gamma:g} after impact {i + 1} within 3 sigma",
                           "ok": bool(ok)})
    ax.set(xlabel="number of impacts", ylabel="broken (%)",
           title=f"Fig. 11: copper ore, {1e3 * REPEATED_SIZE:g} mm at {REPEATED_ENERGY:g} J/kg "
                 "on steel, repeated impacts")
    _legend(ax)
    text_ = settings_text(options, [COPPER_ORE], REPEATED_SIZE, n, args.seed, extra=(
        f"{impacts} impacts at {REPEATED_ENERGY:g} J/kg, each particle back to its start and "
        "fired again without spin, the broken ones leaving the test; gamma "
        + ", ".join(f"{f * base.params.gamma:g}" for f in factors)
        + f" (the file's {base.params.gamma:g})"))
    path = report.save(fig, out / "fig11_repeated.png", text_)
    return {"name": "Fig. 11: broken fraction after repeated impacts", "plot": path.name,
            "settings": text_, "table": report.table(
                ["gamma", "impacts", "particles", "broken %", "model %", "(sim - model) / sigma",
                 "within 3 sigma"], rows), "checks": checks}
