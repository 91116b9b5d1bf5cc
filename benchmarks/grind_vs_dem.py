"""Measurement: the mechanistic mill model against direct breakage DEM over the DEM's window
(docs/grinding.md, Section 7), over several seeds.

    /usr/bin/python3 benchmarks/grind_vs_dem.py --material M SPECTRA_RUN DEM_RUN [SPECTRA_RUN DEM_RUN ...]

Each pair: SPECTRA_RUN, a `scripts/ball_mill.py --breakage 0` run (nothing breaks: the spectra
run), and DEM_RUN, the same mill and seed with breakage, finished or stopped early (its last
sample ends the window). The spectra run's stressing events up to the end of that window
(events.jsonl, pair types from the body ids: drum and end walls, then balls, then ore) are binned
as the mill bins them, converted (grinding.from_mill_run) and the model grinds M's feed over the
window. Prints, for each pair, the fraction of the feed left in the feed class (sizes above
feed / sqrt 2) at the DEM's sample times, the first-order rate fitted to each, the broken mass and
the passing at three sieves with their ratios; then, over the pairs, each ratio's mean and
standard deviation and whether it is within 20 %.

The DEM engine's conventions, mirrored in the model on request (BatchGrinder's options):
--t10-at threshold (every breakage's t10 at the fracture threshold, Eq. 9, as the engine breaks
a particle at the first read past its fracture energy) and --dem-dmin (progeny whose own
progeny would be finer than the DEM run's dmin never break again; stressed past their fracture
energy once, they are spread by Eq. 10, Eq. 13). --conventions runs the model four times (as
published, each convention, both) and prints one table of the ratios.

Each pair also prints how the DEM's passing at the three sieves splits between resolved spheres
(counted at their size), dummy fines (Eq. 11) and unbreakable spheres stressed past their
fracture energy (Eq. 13): the last exactly from the events, the dummy fines as the expectation
of the family sets at each breakage's t10' (the draws are not logged), resolved spheres the rest.
"""
import argparse
import csv
import json
import math
import sys
import tempfile
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(sys.argv[0]).resolve().parent.parent))

from yadebreak import model  # noqa: E402
from yadebreak.model import families, milling  # noqa: E402
from yadebreak.tools.grinding import (BatchGrinder, feed_masses, from_mill_run,  # noqa: E402
                                root2_classes)
from yadebreak.model.materials import load_material  # noqa: E402

parser = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
parser.add_argument("runs", nargs="+", help="SPECTRA_RUN DEM_RUN pairs")
parser.add_argument("--material", required=True)
parser.add_argument("--cells", type=int, default=120)
parser.add_argument("--t10-at", choices=("collision", "threshold"), default="collision",
                    help="t10 of a breakage at e_j / E (the model) or at the threshold (the DEM)")
parser.add_argument("--dem-dmin", action="store_true",
                    help="progeny finer than the DEM run's dmin allows never break again")
parser.add_argument("--conventions", action="store_true",
                    help="run the model as published, with each convention and with both")
args = parser.parse_args()
if len(args.runs) % 2:
    parser.error("give the runs in pairs: SPECTRA_RUN DEM_RUN [SPECTRA_RUN DEM_RUN ...]")

SETTLE_TIME = 0.25      # s of settling before the drum turns (mill.py): mill time = scene time - it


def window_spectra(run_dir, t_end, folder):
    """The spectra run's events with mill time <= t_end as a mill run's folder (summary.json,
    collision_spectra.csv) in `folder`, binned as mill.collision_spectra bins them."""
    run_dir = Path(run_dir)
    summary = json.loads((run_dir / "summary.json").read_text())
    n_drum = summary["bodies_start"] - summary["balls"] - summary["ore_particles"] - 2
    first_ball, first_ore = n_drum + 2, n_drum + 2 + summary["balls"]
    events = [json.loads(line) for line in open(run_dir / "events.jsonl")]
    events = [e for e in events if e.get("kind") in ("damage", "breakage", "stressing")
              and e["time"] - SETTLE_TIME <= t_end and e.get("partner", -1) >= 0]
    energy = np.array([e["specific_energy"] for e in events])
    kind = np.array(["ore-liner" if e["partner"] < first_ball else "ball-ore"
                     if e["partner"] < first_ore else "ore-ore" for e in events])
    edges = np.geomspace(energy[energy > 0].min(), energy.max() * (1 + 1e-9), 25)
    rates = {k: milling.event_spectrum(energy[kind == k], t_end, edges)[0]
             for k in ("ball-ore", "ore-ore", "ore-liner")}
    with open(Path(folder) / "collision_spectra.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["energy_low_J_per_kg", "energy_high_J_per_kg"]
                   + [f"{k}_per_s" for k in rates])
        for j in range(len(edges) - 1):
            w.writerow([edges[j], edges[j + 1]] + [rates[k][j] for k in rates])
    (Path(folder) / "summary.json").write_text(json.dumps({**summary, "simulated_time": t_end}))
    return len(events)


