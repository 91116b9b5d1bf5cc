"""Benchmark: the time of `python3 -m yadebreak fit` on the example data (all four kinds), with
profile-likelihood intervals and with bootstrap intervals, median of --repeat runs in this process;
with --coverage N, also the coverage of the fracture-energy fit's 95 % intervals over N data sets
per Tavares material (the design of tests/test_calibration.py) and its time per fit.

    /usr/bin/python3 benchmarks/bench_calibration.py [--repeat 3] [--replicates 100] [--coverage 25]
"""
import argparse
import math
import statistics
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(sys.argv[0]).resolve().parent.parent))

import numpy as np  # noqa: E402

from yadebreak import load_material  # noqa: E402
from yadebreak.studies.calibration import bootstrap, data, examples, fit_all, fracture  # noqa: E402

EXAMPLES = Path(__file__).resolve().parent.parent / "docs" / "examples" / "calibration"

p = argparse.ArgumentParser()
p.add_argument("--repeat", type=int, default=3)
p.add_argument("--replicates", type=int, default=100)
p.add_argument("--coverage", type=int, default=0, help="data sets per material (0: none)")
a = p.parse_args()
base = load_material("copper_ore")
tables = {kind: data.concat(ts) for kind, ts in
          data.read_tables(sorted(EXAMPLES.glob("*.csv"))).items()}
rows = sum(len(t) for t in tables.values())
fits, boots = [], []
for _ in range(a.repeat):
    t0 = time.perf_counter()
    cal = fit_all(tables, "tavares", base)
    fits.append(time.perf_counter() - t0)
    t0 = time.perf_counter()
    _, failed = bootstrap(tables, "tavares", base, a.replicates, seed=1, near=cal)
    boots.append(time.perf_counter() - t0)
print(f"example data: {', '.join(f'{k} {len(t)} rows' for k, t in tables.items())} ({rows} rows)")
print(f"full fit with profile-likelihood intervals: median {statistics.median(fits):.2f} s "
      f"(runs {', '.join(f'{v:.2f}' for v in fits)})")
print(f"bootstrap, {a.replicates} replicates of every fit: median {statistics.median(boots):.1f} s "
      f"({statistics.median(boots) / a.replicates * 1e3:.0f} ms a replicate; {failed} failed)")

if a.coverage:
    names = ("e_inf", "d0", "phi", "sigma")
    hits, reps, t0 = dict.fromkeys(names, 0), 0, time.process_time()
    for k, name in enumerate(("copper_ore", "granulite", "limestone_2", "iron_ore_1")):
        mat = load_material(name)
        tp = mat.params
        truth = {"e_inf": tp.e_inf, "d0": tp.d0 * 1e3, "phi": tp.phi, "sigma": tp.sigma}
        rng = np.random.default_rng(1000 + k)
        for _ in range(a.coverage):
            rows = np.array(examples.fracture_rows(mat, rng, (2.0, 5.0, 12.0, 30.0), 40,
                                                   cap_quantile=0.95))
            table = data.Table(name, "fracture", {"size": rows[:, 0], "energy": rows[:, 1],
                                                  "broken": rows[:, 2]},
                               np.arange(len(rows)) + 2, {})
            est = fracture.fit_fracture(table, fracture.Device(mat.hertz_stiffness),
                                        {"emax_ratio": mat.params.emax_ratio}).result.estimates
            for n in names:
                hits[n] += est[n].lo <= truth[n] <= est[n].hi
            reps += 1
    cpu = time.process_time() - t0
    sd = math.sqrt(0.95 * 0.05 / reps)
    print(f"fracture-energy 95 % intervals over {reps} data sets (4 classes x 40 particles): "
          + ", ".join(f"{n} {100 * h / reps:.0f} %" for n, h in hits.items())
          + f" (binomial sd {100 * sd:.1f} %); {cpu / reps:.2f} s CPU a fit")
