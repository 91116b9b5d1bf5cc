"""Gather the summaries of a bed sweep into one table and the paper's Figs. 20 and 22.

    /usr/bin/python3 scripts/gather_sweep.py [--sweep out/sweep] [--out out/sweep_report]
Writes sweep.csv, sweep.md (means and standard deviations over seeds), broken_mass.png (broken
mass against bed configuration per material, like Fig. 22) and capture_radius.png (capture
radius against impact energy, like Fig. 20).
"""
import argparse
import csv
import json
from collections import defaultdict
from pathlib import Path

import numpy as np

parser = argparse.ArgumentParser(description=__doc__)
parser.add_argument("--sweep", default="out/sweep",
                    help="folder of the yade-batch runs; default out/sweep")
parser.add_argument("--out", default="out/sweep_report",
                    help="output folder; default out/sweep_report")
args = parser.parse_args()

runs = [json.loads(p.read_text()) for p in sorted(Path(args.sweep).glob("*/summary.json"))]
if not runs:
    raise SystemExit(f"no */summary.json under {args.sweep}: run the sweep first "
                     "(yade-batch -j 2 scripts/bed_sweep.table scripts/bed_impact.py)")
out = Path(args.out)
out.mkdir(parents=True, exist_ok=True)
groups = defaultdict(list)
for r in runs:
    groups[(r["material"], r["rings"], r["layers"], r["energy"])].append(r)
rows = []
for (mat, rings, layers, energy), rs in sorted(groups.items()):
    bm = np.array([r["broken_mass"] for r in rs]) * 1e3
    cr = np.array([r["capture_radius"] for r in rs]) * 1e3
    rows.append({"material": mat, "rings": rings, "layers": layers, "energy_J": energy,
                 "runs": len(rs), "broken_mass_g": bm.mean(), "broken_mass_sd": bm.std(),
                 "broken_fraction": np.mean([r["broken_mass_fraction"] for r in rs]),
                 "capture_radius_mm": cr.mean(), "capture_radius_sd": cr.std(),
                 "runtime_s": np.mean([r["runtime_s"] for r in rs])})
with open(out / "sweep.csv", "w", newline="") as f:
    w = csv.DictWriter(f, fieldnames=list(rows[0]))
    w.writeheader()
    w.writerows(rows)
lines = ["| material | rings | layers | energy (J) | runs | broken mass (g) | broken % | capture radius (mm) |",
         "|---|---|---|---|---|---|---|---|"]
lines += [f"| {r['material']} | {r['rings']} | {r['layers']} | {r['energy_J']:g} | {r['runs']} | "
          f"{r['broken_mass_g']:.3f} ± {r['broken_mass_sd']:.3f} | {100 * r['broken_fraction']:.1f} | "
          f"{r['capture_radius_mm']:.1f} ± {r['capture_radius_sd']:.1f} |" for r in rows]
(out / "sweep.md").write_text("\n".join(lines) + "\n")

import matplotlib  # noqa: E402
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

fig, ax = plt.subplots(figsize=(7, 4.5))
for k, mat in enumerate(sorted({r["material"] for r in rows})):
    sel = [r for r in rows if r["material"] == mat and abs(r["energy_J"] - 3.05) < 1e-9]
    labels = [f"{r['rings']}R x {r['layers']}L" for r in sel]
    ax.errorbar(range(len(sel)), [r["broken_mass_g"] for r in sel],
                yerr=[r["broken_mass_sd"] for r in sel], fmt="o-", c=f"C{k}", label=mat)
    ax.set_xticks(range(len(sel)), labels)
ax.set(xlabel="bed configuration (rings x layers)", ylabel="broken mass (g)",
       title="broken mass at 3.05 J (paper Fig. 22)")
ax.legend()
fig.tight_layout()
fig.savefig(out / "broken_mass.png", dpi=110)
fig, ax = plt.subplots(figsize=(6, 4.5))
for k, mat in enumerate(sorted({r["material"] for r in rows})):
    sel = [r for r in rows if r["material"] == mat and r["layers"] == 1 and r["rings"] == 3]
    ax.errorbar([r["energy_J"] for r in sel], [r["capture_radius_mm"] for r in sel],
                yerr=[r["capture_radius_sd"] for r in sel], fmt="o-", c=f"C{k}", label=mat)
ax.set(xlabel="impact energy (J)", ylabel="capture radius (mm)",
       title="capture radius, monolayer of 3 rings (paper Fig. 20)")
ax.legend()
fig.tight_layout()
fig.savefig(out / "capture_radius.png", dpi=110)
print(f"{len(runs)} runs in {len(rows)} configurations; wrote {out}/sweep.csv, sweep.md, "
      "broken_mass.png, capture_radius.png")
