"""Speed against accuracy: what each knob costs and what it changes.

Single impacts (5.5 mm copper ore on steel, 400 J/kg): time-step fraction, stiffness scaling
(Young's moduli x1, x0.1, x0.01, ratios kept) and the contact-read mode, against the finest run
(1 % of the Rayleigh time, every contact read every step). The default bed (37 particles, 3.05 J):
time-step fraction, read mode, dummy fines as spheres or a ledger, and dmin, against the paper's
setting; each bed run stops at 4 ms of simulated time at the latest. One seed: the bed's
differences include the scatter of one stochastic run (see the sweep table for triplicates).
Writes speed_accuracy.csv, speed_accuracy.md and pareto.png into --out.

    /usr/bin/python3 scripts/speed_accuracy.py [--quick]
"""
import argparse
import csv
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(sys.argv[0]).resolve().parent.parent))

import numpy as np  # noqa: E402

from yadebreak import bed, coupling, load_material, scenes  # noqa: E402

parser = argparse.ArgumentParser(description=__doc__)
parser.add_argument("--out", default="out/speed_accuracy",
                    help="output folder; default out/speed_accuracy")
parser.add_argument("--quick", action="store_true",
                    help="fewer settings (a few minutes); default off")
args = parser.parse_args()
out = Path(args.out)
out.mkdir(parents=True, exist_ok=True)
rows = []


def single(tsf, stiffness, read, n=250, energy=400.0):
    coupling.forget()
    speed = (2 * energy) ** 0.5
    t0 = time.time()
    brk, ids = scenes.impact_scene("copper_ore", 5.5e-3, [speed] * n, seed=3, replace=False,
                                   time_step_fraction=tsf, stiffness_scale=stiffness,
                                   read_period=read)
    from yade import O
    scenes.run_until_rebound(ids)
    first = {}
    for e in brk.events:
        first.setdefault(e["id"], e)
    share = load_material("copper_ore").energy_partition(load_material("steel"))
    absorbed = [first[i]["specific_energy"] / share for i in ids
                if i in first and first[i]["kind"] == "damage"]
    broken = [first[i] for i in ids if i in first and first[i]["kind"] == "breakage"]
    return {"case": "single impact", "time_step_fraction": tsf, "stiffness_scale": stiffness,
            "read_period": read, "dummies": "-", "dmin_ratio": "-", "wall_s": time.time() - t0,
            "steps": O.iter, "broken_fraction": len(broken) / n,
            "t10_mean": _mean_t10(broken),
            "energy_error": float(np.mean(absorbed)) / energy - 1}


def _mean_t10(events):
    """Mean t10' (%, Eq. 8) of the breakage events of the original particles."""
    t10 = [e["t10"] for e in events if e["kind"] == "breakage" and e.get("generation", 0) == 0]
    return float(np.mean(t10)) if t10 else float("nan")


def bed_run(tsf, read, dummies, dmin_ratio):
    coupling.forget()
    a = argparse.Namespace(material="copper_ore", size=5.5e-3, rings=3, layers=1, energy=3.05,
                           speed=0.0, seed=1, time_step_fraction=tsf, dmin=5.5e-3 / dmin_ratio,
                           global_damping=0.0, dummies=dummies, read_period=read, max_time=0.004,
                           out=str(out / "bed"))
    brk, s = bed.run(a, quiet=True)
    sd = brk.size_distribution([1e-3, 2e-3, 4.75e-3])
    return {"case": "default bed", "time_step_fraction": tsf, "stiffness_scale": 1.0,
            "read_period": read, "dummies": dummies, "dmin_ratio": dmin_ratio,
            "wall_s": s["runtime_s"], "steps": s["steps"],
            "broken_fraction": s["broken_mass_fraction"], "t10_mean": _mean_t10(brk.events),
            "passing_1mm": sd.passing_percent[0], "passing_2mm": sd.passing_percent[1]}


singles = [(0.01, 1.0, 1), (0.02, 1.0, 1), (0.05, 1.0, 1), (0.1, 1.0, 1), (0.2, 1.0, 1),
           (0.05, 0.1, 1), (0.05, 0.01, 1), (0.05, 1.0, "auto"), (0.05, 1.0, "fast")]
# the bed's reference is the paper's setting (5 % of the Rayleigh time, every contact read, dummy
# spheres): finer time steps take hours here
beds = [(0.05, 1, "spheres", 20), (0.05, "auto", "spheres", 20), (0.05, "fast", "spheres", 20),
        (0.05, 1, "ledger", 20), (0.05, "auto", "ledger", 20), (0.05, "fast", "ledger", 20),
        (0.1, "auto", "ledger", 20), (0.05, "auto", "ledger", 5), (0.05, "auto", "ledger", 40)]
if args.quick:
    singles, beds = singles[:1] + singles[2:4] + singles[-2:], beds[4:7]
for setting in singles:
    rows.append(single(*setting))
    print(f"[yadebreak] single impact {setting}: {rows[-1]['wall_s']:.1f} s", flush=True)
for setting in beds:
    rows.append(bed_run(*setting))
    print(f"[yadebreak] bed {setting}: {rows[-1]['wall_s']:.1f} s, broken "
          f"{100 * rows[-1]['broken_fraction']:.1f} %", flush=True)

for case in ("single impact", "default bed"):
    sel = [r for r in rows if r["case"] == case]
    ref = sel[0]                                   # the finest setting of each case comes first
    for r in sel:
        r["broken_fraction_error"] = r["broken_fraction"] - ref["broken_fraction"]
        r["t10_error"] = r["t10_mean"] / ref["t10_mean"] - 1
        r["speedup_vs_finest"] = ref["wall_s"] / r["wall_s"]
keys = ["case", "time_step_fraction", "stiffness_scale", "read_period", "dummies", "dmin_ratio",
        "wall_s", "speedup_vs_finest", "steps", "broken_fraction", "broken_fraction_error",
        "t10_mean", "t10_error", "energy_error", "passing_1mm", "passing_2mm"]
with open(out / "speed_accuracy.csv", "w", newline="") as f:
    w = csv.DictWriter(f, fieldnames=keys, extrasaction="ignore")
    w.writeheader()
    w.writerows(rows)


def fmt(v):
    return f"{v:.3g}" if isinstance(v, float) else str(v)


lines = ["| " + " | ".join(keys) + " |", "|" + "---|" * len(keys)]
lines += ["| " + " | ".join(fmt(r.get(k, "")) for k in keys) + " |" for r in rows]
(out / "speed_accuracy.md").write_text("\n".join(lines) + "\n")

import matplotlib  # noqa: E402
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

fig, ax = plt.subplots(figsize=(7, 4.5))
for k, case in enumerate(("single impact", "default bed")):
    sel = [r for r in rows if r["case"] == case]
    ax.scatter([r["wall_s"] for r in sel], [100 * abs(r["broken_fraction_error"]) for r in sel],
               c=f"C{k}", label=case)
    for r in sel:
        ax.annotate(f"{r['time_step_fraction']}/{r['read_period']}/{r['dummies']}/"
                    f"{r['stiffness_scale']}", (r["wall_s"], 100 * abs(r["broken_fraction_error"])),
                    fontsize=6)
ax.set(xscale="log", xlabel="wall time (s)", ylabel="|broken fraction - finest| (points of %)",
       title="speed against accuracy (labels: dt fraction / read / dummies / stiffness)")
ax.legend()
fig.tight_layout()
fig.savefig(out / "pareto.png", dpi=110)
print(f"[yadebreak] wrote {out}/speed_accuracy.csv, speed_accuracy.md, pareto.png")
