"""Where the energy of a cascade goes: the kinetic energy E0 of a single impact split into where it
ends, per breakage generation and in total, closing to the integration error (`verify --figures
energy`; docs/verification.md, "Where the energy of a cascade goes").

Each particle is run alone as Fig. 16 runs it (the paper's settings, scenes.run_until_rebound
waiting for arrivals; particle k is the scene seeded scenes.scene_seed(seed, k), so it is the k-th
particle of verify's run at that energy), with YADE's energy tracking on (scenes.energy: it adds
up what the law and the integrator do and changes no force). At the end:

  E0 = (a) + (c) + (d) + (e) + (f) + (g) + (i) + (j) + residual

  (a) broken       the engine's event log: at each breakage, the elastic energy of the parent's
                   contacts (elastic_energy_before, which the zeroing of the progeny's overlaps
                   takes out) plus the kinetic energy its progeny could not take
                   (kinetic_energy_before - kinetic_energy_after: spin beyond the parent's);
                   per generation of the broken body
  (c) dashpots     normal and shear dashpots of every contact, read every step (the shear
                   one over the material points' displacement, as friction)
                   (scenes.energy.ContactDissipation: the law's own counters corrupt memory on
                   this YADE); the share inside counted stressing events is not separated
  (d) damping      YADE: O.energy['nonviscDamp'] (Newton's damping, which the engine's global
                   damping switches on for fragments only)
  (e) kinetic      the scene at the end: kinetic energy (translation, spin) of breakable bodies
                   (the fragments that may still break, an unbroken particle), all leaving
  (f) inert        the same of unbreakable fragments and dummies
  (g) friction     the work of the elastic shear forces over the displacement of the bodies'
                   material points at the contact point, less the rise of their elastic energy
                   (ContactDissipation: slip, and what Mindlin's incremental shear spring, whose
                   stiffness follows the overlap, does not store), plus O.energy['gravWork'] (0:
                   the impact scenes have no gravity; no rolling friction in them)
  (i) ledger       the fines ledger's kinetic energy (dummies="ledger"; 0 with dummy spheres)
  (j) elastic      the elastic energy the contacts still hold at the end (the engine's count,
                   zeroed overlaps as the zero)
  residual         E0 minus the rest: the integration error. It holds (h), the zeroing's work,
                   which is nil by construction (a zeroed pair's zero moves only while it makes no
                   force), and the last step of each breakage: the law counts the parent's
                   contacts' dashpot work and elastic energy of that step, but the parent is
                   replaced before Newton applies that force, so its kinetic energy never pays
                   for it. It shrinks with the time step through a primary breakage (0.56 % of
                   E0 at 2 % RT, 0.05 % at 1 %: tests/test_cascade_energy.py); through a
                   fragment cloud it holds where the primary breakage left it (the same test).

Beside the sinks, what the criterion counted (not sinks: Ek' is the loading work of a body's
contacts, elastic energy that mostly returns plus dashpot work that is in (c)): (a') the Ek' of
the breakage events and its excess over m E (the fracture energy at the break), (b) the Ek' of
the events that did not break (damage), and the Ek' that unbreakable fragments received past
their fracture energy. Per generation: the energy that reached breakable bodies of that
generation above their fracture energy, the t10' Eq. 8 gives for it (at sum Ek' / sum m E, the
material's A and b', kappa 1) and the t10 the generation made (its families' t10, mass-weighted).
"""
from __future__ import annotations

import json
import time

import numpy as np

from yadebreak.jobs.lifecycle import progress
from yadebreak.model import equations
from yadebreak.studies.verify import report
from yadebreak.studies.verify.settings import (FRAGMENT_SIZE, RT_FRAGMENTATION, paper_material,
                                               settings_text)

#: the sinks, in the order of the table and the plot: key, the issue's letter, label
CATEGORIES = (("broken", "a", "broken (contacts' elastic energy at the break)"),
              ("dashpots", "c", "dashpots"),
              ("global_damping", "d", "global damping"),
              ("kinetic", "e", "kinetic, breakable bodies leaving"),
              ("inert", "f", "kinetic, unbreakable fragments and dummies"),
              ("friction", "g", "friction slip (and gravity)"),
              ("ledger", "i", "kinetic sent to the ledger"),
              ("elastic", "j", "elastic, still stored"),
              ("residual", "", "residual (integration error)"))
