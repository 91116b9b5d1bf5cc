"""Measurement: the t10 that the paper's rebuild of the fines (Eqs. 11-12, Gaudin-Schuhmann below
the dummy size) gives a breakage of t10', against t10' itself (Eq. 10), for each material: the
expected value over the family set of that t10' (each family's resolved spheres at their sizes,
its dummies spread by Eqs. 11-12, or by Eq. 10 for comparison), docs/verification.md.

    /usr/bin/python3 benchmarks/fines_rebuild.py [--materials copper_ore,granulite,limestone]
        [--t10 2,4,10,25,50]
"""
import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(sys.argv[0]).resolve().parent.parent))

from yadebreak.model import families  # noqa: E402
from yadebreak.criteria import load_material  # noqa: E402


def rebuilt_t10(fset, beta_params, fines):
    """Probability-weighted t10 (%) of the families of `fset` with their dummies spread by
    `fines` ("gaudin_schuhmann" or "eq10"); sizes relative to the parent's."""
    return sum(p * families.family_passing(counts, fset.t10, beta_params, [0.1], fines)[0]
               for counts, p in zip(fset.counts, fset.probabilities))


parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
parser.add_argument("--materials", default="copper_ore,granulite,limestone")
parser.add_argument("--t10", default="2,4,10,25,50", help="t10' values (%%), comma-separated")
args = parser.parse_args()
print("material | t10' set (%) | t10 rebuilt by Eqs. 11-12 | ratio | by Eq. 10 | ratio")
for name in args.materials.split(","):
    mat = load_material(name)
    table = families.table_for(mat)
    for t in (float(v) for v in args.t10.split(",")):
        if not mat.t10_min <= t <= mat.params.A:
            continue
        fset = table.sets[table.nearest(t)]
        gs, e10 = (rebuilt_t10(fset, mat.beta_params, f) for f in ("gaudin_schuhmann", "eq10"))
        print(f"{name} | {fset.t10:.2f} | {gs:.2f} | {gs / fset.t10:.3f} | {e10:.2f} | "
              f"{e10 / fset.t10:.3f}")
