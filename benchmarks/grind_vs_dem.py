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

from yadebreak.model import milling  # noqa: E402
from yadebreak.tools.grinding import (BatchGrinder, feed_masses, from_mill_run,  # noqa: E402
                                root2_classes)
from yadebreak.model.materials import load_material  # noqa: E402

parser = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
parser.add_argument("runs", nargs="+", help="SPECTRA_RUN DEM_RUN pairs")
parser.add_argument("--material", required=True)
parser.add_argument("--cells", type=int, default=120)
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


def compare(spectra_run, dem_run, material):
    """Print the comparison of one pair; returns {measure: model / DEM}."""
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
                           holdup_mass=dem["initial_mass"])
    result = grinder.run(masses, fines, np.concatenate([[0.0], times]))
    model_passing = result.passing_percent[1:]
    model_at = at_sieves(model_passing, dem_sieves, classes)
    lower = d0 / math.sqrt(2.0)
    k_lower = int(np.argmin(np.abs(dem_sieves - lower)))
    dem_left = 1.0 - dem_passing[:, k_lower] / 100.0
    model_left = 1.0 - model_at[:, k_lower] / 100.0
    print(f"spectra: {spectra_run}, {counted} stressing events in the window "
          f"({spectra.rates_per_s.sum():.4g} collisions/s); DEM: "
          f"{dem_run} ({dem['breakage_events']} breakages, window {times[-1]:.3f} s)")
    print("time s | feed class left, DEM | model | model / DEM")
    for t, a, b in list(zip(times, dem_left, model_left))[::max(1, len(times) // 10)] + [
            (times[-1], dem_left[-1], model_left[-1])]:
        print(f"{t:.3f} | {a:.4f} | {b:.4f} | {ratio(b, a):.3f}")
    s_dem, _ = milling.first_order_breakage_rate(times, dem_left)
    s_model, _ = milling.first_order_breakage_rate(times, model_left)
    print(f"first-order rate of the feed class (1/s): DEM {s_dem:.4g}, model {s_model:.4g}, "
          f"ratio {ratio(s_model, s_dem):.3f}")
    print(f"broken mass fraction (below {1e3 * lower:.3g} mm): DEM {1 - dem_left[-1]:.4f}, model "
          f"{1 - model_left[-1]:.4f}, ratio {ratio(1 - model_left[-1], 1 - dem_left[-1]):.3f}")
    out = {"rate": ratio(s_model, s_dem),
           "broken mass": ratio(1 - model_left[-1], 1 - dem_left[-1])}
    for k in (k_lower + 1, k_lower + 2, k_lower + 4):
        a, b = dem_passing[-1, k], model_at[-1, k]
        print(f"passing {1e3 * dem_sieves[k]:.4g} mm: DEM {a:.3f} %, model {b:.3f} %, ratio "
              f"{ratio(b, a):.3f}")
        out[f"passing {1e3 * dem_sieves[k]:.3g} mm"] = ratio(b, a)
    print(f"model: {result.steps} steps, {result.runtime_s:.1f} s, mass error "
          f"{result.mass_relative_error:.1e}")
    return out


material = load_material(args.material)
ratios = []
for spectra_run, dem_run in zip(args.runs[::2], args.runs[1::2]):
    ratios.append(compare(spectra_run, dem_run, material))
    print()
print(f"over {len(ratios)} pair(s): model / DEM, mean +- standard deviation (target: within 20 %)")
for key in ratios[0]:
    values = np.array([r[key] for r in ratios])
    sd = values.std(ddof=1) if len(values) > 1 else float("nan")
    print(f"  {key}: {values.mean():.3f} +- {sd:.3f} ({', '.join(f'{v:.3f}' for v in values)}); "
          f"{'within' if abs(values.mean() - 1) <= 0.2 else 'outside'} 20 %")