#: the figure's cases: energies (J/kg), those where Eq. 7 is at most 20 % (cases()), and particles
#: per case. Reading every contact every step costs: measured (2 % RT, one particle, seed 3),
#: under 2 s for copper ore at 150 and 1000 J/kg, 103 s for granulite at 1000, 47 s for limestone
#: at 150 and 454 s at 1000, where Eq. 7 is 42.5 %
ENERGIES, PARTICLES = (150.0, 1000.0), 1
#: the quick subset: copper ore at 1000 J/kg, one particle
QUICK_ENERGIES, QUICK_PARTICLES = (1000.0,), 1
#: a scene stops after this many steps at the latest (as verify's runs)
MAX_STEPS = 200000


def audit_impact(material, size, specific_energy, seed, options, duration=None,
                 max_steps=MAX_STEPS):
    """One particle of `material` (name) and `size` (m) fired normally at a steel plate at
    sqrt(2 `specific_energy`), seeded `seed`, with attach() `options`; run to rebound as verify
    runs it (or for `duration` s of simulated time). Returns the audit (split)."""
    from yadebreak import engine, scenes
    from yadebreak.scenes import energy as scene_energy
    brk, ids = scenes.impact_scene(material, size, [float(np.sqrt(2.0 * specific_energy))],
                                   seed=seed, **options)
    before = scene_energy.energy_now(brk)
    part = scene_energy.track_energy()
    if duration is None:
        scenes.run_until_rebound(ids, max_steps=max_steps, brk=brk, wait_for_arrivals=True)
    else:
        from yadebreak.scenes import view
        while view.now() < duration:
            engine.run_steps(10)
    after = scene_energy.energy_now(brk, part)
    return split(sum(before.kinetic.values()) + before.elastic, after, events_of(brk))


def events_of(brk):
    """The controller's events, each with its body's generation (damage events carry none)."""
    column = brk.state.table.columns["generation"]
    return [{**e, "generation": int(e.get("generation", column[e["id"]]))} for e in brk.events]


def split(e0, after, events):
    """The audit of one impact from its start energy `e0` (J), the scene's scenes.energy.EnergyNow
    at the end and its events (each with its body's generation): the sinks (J), what the criterion
    counted, the generations."""
    kinetic = after.kinetic
    sinks = {"broken": sum(broken_energy(e) for e in events if e["kind"] == "breakage"),
             "dashpots": after.normal_dashpot + after.shear_dashpot,
             "global_damping": after.global_damping,
             "kinetic": kinetic.get("breakable", 0.0) + kinetic.get("none", 0.0),
             "inert": kinetic.get("unbreakable", 0.0) + kinetic.get("dummy", 0.0),
             "friction": after.friction + after.gravity,
             "ledger": after.ledger_kinetic, "elastic": after.elastic}
    sinks["residual"] = e0 - sum(sinks.values())
    counted = {"breakage": _counted(events, "breakage"), "damage": _counted(events, "damage"),
               "unbreakable": _counted(events, "unbreakable_stressed"),
               "excess": sum(_excess(e) for e in events if e["kind"] == "breakage")}
    return {"e0": e0, "sinks": sinks, "counted": counted, "generations": generations(events)}


def broken_energy(event):
    """Energy (J) a breakage takes out of the DEM: its parent's contacts' elastic energy and the
    kinetic energy its progeny could not take."""
    return (event["elastic_energy_before"] + event["kinetic_energy_before"]
            - event["kinetic_energy_after"])


def _counted(events, kind):
    return sum(e["specific_energy"] * e["mass"] for e in events if e["kind"] == kind)


def _excess(event):
    return (event["specific_energy"] - event["fracture_energy"]) * event["mass"]


def generations(events):
    """Per generation (from 0), sums (J, kg) over its bodies' events: breakages, their mass, the
    energy taken out at the breaks, Ek' and m E of the breakages, the damage events' Ek', and
    the mass-weighted t10 of the families drawn (% times kg: divide by the mass)."""
    out = {}
    for e in events:
        g = out.setdefault(e["generation"], dict.fromkeys(
            ("breakages", "mass", "broken", "stressing", "fracture", "damage", "t10_mass"), 0.0))
        if e["kind"] == "breakage":
            g["breakages"] += 1
            g["mass"] += e["mass"]
            g["broken"] += broken_energy(e)
            g["stressing"] += e["specific_energy"] * e["mass"]
            g["fracture"] += e["fracture_energy"] * e["mass"]
            g["t10_mass"] += e.get("family_t10", e["t10"]) * e["mass"]
        elif e["kind"] == "damage":
            g["damage"] += e["specific_energy"] * e["mass"]
    return [dict(generation=k, **out[k]) for k in sorted(out)]


