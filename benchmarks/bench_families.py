"""Benchmark: build time of one material's family table and the cost of one draw.

    /usr/bin/python3 benchmarks/bench_families.py
"""
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(sys.argv[0]).resolve().parent.parent))

import numpy as np  # noqa: E402

from yadebreak.model import families  # noqa: E402
from yadebreak import load_material  # noqa: E402

for name in ("copper_ore", "limestone", "granulite", "iron_ore_1"):
    mat = load_material(name)
    seconds = families.build_time(mat.beta_params, mat.t10_min, mat.params.A)
    table = families.FamilyTable(mat.beta_params, mat.t10_min, mat.params.A)
    rng = np.random.default_rng(0)
    t10 = rng.uniform(mat.t10_min, mat.params.A, 20000)
    start = time.perf_counter()
    for t in t10:
        table.draw(rng, t)
    per_draw = (time.perf_counter() - start) / len(t10)
    sizes = [len(f.relative_sizes) for f in (table.draw(rng, t) for t in t10[:2000])]
    print(f"{name:11s} table of {len(table.sets)} sets built in {seconds:.2f} s (cached after); "
          f"one draw {1e6 * per_draw:.1f} us; spheres per family {min(sizes)}-{max(sizes)} "
          f"(median {int(np.median(sizes))})")
