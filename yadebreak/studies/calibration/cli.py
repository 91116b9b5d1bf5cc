"""`python3 -m yadebreak fit DATA... --out DIR [--name NAME] [--model tavares|ab_t10]
[--base MATERIAL] [--bootstrap N] [--seed N]`: a material file from laboratory data.

Bad data stop with one line naming the file, the line and the column (or the parameter and why),
exit code 2, and nothing is written. Model layer: no YADE."""
from __future__ import annotations

import sys
import time
from pathlib import Path

from yadebreak.model.intervals import Interval, elastic_wave_speed
from yadebreak.model.materials import MaterialError
from yadebreak.criteria import load_material
from yadebreak.jobs.lifecycle import write_atomic
from yadebreak.jobs.lifecycle import tool_run
from yadebreak.options.flags import (COMMON, ScriptParser, add_params, fail, out_option,
                                     overwrite_option, read_params)
from yadebreak.studies.calibration import data, outputs
from yadebreak.studies.calibration.fit import apply_bootstrap, bootstrap, fit_all
from yadebreak.studies.calibration.mle import FitError

def parser():
    p = ScriptParser(prog="yadebreak fit", description=(
        "Fit a material to laboratory data (CSV files; the kind of each is told from its "
        "columns: docs/calibration.md)."))
    p.add_argument("data", nargs="+", help="CSV files: fracture energies, t10, repeated impacts, "
                   "progeny")
    p.add_argument("--out", required=True, help="output folder")
    p.add_argument("--name", default="fitted", help="name of the material (and of NAME.toml)")
    p.add_argument("--model", default="tavares", choices=("tavares", "ab_t10"),
                   help="breakage model (default tavares)")
    p.add_argument("--base", default=None, help="material giving the elastic and contact data "
                   "and every parameter the data do not fit")
    p.add_argument("--bootstrap", default="0", help="bootstrap replicates for the intervals "
                   "(0: profile likelihood; default 0)")
    p.add_argument("--seed", default="1", help="seed of the bootstrap resampling (default 1)")
    add_params(p, [overwrite_option(), *COMMON])
    return p


def _whole(text, option, lo):
    if not text.isdigit() or int(text) < lo:
        fail(f"--{option} = {text}: must be a whole number >= {lo}")
    return int(text)


def main(argv=None):
    args = parser().parse_args(sys.argv[1:] if argv is None else argv)
    read_params(args, [out_option(None), overwrite_option(), *COMMON])
    replicates = _whole(args.bootstrap, "bootstrap", 0)
    seed = _whole(args.seed, "seed", 0)
    if not args.name.replace("_", "").replace("-", "").isalnum():
        fail(f"--name = {args.name!r}: letters, digits, '_' and '-' only (it names the file)")
    try:
        with tool_run(args.out, args):
            return run(args, replicates, seed)
    except (data.DataError, FitError, MaterialError) as exc:
        if args.debug:
            raise
        fail(str(exc).replace("\n", " "))


def run(args, replicates, seed):
    start = time.perf_counter()
    base = load_material(args.base) if args.base else None
    by_kind = data.read_tables(args.data)
    if base is not None:                  # its own wave speed bounds the impact energies
        speed = elastic_wave_speed(base.young_modulus, base.density)
        for table in (t for ts in by_kind.values() for t in ts if "energy" in t.columns):
            data.within(table, "energy", Interval(0.0, 0.5 * speed ** 2, True, True), "J/kg",
                        f": v = sqrt(2 Ek/mp) must stay below the elastic wave speed sqrt(E/rho) "
                        f"of --base {base.name}, {speed:.4g} m/s")
    tables = {kind: data.concat(ts) for kind, ts in by_kind.items()}
    cal = fit_all(tables, args.model, base)
    timings = {"fit with profile intervals": time.perf_counter() - start}
    if replicates:
        t0 = time.perf_counter()
        intervals, failed = bootstrap(tables, args.model, base, replicates, seed,
                                      say=lambda m: print(f"[yadebreak] {m}", flush=True),
                                      near=cal)
        apply_bootstrap(cal, intervals, replicates)
        timings[f"bootstrap ({replicates} replicates, {failed} failed)"] = time.perf_counter() - t0
        if failed > 0.05 * replicates:
            cal.notes.append(f"{failed} of {replicates} bootstrap replicates failed to fit")
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    text = outputs.material_text(cal, args.name, [str(p) for p in args.data])
    if text is not None:
        path = out / f"{args.name}.toml"
        write_atomic(path, text)
        try:
            load_material(path)
        except MaterialError as exc:
            path.unlink()
            raise FitError(f"the fitted material does not load: {'; '.join(exc.problems)}") \
                from None
    figures = outputs.plots(cal, out)
    outputs.write_json(cal, out / "fit.json", {"timings_s": timings})
    write_atomic(out / "report.md", outputs.report_text(cal, figures, timings))
    for k, e in cal.estimates.items():
        print(f"[yadebreak] {k} = {e.value:.4g} {e.unit}, 95 % [{e.lo:.4g}, {e.hi:.4g}]")
    print(f"[yadebreak] wrote {out / 'fit.json'}, {out / 'report.md'}"
          + (f", {out / (args.name + '.toml')}" if text is not None else ""))
    if text is None:
        fail("material file not written: missing " + ", ".join(cal.missing or ["elastic and "
             "contact data"]) + " (give --base MATERIAL to take them from a material)")
    return 0
