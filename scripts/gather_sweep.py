"""Gather the summaries of a bed sweep into one table and the paper's Figs. 20 and 22.

The bed's own report; `python3 -m yadebreak gather TABLE --out DIR` (or the end of `python3 -m
yadebreak sweep`) writes the generic DIR/sweep.csv, every summary.json flattened.

    /usr/bin/python3 scripts/gather_sweep.py [--sweep out/sweep] [--out out/sweep_report]
                                             [--table scripts/bed_sweep.table]
A partial sweep is gathered as far as it went: runs without summary.json, or that ended in an
error or were interrupted (summary.json's end_reason), are listed as unfinished.
Writes sweep.csv, sweep.md (means and standard deviations over seeds), broken_mass.png (broken
mass against bed configuration per material, like Fig. 22) and capture_radius.png (capture
radius against impact energy, like Fig. 20).
"""
import argparse
import csv
import json
import sys
from collections import defaultdict
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
from yadebreak import sweep as sweep_tables  # noqa: E402
from yadebreak.reports import bounded_errors  # noqa: E402

parser = argparse.ArgumentParser(description=__doc__)
parser.add_argument("--sweep", default="out/sweep",
                    help="folder of the yade-batch runs; default out/sweep")
parser.add_argument("--out", default="out/sweep_report",
                    help="output folder; default out/sweep_report")
parser.add_argument("--table", default="",
                    help="the sweep's yade-batch table, to list its lines not run yet; default none")
args = parser.parse_args()


def read_table(path):
    """The descriptions (output folder names) of a yade-batch table's lines."""
    try:
        return [line.description for line in sweep_tables.read_table(path)]
    except sweep_tables.SweepError as exc:
        raise SystemExit(f"--table: {exc}") from None


def gather(sweep, expected):
    """(finished runs' summaries, unfinished lines with why): a partial sweep is gathered as far
    as it went."""
    runs, unfinished = [], []
    folders = {p.name: p for p in Path(sweep).iterdir() if p.is_dir()} if Path(sweep).is_dir() else {}
    for name in sorted(set(folders) | set(expected)):
        path = folders.get(name, Path(sweep) / name) / "summary.json"
        if not path.exists():
            unfinished.append((name, "not run" if name not in folders else "no summary.json"))
            continue
        summary = json.loads(path.read_text())
        reason = summary.get("end_reason", "finished")
        if reason in ("finished", "time_limit"):
            runs.append(summary)
        else:
            unfinished.append((name, f"{reason}: {summary.get('end_message', '')}"))
    return runs, unfinished


runs, unfinished = gather(args.sweep, read_table(args.table) if args.table else [])
for name, why in unfinished:
    print(f"unfinished: {name} ({why})")
if not runs:
    raise SystemExit(f"no finished run under {args.sweep}: run the sweep first "
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
at_305 = [r for r in rows if abs(r["energy_J"] - 3.05) < 1e-9]
configs = sorted({(r["rings"], r["layers"]) for r in at_305}, key=lambda c: (c[1], c[0]))
for k, mat in enumerate(sorted({r["material"] for r in at_305})):
    sel = sorted((r for r in at_305 if r["material"] == mat),
                 key=lambda r: configs.index((r["rings"], r["layers"])))
    mass = [r["broken_mass_g"] for r in sel]
    ax.errorbar([configs.index((r["rings"], r["layers"])) for r in sel], mass,
                yerr=bounded_errors(mass, [r["broken_mass_sd"] for r in sel]), fmt="o-",
                c=f"C{k}", label=mat)
ax.set_xticks(range(len(configs)), [f"{rings}R x {layers}L" for rings, layers in configs])
ax.set(xlabel="bed configuration (rings x layers)", ylabel="broken mass (g)",
       title="broken mass at 3.05 J (paper Fig. 22)")
ax.legend()
fig.tight_layout()
fig.savefig(out / "broken_mass.png", dpi=110)
fig, ax = plt.subplots(figsize=(6, 4.5))
for k, mat in enumerate(sorted({r["material"] for r in rows})):
    sel = [r for r in rows if r["material"] == mat and r["layers"] == 1 and r["rings"] == 3]
    radius = [r["capture_radius_mm"] for r in sel]
    ax.errorbar([r["energy_J"] for r in sel], radius,
                yerr=bounded_errors(radius, [r["capture_radius_sd"] for r in sel]), fmt="o-",
                c=f"C{k}", label=mat)
ax.set(xlabel="impact energy (J)", ylabel="capture radius (mm)",
       title="capture radius, monolayer of 3 rings (paper Fig. 20)")
ax.legend()
fig.tight_layout()
fig.savefig(out / "capture_radius.png", dpi=110)
print(f"{len(runs)} runs in {len(rows)} configurations"
      + (f" ({len(unfinished)} unfinished, listed above)" if unfinished else "")
      + f"; wrote {out}/sweep.csv, sweep.md, broken_mass.png, capture_radius.png")