def combine(audits):
    """Several impacts' audits summed (J; the generations by generation)."""
    sinks = {k: sum(a["sinks"][k] for a in audits) for k, _, _ in CATEGORIES}
    counted = {k: sum(a["counted"][k] for a in audits) for k in audits[0]["counted"]}
    by = {}
    for a in audits:
        for g in a["generations"]:
            row = by.setdefault(g["generation"], dict.fromkeys(g, 0.0))
            for k, v in g.items():
                row[k] = g["generation"] if k == "generation" else row[k] + v
    return {"e0": sum(a["e0"] for a in audits), "sinks": sinks, "counted": counted,
            "generations": [by[k] for k in sorted(by)],
            "worst_residual": max(abs(a["sinks"]["residual"]) / a["e0"] for a in audits)}


def _paper_options(args, time_step):
    """The paper's settings with the command's fragmentation flags (as Figs. 13-19)."""
    from yadebreak.studies.verify import fragmentation_options
    from yadebreak.studies.verify.settings import paper_options
    return paper_options(time_step, **fragmentation_options(args))


#: an audited scene costs about this many of the same impact's scenes run as Fig. 16 runs them
#: (every contact read every step; measured: granulite at 1000 J/kg, 75 s against 21 s): the
#: place of its task in the queue (settings.run_cost)
AUDIT_COST = 3.5


def audit_task(name, energy, particles, seed, options):
    """The Task of `particles` particles of material `name` at `energy` (J/kg): scene k is
    particle k (audit_scene), on a worker or here."""
    from yadebreak.studies.verify.settings import Run, Task, run_cost
    options = {**options, "global_damping": paper_material(name).global_damping}
    key = json.dumps(["energy_audit", name, energy, particles, seed, sorted(options.items())])
    spec = {"task": f"{__name__}:audit_scene", "counts": [1] * particles, "material": name,
            "size": FRAGMENT_SIZE, "energy": energy, "seed": seed, "options": options}
    like = Run(name, FRAGMENT_SIZE, [energy], particles, (seed,), options)
    return Task(key, spec, AUDIT_COST * run_cost(like, energy))


def audit_scene(spec, k):
    """Scene k of an audit task: its particle's audit (audit_impact), with the seconds it took."""
    from yadebreak import scenes
    began = time.time()
    audit = audit_impact(spec["material"], spec["size"], spec["energy"],
                         scenes.scene_seed(spec["seed"], k), spec["options"])
    return {**audit, "wall_s": time.time() - began}


def audit_cases(runner, tasks):
    """The combined audit of each task's particles (runner.run_tasks: the workers take them
    with the other figures' scenes)."""
    results = []
    for task, audits in zip(tasks, runner.run_tasks(tasks)):
        spec = task.spec
        r = {"test": "energy_audit", "material": spec["material"], "size": spec["size"],
             "specific_energy": spec["energy"], "particles": len(spec["counts"]),
             "seed": spec["seed"], "options": spec["options"], "scenes_at_step_limit": 0,
             "wall_s": sum(a["wall_s"] for a in audits), **combine(audits)}
        progress(f"energy audit {r['material']} {r['specific_energy']:g} J/kg: broken "
                 f"{100 * r['sinks']['broken'] / r['e0']:.1f} %, residual "
                 f"{100 * r['sinks']['residual'] / r['e0']:+.2f} % ({r['wall_s']:.0f} s)")
        runner.results[task.key] = r
        results.append(r)
    return results


# -- the report --------------------------------------------------------------------------------
SINK_HEADER = ["material", "Ek/mp (J/kg)", "particles"] + [
    f"({letter}) {label}" if letter else label for _, letter, label in CATEGORIES] + [
    "worst residual of one particle", "(a') Ek' of breakages (excess over mE)",
    "(b) Ek' of damage", "Ek' unbreakable"]


def sink_row(r):
    """One row of the sinks (% of E0) and the counted energies (% of E0)."""
    e0 = r["e0"]

    def pct(v):
        return f"{100 * v / e0:.1f}"
    c = r["counted"]
    return ([r["material"], f"{r['specific_energy']:g}", r["particles"]]
            + [pct(r["sinks"][k]) for k, _, _ in CATEGORIES[:-1]]
            + [f"{100 * r['sinks']['residual'] / e0:+.2f}", f"{100 * r['worst_residual']:.2f}",
               f"{pct(c['breakage'])} ({pct(c['excess'])})", pct(c["damage"]),
               pct(c["unbreakable"])])


