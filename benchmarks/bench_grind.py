"""Measurement: the mechanistic mill model (yadebreak.studies.grinding) on synthetic spectra
(docs/grinding.md, Section 7).

    /usr/bin/python3 benchmarks/bench_grind.py [--material copper_ore] [--minutes 10]

Prints (1) the initial breakage rate (net, 1/min) of single-size feeds from 0.1 to 16 mm for
25 and 40 mm balls (synthetic spectra, same mill and power): the maximum against size and its
shift with ball size; (2) a 5.5 mm feed ground for --minutes with 25 mm balls: the top class
left against time beside first order at the initial rate, with and without damage; (3) the
wall time of that integration (the cost of minutes of grinding).
"""
import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(sys.argv[0]).resolve().parent.parent))

from yadebreak.studies.grinding import (BatchGrinder, feed_masses, root2_classes,  # noqa: E402
                                synthetic_spectra)
from yadebreak.criteria import load_material  # noqa: E402

parser = argparse.ArgumentParser(description=__doc__)
parser.add_argument("--material", default="copper_ore")
parser.add_argument("--minutes", type=float, default=10.0)
args = parser.parse_args()
material = load_material(args.material)

print("(1) initial breakage rate (1/min) of a single-size feed")
sizes_mm = [0.1, 0.2, 0.5, 1.0, 2.0, 4.0, 8.0, 16.0]
print("ball mm | " + " | ".join(f"{d:g} mm" for d in sizes_mm))
for ball_mm in (25, 40):
    spectra = synthetic_spectra(ball_mm * 1e-3)
    rates = []
    for d_mm in sizes_mm:
        classes = root2_classes(d_mm * 1e-3 * 2 ** 0.25, 4)
        grinder = BatchGrinder(material, spectra, classes, cells=60)
        masses, fines = feed_masses(classes, d_mm * 1e-3, spectra.ore_mass_kg)
        rates.append(60 * grinder.initial_rates(masses, fines, net=True)[0])
    print(f"{ball_mm} | " + " | ".join(f"{r:.3g}" for r in rates))

print(f"\n(2) 5.5 mm feed, 25 mm balls, {args.minutes:g} min: fraction left in the top class")
spectra = synthetic_spectra(25e-3)
classes = root2_classes(5.5e-3 * 2 ** 0.25, 16)
masses, fines = feed_masses(classes, 5.5e-3, spectra.ore_mass_kg)
times = np.linspace(0.0, args.minutes * 60.0, 6)
walls = {}
results = {}
for damage in (True, False):
    grinder = BatchGrinder(material, spectra, classes, damage=damage)
    start = time.time()
    results[damage] = grinder.run(masses, fines, times)
    walls[damage] = time.time() - start
s0 = grinder.initial_rates(masses, fines, net=True)[0]
print("minutes | first order at S0 | model, damage | model, no damage")
for k, t in enumerate(times):
    print(f"{t / 60:g} | {np.exp(-s0 * t):.4f} | "
          f"{results[True].masses[k, 0] / masses[0]:.4f} | "
          f"{results[False].masses[k, 0] / masses[0]:.4f}")
r = results[True]
print(f"\n(3) wall time, {args.minutes:g} min of grinding, 16 classes x 120 cells: "
      f"{walls[True]:.1f} s with damage ({r.steps} steps), {walls[False]:.1f} s without; "
      f"mass error {r.mass_relative_error:.1e}; collision energy "
      f"{r.collision_energy_J_per_kg[-1] / 3600:.3g} kWh/t")