def at_sieves(passing, sieves, classes):
    """The model's passing (%) at the DEM's sieves, linear in ln size between its own."""
    asc = classes.sieves[::-1]
    return np.array([np.interp(np.log(sieves), np.log(asc), p[::-1], left=0.0, right=100.0)
                     for p in passing])


def ratio(a, b):
    return a / b if b else float("nan")


def dem_dmin(dem_run, dem):
    """The DEM run's dmin (m): its --dmin, or the mill's default, a third of the feed size."""
    finished = Path(dem_run) / "finished.json"
    given = 0.0
    if finished.exists():
        given = json.loads(finished.read_text())["arguments"].get("dmin", 0.0)
    return given if given > 0 else dem["size"] / 3.0


def dem_split(dem_run, material, sieves):
    """The DEM product's mass (kg) passing `sieves` (m) by origin: (resolved spheres at their
    size, dummy fines spread by Eq. 11, unbreakable spheres stressed past their fracture energy
    spread by Eq. 13, their total). Unbreakable: exact from the events; dummies: each breakage's
    family set (nearest its t10') in expectation, radii scaled as the engine scales them;
    resolved: the family sets' non-dummy spheres in expectation, less the stressed unbreakables
    at their size."""
    events = [json.loads(line) for line in open(Path(dem_run) / "events.jsonl")]
    table = families.table_for(material)
    beta = material.beta_params
    resolved, dummies = np.zeros(len(sieves)), np.zeros(len(sieves))
    for e in (e for e in events if e["kind"] == "breakage"):
        parent = 2.0 * e["radius"]
        fs = table.sets[table.nearest(e["t10"])]
        scale = fs.volumes ** (-1.0 / 3.0)                          # exact mass per family
        for counts, p, k in zip(fs.counts, fs.probabilities, scale):
            volume = counts * families.CLASS_VOLUMES * k ** 3          # parent volume units
            size = families.RELATIVE_SIZES * k * parent
            real = np.arange(families.N_CLASSES) != families.DUMMY
            passes = size[None, :] <= sieves[:, None]
            resolved += p * e["mass"] * (passes & real[None, :]) @ volume
            dummies += (p * e["mass"] * volume[families.DUMMY]
                        * model.dummy_fines_passing(sieves, parent, e["t10"], beta)[0])
    stressed = np.zeros(len(sieves))
    for e in (e for e in events if e["kind"] == "unbreakable_stressed"):
        d = 2.0 * e["radius"]
        resolved -= e["mass"] * (d <= sieves)
        stressed += e["mass"] * model.progeny_passing(e["t10"], beta, sieves / d) / 100.0
    return resolved, dummies, stressed, resolved + dummies + stressed


def dem_stressed_once(dem_run):
    """kg of unbreakable spheres the DEM stressed past their fracture energy."""
    return sum(json.loads(line)["mass"] for line in open(Path(dem_run) / "events.jsonl")
               if '"unbreakable_stressed"' in line)


