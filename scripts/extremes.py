"""The stability matrix (issue 7): every input at its extremes, and what each run must satisfy.

For each case: no NaN or infinity in any body or event; mass (spheres plus ledger) conserved to
1e-9; no fragment leaving faster than its parent's rigid velocity field (|v| + 2 |w| r); no kinetic
energy created (no gravity: the contact law only stores and dissipates); and the run ending (no
collision left). Prints a table and writes extremes.md, extremes.csv and extremes.json into --out.
Exit status 1 if any case fails. tests/test_extremes.py runs a fast subset of the same cases.

    /usr/bin/python3 scripts/extremes.py [--fast] [--only "sigma"]
"""
import argparse
import csv
import json
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(sys.argv[0]).resolve().parent.parent))   # yade sets argv[0]

from yadebreak.tools.options import progress  # noqa: E402

parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
parser.add_argument("--out", default="out/extremes", help="output folder; default out/extremes")
parser.add_argument("--fast", action="store_true",
                    help="the test suite's particle counts; default off")
parser.add_argument("--only", default="",
                    help="run the cases whose name contains this text; default all cases")
args, _ = parser.parse_known_args()

from yadebreak.runs import extremes  # noqa: E402

out = Path(args.out)
out.mkdir(parents=True, exist_ok=True)
rows = []
start = time.time()
for case in extremes.cases():
    if args.only and args.only not in case.name:
        continue
    r = extremes.run_case(case, fast=args.fast)
    rows.append(r)
    progress(f"{case.name}: {'ok' if r['ok'] else 'FAILED'}, {r['breakages']} breakages, "
             f"{r['steps']} steps, {r['wall_s']:.1f} s")

header = ("| case | particles | breakages | most in one step | steps | ended | finite | mass error "
          "| fragment speed margin (m/s) | kinetic energy before, after (J) | warnings | wall (s) | ok |")
lines = [header, "|" + "---|" * 13]
for r in rows:
    margin = "-" if r["fragment_speed_excess"] == float("-inf") else f"{r['fragment_speed_excess']:.1e}"
    lines.append(f"| {r['case']} | {r['particles']} | {r['breakages']} | {r['max_breakages_one_step']} "
                 f"| {r['steps']} | {'yes' if r['ended'] else 'NO'} | {'yes' if r['finite'] else 'NO'} "
                 f"| {r['mass_error']:.1e} | {margin} | {r['kinetic_before']:.3g}, {r['kinetic_after']:.3g} "
                 f"| {', '.join(r['warnings']) or '-'} "
                 f"| {r['wall_s']:.1f} | {'yes' if r['ok'] else 'NO'} |")
table = "\n".join(lines)
print(table)
(out / "extremes.md").write_text(table + "\n")
with open(out / "extremes.csv", "w", newline="") as f:
    writer = csv.DictWriter(f, fieldnames=list(rows[0]))
    writer.writeheader()
    for r in rows:
        writer.writerow({k: (";".join(v) if isinstance(v, list) else v) for k, v in r.items()})
(out / "extremes.json").write_text(json.dumps(rows, indent=2))
failed = [r["case"] for r in rows if not r["ok"]]
progress(f"{len(rows) - len(failed)} of {len(rows)} cases ok in {time.time() - start:.0f} s; "
         f"wrote {out / 'extremes.md'}" + (f"; FAILED: {failed}" if failed else ""))
sys.exit(1 if failed else 0)
