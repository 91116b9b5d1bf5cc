"""The bed sweep's report: its runs gathered by configuration, and the paper's Figs. 20-23.

    /usr/bin/python3 scripts/gather_sweep.py [--sweep out/sweep] [--out out/sweep_report]
                                             [--table scripts/bed_sweep.table]

Writes configurations.csv, configurations.md and the figures (yadebreak.studies.bed_report;
docs/outputs.md). The sweep's own sweep.csv, a row per table line, is written by `python3 -m
yadebreak sweep` or `python3 -m yadebreak gather`.
"""
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
from yadebreak.studies.bed_report import report  # noqa: E402
from yadebreak.options.flags import ScriptParser, out_option, read_params  # noqa: E402

parser = ScriptParser(description=__doc__)
parser.add_argument("--sweep", default="out/sweep",
                    help="folder of the yade-batch runs; default out/sweep")
parser.add_argument("--out", default="out/sweep_report",
                    help="output folder; default out/sweep_report")
parser.add_argument("--table", default="",
                    help="the sweep's yade-batch table, to list its lines not run yet; default none")
args = read_params(parser.parse_args(), [out_option("out/sweep_report")])
print(report(args.sweep, args.out, args.table))
