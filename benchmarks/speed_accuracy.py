"""The speed-accuracy study of the README and docs/speed_accuracy.md, with the trade-off tool.

    /usr/bin/python3 benchmarks/speed_accuracy.py [--seeds 5] [--scheduler local:2]
        [--out out/tradeoff] [--only bed_read_dummies,mill]

Five studies, each `python3 -m yadebreak tradeoff ...` (one Dask task per run, the same seeds for
every variant): the default bed's read mode x dummy fines, its time step x stiffness scaling and
its dmin; high-energy single impacts (ab_t10_ore, 12 mm, 640 J/kg) read mode x time step; the
ball mill's stiffness scaling (0.25 s of milling). Each writes <out>/<study>/tradeoff.md,
tradeoff.csv and pareto.png; about 15 minutes on this 2-core machine with the default seeds. A
study already done in <out> is not run again (the tool's sweep.json).
"""
import argparse
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
BED = ["scripts/bed_impact.py", "--vtk-interval", "0", "--checkpoint-every", "-1"]
BED_METRICS = "broken_mass_fraction,capture_radius,breakage_events"
STUDIES = {
    "bed_read_dummies": [*BED, "--vary", "read-period=every_step,fast", "--vary",
                         "dummies=spheres,ledger", "--metrics", BED_METRICS],
    "bed_step_stiffness": [*BED, "--vary", "time-step-fraction=0.05,0.1", "--vary",
                           "stiffness-scale=1,0.1", "--metrics", BED_METRICS, "--reference",
                           "time-step-fraction=0.05,stiffness-scale=1"],
    "bed_dmin": [*BED, "--vary", "dmin=1.375e-4,2.75e-4,1.1e-3", "--metrics", BED_METRICS],
    "high_energy": ["scripts/single_impact.py", "--material", "ab_t10_ore", "--size", "0.012",
                    "--energies", "640", "--particles", "10", "--vary",
                    "read-period=every_step,fast", "--vary", "time-step-fraction=0.05,0.1",
                    "--metrics", "results.0.broken_fraction,results.0.t10_simulated",
                    "--reference", "read-period=every_step,time-step-fraction=0.05"],
    "mill": ["scripts/ball_mill.py", "--duration", "0.25", "--vtk-interval", "0",
             "--checkpoint-every", "-1", "--vary", "stiffness-scale=1e-4,1e-3", "--metrics",
             "broken_mass_fraction,breakage_events,mean_power_W,"
             "stressing_events_per_second.ball-ore"],
}


def main():
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--seeds", type=int, default=5)
    parser.add_argument("--scheduler", default="local:2")
    parser.add_argument("--out", default="out/tradeoff")
    parser.add_argument("--only", default="", help="comma-separated study names; default all")
    args = parser.parse_args()
    names = [n for n in args.only.split(",") if n] or list(STUDIES)
    for name in names:
        cmd = [sys.executable, "-m", "yadebreak", "tradeoff", *STUDIES[name], "--seeds",
               str(args.seeds), "--scheduler", args.scheduler, "--out",
               str(Path(args.out) / name)]
        print(" ".join(cmd), flush=True)
        if subprocess.run(cmd, cwd=ROOT).returncode != 0:
            sys.exit(f"{name} failed")
        print((Path(args.out) / name / "tradeoff.md").read_text(), flush=True)


if __name__ == "__main__":
    main()