GENERATION_HEADER = ["material", "Ek/mp (J/kg)", "generation", "breakages",
                     "mass broken (% of the particles')", "taken at the breaks (% E0)",
                     "Ek' of breakages (% E0)", "above m E (% E0)", "damage Ek' (% E0)",
                     "Eq. 8 t10' at sum Ek' / sum mE (%)", "t10 made (%)"]


def generation_rows(r):
    """Per generation: what reached its bodies and the t10' Eq. 8 gives for it against the t10
    its families made."""
    mat, e0 = paper_material(r["material"]), r["e0"]
    total_mass = e0 / r["specific_energy"]
    rows = []
    for g in r["generations"]:
        made = g["t10_mass"] / g["mass"] if g["mass"] else None
        eq8 = (float(equations.t10(g["stressing"] / g["fracture"], mat.params.A, mat.params.b_prime))
               if g["fracture"] else None)
        rows.append([mat.name, f"{r['specific_energy']:g}", int(g["generation"]),
                     int(g["breakages"]), f"{100 * g['mass'] / total_mass:.1f}",
                     f"{100 * g['broken'] / e0:.2f}", f"{100 * g['stressing'] / e0:.2f}",
                     f"{100 * (g['stressing'] - g['fracture']) / e0:.2f}",
                     f"{100 * g['damage'] / e0:.2f}",
                     "-" if eq8 is None else f"{eq8:.2f}",
                     "-" if made is None else f"{made:.2f}"])
    return rows


def _plot(results, out, settings):
    plt = report.plt_module()
    fig, ax = plt.subplots(figsize=(11, 5.4))
    labels = [f"{r['material']}\n{r['specific_energy']:g} J/kg" for r in results]
    x = np.arange(len(results))
    bottom = np.zeros(len(results))
    for k, (key, letter, label) in enumerate(CATEGORIES):
        share = np.array([100 * r["sinks"][key] / r["e0"] for r in results])
        ax.bar(x, share, 0.7, bottom=bottom, color=f"C{k}",
               label=f"({letter}) {label}" if letter else label)
        bottom += share
    ax.set_xticks(x, labels, fontsize=7)
    ax.set(ylabel="share of the impact's kinetic energy (%)",
           title="Where the energy of a single impact goes (29 mm, single impacts on steel)")
    ax.legend(fontsize=7, loc="center left", bbox_to_anchor=(1.0, 0.5))
    return report.save(fig, out / "energy_audit.png", settings)


def cases(args):
    """(material, energy) of the figure: --audit-energies "target", ENERGIES where Eq. 7 (the
    model's t10 at 29 mm on steel) is at most the target's ceiling (readings.T10_CEILING %), or
    every material at each energy listed; quick: copper ore at QUICK_ENERGIES."""
    from yadebreak.criteria import load_material
    from yadebreak.studies.verify.readings import T10_CEILING
    if args.quick:
        return [("copper_ore", e) for e in QUICK_ENERGIES]
    if args.audit_energies != "target":
        return [(name, float(e)) for name in args.material_list
                for e in args.audit_energies.split(",")]
    steel = load_material("steel")
    return [(name, e) for name in args.material_list for e in ENERGIES
            if paper_material(name).t10_model(e, FRAGMENT_SIZE, steel) <= T10_CEILING]


def figure_energy(args, runner, out):
    """The energy audit of cases(args), PARTICLES particles each (quick: QUICK_PARTICLES), at
    the fragmentation figures' time step."""
    ts = args.time_step_fraction or RT_FRAGMENTATION
    options = _paper_options(args, ts)
    n = QUICK_PARTICLES if args.quick else PARTICLES
    results = audit_cases(runner, [audit_task(name, e, n, args.seed, options)
                                   for name, e in cases(args)])
    text_ = settings_text(options, args.material_list, FRAGMENT_SIZE, n, args.seed,
                          "YADE's energy tracking on (it changes no force); the particles are "
                          "the first of Fig. 16's at each energy")
    path = _plot(results, out, text_)
    table = (report.table(SINK_HEADER, [sink_row(r) for r in results]) + "\n\nPer generation:\n\n"
             + report.table(GENERATION_HEADER, [row for r in results
                                                for row in generation_rows(r)]))
    return {"name": "Where the energy of a cascade goes", "plot": path.name, "settings": text_,
            "table": table, "checks": []}
