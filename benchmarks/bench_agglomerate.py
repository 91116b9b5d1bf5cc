"""The bonded agglomerate's full case (issue 17): cost, the document's findings, the bond radius
multiplier's effect and the check period's trade, on the 4,104-sphere agglomerate at 4 m/s.

    /usr/bin/python3 benchmarks/bench_agglomerate.py [--particles 4104] [--duration 1e-3]
        [--lambdas 0.4,0.5,0.7] [--check-periods 4,16] [--out out/bench_agglomerate]

Runs `yade -n -x scripts/agglomerate_impact.py` once per variant, one after the other
(whole-process wall times): the default (lambda 0.6, the criterion every step), the other lambdas,
the other check periods, and a run whose criterion is read every 10,000 steps (YADE's own cost:
the scene without yadebreak's criterion). Prints and writes bench_agglomerate.md: seconds of wall
time per millisecond of impact, the share spent in the criterion (yadebreak's Python), and each
variant's broken bonds by mode, damage ratio, peak time of the bonds at >= 80 % of their tensile
strength, debris times, damaged zone and largest fragment; then the document's findings, each
checked on the default run.
"""
import argparse
import json
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def run(out, name, args, **options):
    folder = out / name
    cmd = ["yade", "-n", "-x", str(ROOT / "scripts" / "agglomerate_impact.py"), "--particles",
           str(args.particles), "--duration", repr(args.duration), "--seed", str(args.seed),
           "--vtk-interval", "0", "--out", str(folder)]
    for key, value in options.items():
        cmd += ["--" + key.replace("_", "-"), str(value)]
    start = time.time()
    proc = subprocess.run(cmd, capture_output=True, text=True)
    wall = time.time() - start
    if proc.returncode != 0:
        sys.exit(f"{name} failed:\n{proc.stderr[-3000:]}")
    summary = json.loads((folder / "summary.json").read_text())
    summary["wall_s"] = wall
    f = summary["findings"]
    print(f"{name}: wall {wall:.0f} s, impact {summary['cost']['impact_s']:.0f} s "
          f"(criterion {summary['cost']['criterion_s']:.0f} s), broken "
          f"{summary['bonds_broken_tension']}/{summary['bonds_broken_shear']}/"
          f"{summary['bonds_broken_compression']}, damage {summary['damage_ratio']:.4f}, peak "
          f"{f['peak_above80_tension_ms']:.3f} ms", flush=True)
    return summary


def row(name, s):
    f, c = s["findings"], s["cost"]
    per_ms = c["impact_s"] / (s["duration"] * 1e3)
    debris = "-" if f["debris_leaves_ms"] is None else f"{f['debris_leaves_ms']:.2f}"
    half = "-" if f["debris_half_ms"] is None else f"{f['debris_half_ms']:.2f}"
    return (f"| {name} | {s['radius_multiplier']:g} | {c['check_period']} | {s['wall_s']:.0f} | "
            f"{per_ms:.0f} | {c['criterion_s'] / c['impact_s']:.0%} | "
            f"{s['bonds_broken_tension']} / {s['bonds_broken_shear']} / "
            f"{s['bonds_broken_compression']} | {s['damage_ratio']:.4f} | "
            f"{f['peak_above80_tension_ms']:.3f} | {debris} / {half} | "
            f"{f['damaged_height']:.2f} | {f['upper_half_damaged']:.3f} | "
            f"{s['fragments']['largest_mass_fraction']:.3f} |")


def _ms(value):
    return "none" if value is None else f"{value:.3f} ms"


