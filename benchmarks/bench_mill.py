"""The mill's trade of speed for accuracy (issue 15, item 2): stiffness scaling and the smallest
resolved fragment against breakage and run time, on the default mill of scripts/ball_mill.py.

    /usr/bin/python3 benchmarks/bench_mill.py [--duration 1] [--seed 1] [--out out/bench_mill]
        [--variants "1e-4:3,1e-3:3,1e-2:3,1e-3:6"]

Each variant is stiffness_scale:ratio, ratio = the feed size over dmin (3: fragments down to a
third of the feed, the script's default). Runs `yade -n -x scripts/ball_mill.py` once per variant
(one after the other: whole-process wall times), then prints and writes a table (time step at the
start and at the end, simulated seconds per wall hour, breakage events, broken mass, the feed's
breakage rate, mean power) and a plot. One seed: breakage counts of ten or so differ by their own
Poisson noise (sqrt(n)) between variants that are physically the same; the table says so.
"""
import argparse
import json
import math
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
FIELDS = ("stiffness_scale", "dmin_ratio", "initial_dt", "final_dt", "throughput_s_per_hour",
          "wall_s", "breakage_events", "broken_mass_fraction", "feed_breakage_rate",
          "mean_power_W", "damage_events")


def main():
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--duration", type=float, default=1.0, help="s of milling; default 1")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--variants", default="1e-4:3,1e-3:3,1e-2:3,1e-3:6")
    parser.add_argument("--out", default="out/bench_mill")
    args = parser.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    rows = []
    for variant in args.variants.split(","):
        scale, ratio = variant.split(":")
        folder = out / f"k{scale}_d{ratio}"
        dmin = 8e-3 / float(ratio)
        start = time.time()
        proc = subprocess.run(["yade", "-n", "-x", str(ROOT / "scripts" / "ball_mill.py"),
                               "--stiffness-scale", scale, "--dmin", repr(dmin), "--duration",
                               repr(args.duration), "--seed", str(args.seed), "--vtk-interval",
                               "0", "--out", str(folder)], capture_output=True, text=True)
        wall = time.time() - start
        if proc.returncode != 0:
            sys.exit(f"{variant} failed:\n{proc.stderr[-2000:]}")
        s = json.loads((folder / "summary.json").read_text())
        row = {**{k: s.get(k) for k in FIELDS}, "stiffness_scale": float(scale),
               "dmin_ratio": float(ratio), "wall_s": wall}
        rows.append(row)
        print(" ".join(f"{k}={row[k]:.4g}" for k in FIELDS), flush=True)
    lines = ["| stiffness scale | feed / dmin | dt start (s) | dt end (s) | simulated s per wall h "
             "| wall (s) | breakages (+- sqrt) | broken (%) | S feed (1/s) | power (W) |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['stiffness_scale']:g} | {r['dmin_ratio']:g} | {r['initial_dt']:.3g} "
                     f"| {r['final_dt']:.3g} | {r['throughput_s_per_hour']:.1f} | {r['wall_s']:.0f}"
                     f" | {r['breakage_events']} +- {math.sqrt(r['breakage_events']):.1f} "
                     f"| {100 * r['broken_mass_fraction']:.2f} | {r['feed_breakage_rate']:.2g} "
                     f"| {r['mean_power_W']:.1f} |")
    table = "\n".join(lines)
    print(table)
    (out / "bench_mill.md").write_text(table + "\n")
    (out / "bench_mill.json").write_text(json.dumps(rows, indent=2))
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6.5, 4.5))
    for k, r in enumerate(rows, start=1):
        n = r["breakage_events"]
        ax.errorbar(r["throughput_s_per_hour"], n, yerr=[[min(math.sqrt(n), n)], [math.sqrt(n)]],
                    fmt="o", c=f"C{k - 1}",
                    label=f"{k}: stiffness x {r['stiffness_scale']:g}, dmin = feed / "
                          f"{r['dmin_ratio']:g}")
        ax.annotate(str(k), (r["throughput_s_per_hour"], n), textcoords="offset points",
                    xytext=(6, 4))
    ax.set(xscale="log", xlabel="simulated seconds per wall hour",
           ylabel=f"breakage events in {args.duration:g} s (+- sqrt(n))",
           title="the mill's speed against its breakage")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out / "bench_mill.png", dpi=110)
    print(f"wrote {out / 'bench_mill.md'} and {out / 'bench_mill.png'}")


if __name__ == "__main__":
    main()