def compare(spectra_run, dem_run, material, t10_at="collision", with_dmin=False, verbose=True):
    """Print the comparison of one pair; returns {measure: model / DEM}."""
    say = print if verbose else (lambda *a, **k: None)
    dem = json.loads((Path(dem_run) / "summary.json").read_text())
    with open(Path(dem_run) / "size_distribution.csv", newline="") as f:
        rows = list(csv.reader(f))
    header, table = rows[0], np.array([[float(v) for v in r] for r in rows[1:]])
    times = table[:, 0]
    with tempfile.TemporaryDirectory() as folder:
        counted = window_spectra(spectra_run, times[-1], folder)
        spectra = from_mill_run(folder)
    dem_sieves = np.array([float(h.split("_")[1][:-2]) * 1e-3 for h in header[1:]])
    dem_passing = table[:, 1:]
    d0 = dem["size"]
    classes = root2_classes(d0 * 2 ** 0.25, 16)
    masses, fines = feed_masses(classes, d0, dem["initial_mass"])
    grinder = BatchGrinder(material, spectra, classes, cells=args.cells,
                           holdup_mass=dem["initial_mass"], t10_at=t10_at,
                           progeny_dmin=dem_dmin(dem_run, dem) if with_dmin else None)
    result = grinder.run(masses, fines, np.concatenate([[0.0], times]))
    model_passing = result.passing_percent[1:]
    model_at = at_sieves(model_passing, dem_sieves, classes)
    lower = d0 / math.sqrt(2.0)
    k_lower = int(np.argmin(np.abs(dem_sieves - lower)))
    dem_left = 1.0 - dem_passing[:, k_lower] / 100.0
    model_left = 1.0 - model_at[:, k_lower] / 100.0
    say(f"spectra: {spectra_run}, {counted} stressing events in the window "
          f"({spectra.rates_per_s.sum():.4g} collisions/s); DEM: "
          f"{dem_run} ({dem['breakage_events']} breakages, window {times[-1]:.3f} s)")
    say("time s | feed class left, DEM | model | model / DEM")
    for t, a, b in list(zip(times, dem_left, model_left))[::max(1, len(times) // 10)] + [
            (times[-1], dem_left[-1], model_left[-1])]:
        say(f"{t:.3f} | {a:.4f} | {b:.4f} | {ratio(b, a):.3f}")
    s_dem, _ = milling.first_order_breakage_rate(times, dem_left)
    s_model, _ = milling.first_order_breakage_rate(times, model_left)
    say(f"first-order rate of the feed class (1/s): DEM {s_dem:.4g}, model {s_model:.4g}, "
          f"ratio {ratio(s_model, s_dem):.3f}")
    say(f"broken mass fraction (below {1e3 * lower:.3g} mm): DEM {1 - dem_left[-1]:.4f}, model "
          f"{1 - model_left[-1]:.4f}, ratio {ratio(1 - model_left[-1], 1 - dem_left[-1]):.3f}")
    out = {"rate": ratio(s_model, s_dem),
           "broken mass": ratio(1 - model_left[-1], 1 - dem_left[-1])}
    for k in (k_lower + 1, k_lower + 2, k_lower + 4):
        a, b = dem_passing[-1, k], model_at[-1, k]
        say(f"passing {1e3 * dem_sieves[k]:.4g} mm: DEM {a:.3f} %, model {b:.3f} %, ratio "
              f"{ratio(b, a):.3f}")
        out[f"passing {1e3 * dem_sieves[k]:.3g} mm"] = ratio(b, a)
    say(f"model ({t10_at}{', dmin' if with_dmin else ''}): {result.steps} steps, "
        f"{result.runtime_s:.1f} s, mass error {result.mass_relative_error:.1e}, stressed once "
        f"(unbreakable) {100 * result.once_broken[-1] / result.initial_mass:.2f} % of the charge "
        f"(DEM {100 * dem_stressed_once(dem_run) / dem['initial_mass']:.2f} %)")
    # the DEM's passing by origin; the families' sphere sizes 2^(-k/4) d0 fall on its root-2
    # sieves: a sphere of class k stands for the mass between 2^(-k/4) and 2^(-(k-1)/4) d0 (Eq.
    # 10's mass retained on the sieve 2^(-k/4) d0) but sits on that sieve, so read at 0.99 x
    # sieve the expectation counts it retained, as Eq. 10 (and the model) does
    picked = [k_lower, k_lower + 1, k_lower + 2, k_lower + 4]
    sieves = dem_sieves[picked]
    split = dem_split(dem_run, material, sieves)
    finer, coarser = (dem_split(dem_run, material, sieves * f)[3] for f in (0.99, 1.01))
    total = 100.0 / dem["initial_mass"]
    say("DEM passing by origin, % of the charge: sieve mm | resolved spheres | dummy fines "
        "(Eq. 11) | unbreakables stressed (Eq. 13) | sum (expected) | DEM | expected at "
        "0.99 / 1.01 x sieve")
    for k, (s, idx) in enumerate(zip(sieves, picked)):
        say(f"{1e3 * s:.4g} | {total * split[0][k]:.3f} | {total * split[1][k]:.3f} | "
            f"{total * split[2][k]:.3f} | {total * split[3][k]:.3f} | "
            f"{dem_passing[-1, idx]:.3f} | {total * finer[k]:.3f} / {total * coarser[k]:.3f}")
    retained = {"broken mass": ratio(100.0 - 100.0 * model_left[-1], total * finer[0])}
    for k, idx in enumerate(picked[1:], start=1):
        retained[f"passing {1e3 * dem_sieves[idx]:.3g} mm"] = ratio(model_at[-1, idx],
                                                                   total * finer[k])
    # the same at the model's own sieves (no interpolation between them): the feed class's
    # lower sieve and three finer ones
    own = classes.sieves[[1, 2, 3, 5]]
    dem_own = total * dem_split(dem_run, material, own * 0.99)[3]
    model_own = result.passing_percent[-1, [1, 2, 3, 5]]
    say("at the model's sieves, mm | DEM (expected, spheres on a sieve retained) | model: "
        + ", ".join(f"{1e3 * s:.3g} | {a:.3f} | {b:.3f}" for s, a, b in zip(own, dem_own,
                                                                              model_own)))
    at_own = {f"passing {1e3 * s:.3g} mm": ratio(b, a) for s, a, b in zip(own, dem_own, model_own)}
    return {"as read": out, "retained": retained, "own sieves": at_own}


def summary(ratios):
    """Each ratio's mean +- sd over the pairs."""
    out = {}
    for key in ratios[0]:
        values = np.array([r[key] for r in ratios])
        sd = values.std(ddof=1) if len(values) > 1 else float("nan")
        out[key] = (values.mean(), sd, values)
    return out


def print_table(rows, title):
    """One line per model variant: each ratio's mean +- sd over the pairs."""
    keys = list(next(iter(rows.values())))
    print(title)
    print("model | " + " | ".join(keys))
    for name, row in rows.items():
        print(name + " | " + " | ".join(f"{m:.2f} +- {sd:.2f}" for m, sd, _ in row.values()))


material = load_material(args.material)
pairs = list(zip(args.runs[::2], args.runs[1::2]))
if args.conventions:
    variants = [("as published", "collision", False), ("t10 at threshold", "threshold", False),
                ("dmin rule", "collision", True), ("both", "threshold", True)]
    tables = {"as read": {}, "retained": {}, "own sieves": {}}
    for name, t10_at, with_dmin in variants:
        runs = [compare(s, d, material, t10_at, with_dmin, verbose=False) for s, d in pairs]
        for reading, rows in tables.items():
            rows[name] = summary([r[reading] for r in runs])
    print_table(tables["as read"], f"model / DEM over {len(pairs)} pair(s), mean +- standard "
                "deviation, the DEM as its size_distribution.csv reads")
    print()
    print_table(tables["retained"], "the DEM read with every resolved sphere retained on the "
                "sieve it sits on (the families' expectation at 0.99 x sieve), window's end")
    print()
    print_table(tables["own sieves"], "the same at the model's own sieves (no interpolation)")
    sys.exit(0)
runs = []
for spectra_run, dem_run in pairs:
    runs.append(compare(spectra_run, dem_run, material, args.t10_at, args.dem_dmin))
    print()
print(f"over {len(runs)} pair(s): model / DEM, mean +- standard deviation (target: within 20 %)")
for key, (mean, sd, values) in summary([r["as read"] for r in runs]).items():
    print(f"  {key}: {mean:.3f} +- {sd:.3f} ({', '.join(f'{v:.3f}' for v in values)}); "
          f"{'within' if abs(mean - 1) <= 0.2 else 'outside'} 20 %")
for reading, title in (("retained", "the DEM read with every resolved sphere retained on the "
                        "sieve it sits on"), ("own sieves", "the same at the model's sieves")):
    print(f"against {title}:")
    for key, (mean, sd, values) in summary([r[reading] for r in runs]).items():
        print(f"  {key}: {mean:.3f} +- {sd:.3f} ({', '.join(f'{v:.3f}' for v in values)})")