def findings(s):
    """The document's findings, each with what the default run measured and whether it holds."""
    f = s["findings"]
    share = f["damaged_share_by_height"]
    low = [x for x in share[:3]]
    broken = s["bonds_broken_tension"] + s["bonds_broken_shear"] + s["bonds_broken_compression"]
    checks = [
        ("damage localized at the contact, no diametral fracture",
         f"upper half damaged {f['upper_half_damaged']:.3f}, largest fragment "
         f"{s['fragments']['largest_mass_fraction']:.1%} of the mass, damaged zone up to "
         f"{f['damaged_height']:.2f} of the height",
         f["upper_half_damaged"] < 0.05 and s["fragments"]["largest_mass_fraction"] > 0.8),
        ("a cone-shaped zone: fills the section at the plane, narrows upwards",
         "damaged share by tenth of height " + ", ".join(f"{x:.2f}" for x in share[:5]),
         low[0] > 0.8 and all(a >= b - 0.05 for a, b in zip(share, share[1:]))),
        ("tension the dominant failure mode, none in compression",
         f"{s['bonds_broken_tension']} tension, {s['bonds_broken_shear']} shear, "
         f"{s['bonds_broken_compression']} compression",
         s["bonds_broken_tension"] > 0.9 * broken and s["bonds_broken_compression"] == 0),
        ("bonds at >= 80 % of the tensile strength peak around 0.26 ms",
         f"peak at {f['peak_above80_tension_ms']:.3f} ms ({f['peak_above80_tension']} bonds)",
         abs(f["peak_above80_tension_ms"] - 0.26) <= 0.1),
        ("debris leaves the fracture zone after about 0.44 ms",
         f"first sphere {_ms(f['debris_leaves_ms'])}, half the debris {_ms(f['debris_half_ms'])}",
         f["debris_half_ms"] is not None and abs(f["debris_half_ms"] - 0.44) <= 0.15),
    ]
    lines = ["| the document | measured (default run) | holds |", "|---|---|---|"]
    lines += [f"| {a} | {b} | {'yes' if ok else 'no'} |" for a, b, ok in checks]
    return lines


def main():
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--particles", type=int, default=4104)
    parser.add_argument("--duration", type=float, default=1e-3, help="s after the first touch")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--lambdas", default="0.4,0.5,0.7")
    parser.add_argument("--check-periods", default="4,16")
    parser.add_argument("--out", default="out/bench_agglomerate")
    args = parser.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    runs = [("default", run(out, "default", args))]
    runs.append(("YADE alone", run(out, "yade_alone", args, check_period=10000)))
    for p in [int(x) for x in args.check_periods.split(",") if x]:
        runs.append((f"check every {p}", run(out, f"check{p}", args, check_period=p)))
    for lam in [float(x) for x in args.lambdas.split(",") if x]:
        runs.append((f"lambda {lam:g}", run(out, f"lambda{lam:g}", args, radius_multiplier=lam)))
    default = runs[0][1]
    alone = runs[1][1]
    lines = [f"# Bonded agglomerate: {args.particles} spheres, {default['bonds_initial']} bonds, "
             f"4 m/s, {args.duration * 1e3:g} ms after the touch, seed {args.seed}", "",
             "| run | lambda | check period | wall (s) | s per ms of impact | criterion share | "
             "broken T / S / C | damage ratio | 80 % peak (ms) | debris first / half (ms) | "
             "damaged height | upper half damaged | largest fragment |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    lines += [row(name, s) for name, s in runs]
    per_ms = default["cost"]["impact_s"] / (args.duration * 1e3)
    yade_ms = alone["cost"]["impact_s"] / (args.duration * 1e3)
    lines += ["", f"Default: {per_ms:.0f} s of wall time per ms of impact; YADE alone "
              f"{yade_ms:.0f} s per ms: yadebreak's criterion {default['cost']['criterion_s']:.0f}"
              f" s of {default['cost']['impact_s']:.0f} s "
              f"({default['cost']['criterion_s'] / default['cost']['impact_s']:.0%}); "
              f"{default['cost']['criterion_s'] / default['cost']['bonds_read'] * 1e6:.2f} us per "
              f"bond read. Whole default run {default['wall_s']:.0f} s.", ""]
    lines += findings(default)
    text = "\n".join(lines)
    (out / "bench_agglomerate.md").write_text(text + "\n")
    print(text)


if __name__ == "__main__":
    main()
